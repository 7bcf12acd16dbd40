"""A dead zone whose band is not centered where the command starts: a known defect (session 59), kept as a strict
expected failure so that the fix is seen (the marker then has to go).

The dead-zone candidate holds its center at the command's first sample ("the command at rest"), and every benchmark
generator puts the true center there too. On a closed loop's continuously varying command that starts elsewhere,
the misplaced candidate explained 28 % of the held-out error and a quantizer 70 %: the diagnosis named a quantizer
(`benchmarks/gap/diagnose_speed.py --input smooth`, a 20,000-sample X-4 record). Here the diagnosis says
"parameter_mismatch" (record 0) or "saturation" (record 1).

Tried in session 59 and not kept: the center as a second grid parameter (the first sample and the command's
quartiles), searched jointly with the width. Both records here then pass, but on the withheld-effect benchmark's
dead zone, backlash and static-map cases of seeds 0 and 1 (112 cases, the truth's center at the first sample) the
right verdicts fell from 102 to 97: the dead zones at 10x and 30x named a saturation or nothing, the extra
parameter counted against the dead zone by the parsimony test.

The records here are simulated by scipy alone (exact zero-order hold of the dead-zoned command samples,
``cont2discrete`` and ``dlsim``), not by synth: random second-order plants, a smooth random command (white noise
low-passed at 0.3 Hz, scaled to 0-10), the band's center 1.5-3 units from where the command starts, inside 2.5-7.5.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.gap.diagnose import diagnose
from synth.plant import Plant

DT, N = 0.01, 3000


def _dead_zone(x: np.ndarray, width: float, center: float) -> np.ndarray:
    """``center`` inside ``|x - center| <= width``, ``x -+ width`` outside (the block's documented map)."""
    return np.where(x > center + width, x - width, np.where(x < center - width, x + width, center))


def _records(seed: int):
    rng = np.random.default_rng(seed)
    p1, p2, gain = rng.uniform(1.0, 4.0), rng.uniform(6.0, 20.0), rng.uniform(0.5, 3.0)
    num, den = np.array([gain * p1 * p2]), np.polymul([1.0, p1], [1.0, p2])
    disc = signal.cont2discrete(signal.tf2ss(num, den), DT, method="zoh")
    a = np.exp(-2.0 * np.pi * 0.3 * DT)
    commands = []
    for _ in range(2):  # estimation, validation: smooth commands over 0-10, at rest for 2 s first
        x = signal.lfilter([1.0 - a], [1.0, -a], rng.normal(size=N))
        u = 10.0 * (x - x.min()) / np.ptp(x)
        commands.append(np.r_[np.full(200, u[0]), u[:-200]])
    width = rng.uniform(0.5, 1.2)
    start = commands[0][0]  # the band 1.5-3 units to the wider side of where the estimation command starts
    center = float(np.clip(start + (1.0 if start < 5.0 else -1.0) * rng.uniform(1.5, 3.0), 2.5, 7.5))
    out = []
    for u in commands:
        v = _dead_zone(u, width, center)
        _, y, _ = signal.dlsim(disc, v - v[0])
        y = np.ravel(y) + gain * float(v[0])  # started in the steady state of the first held command
        y = y + 0.01 * np.std(y) * rng.normal(size=N)
        out.append(record_from_arrays(np.arange(N) * DT, u, y))
    if abs(commands[0][0] - center) <= 2.0 * width:  # not an assertion: the expected failure below must not hide it
        raise ValueError(f"record {seed}: the band is where the command starts")
    nominal = Plant(num * 1.03, np.r_[den[0], den[1:] * np.array([0.97, 1.02])])
    return nominal, out[0], out[1], center, width


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,  # a crash or a bad record is a failure, not this defect
                   reason="known defect: the dead zone's center is held at the command's first sample")
@pytest.mark.parametrize("seed", [0])
def test_an_off_center_dead_zone_is_named_with_its_center(seed: int) -> None:
    nominal, rec, val, center, width = _records(seed)
    d = diagnose(nominal, rec, val, candidates=["deadzone", "quantization", "backlash", "saturation"], n_boot=200)
    assert d.verdict["effects"] == ["deadzone"], d.summary
    found = next(e for e in d.attribution.effects if e.effect == "deadzone").parameters
    assert abs(found["center"] - center) < 0.02 * 10.0, (found, center)
    assert abs(found["width"] - width) < 0.1 * width, (found, width)
