"""A closed-loop peak at w = 0 (a black-box test's finding, session 54).

A loop whose DC gain is negative and near -1 (a right-half-plane zero and a gain of the "wrong" sign, or a plant
whose high-frequency sign is opposite to its DC sign) has ``|S|`` and ``|T|`` largest at w = 0. The unbanded peak
types and the disk margin gridded from the loop's slowest corner over a hundred and reported the value there:
peak |S| 31.89 dB "met" where ``|S(0)|`` is 46.02 dB, a disk margin of 0.0255 for 0.00501, and a design
"FEASIBLE" at kp = -1.96066 whose peak |S| is 34.1 dB against a bound of 30 dB. The references here are closed
forms at w = 0 and a dense grid with w = 0 (numpy only).
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.design import design
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant
from synth.requirements import DiskMargin, PeakComplementary, PeakSensitivity
from synth.requirements.base import NEPER_PER_DB
from synth.spec import parse_spec


def _dense_peaks(num: np.ndarray, den: np.ndarray, k: float) -> tuple[float, float, float]:
    w = np.r_[0.0, np.geomspace(1e-6, 1e5, 220_000)]
    L = k * np.polyval(num, 1j * w) / np.polyval(den, 1j * w)
    S = 1 / (1 + L)
    return float(np.max(np.abs(S))), float(np.max(np.abs(L * S))), float(1 / np.max(np.abs(S - 0.5)))


@pytest.mark.parametrize("seed", range(6))
def test_peaks_and_disk_margin_at_w_zero_match_a_dense_grid(seed: int) -> None:
    rng = np.random.default_rng(seed)
    z, p1, p2 = rng.uniform(0.3, 5.0, 3)
    num, den = np.array([-1.0, z]), np.poly([-p1, -p2])  # (-s + z)/((s + p1)(s + p2)): DC gain z/(p1 p2) > 0
    eps = rng.uniform(0.005, 0.1)
    k = -(1 - eps) * p1 * p2 / z  # L(0) = -(1 - eps): |S(0)| = 1/eps
    if np.any(np.roots(np.polyadd(den, k * num)).real >= 0):
        pytest.skip("this draw's loop is not stable")
    loop = Loop(Plant(num, den), Controller("P", {"kp": float(k)}))
    ms, mt, alpha = _dense_peaks(num, den, k)
    assert ms >= 1 / eps * (1 - 1e-9)  # the closed form at w = 0 (the dense grid may hold more)
    assert PeakSensitivity(max_db=0.0).evaluate(loop).value == pytest.approx(20 * np.log10(ms), abs=0.01)
    assert PeakComplementary(max_db=0.0).evaluate(loop).value == pytest.approx(20 * np.log10(mt), abs=0.01)
    assert DiskMargin(min=0.01).evaluate(loop).value == pytest.approx(alpha, rel=2e-3)
    batch = LoopBatch(Plant(num, den), [Controller("P", {"kp": float(k)})])
    slack = PeakSensitivity(max_db=0.0).batch_slack(batch)[0]
    assert -slack / NEPER_PER_DB == pytest.approx(20 * np.log10(ms), abs=0.01)


def test_a_p_design_ends_where_the_peak_at_w_zero_meets_its_bound() -> None:
    """The black-box test's design: kp in [-1.999, -1] on (1 - s)/((s + 1)(s + 2)), peak |S| <= 30 dB, disk margin
    >= 0.03, maximize the low-frequency gain. Its peak is |S(0)| = 1/(1 + kp/2), so the feasible set ends at
    kp = 2 (10^(-30/20) - 1) = -1.93675 (the disk margin's end, 2 (0.03 - 1) = -1.94, lies beyond it)."""
    spec = parse_spec({"name": "dc3", "plant": {"tf": "(-s+1)/((s+1)*(s+2))"},
                       "controller": {"type": "P", "bounds": {"kp": [-1.999, -1.0]}},
                       "requirements": [{"type": "peak_sensitivity", "max_db": 30},
                                        {"type": "disk_margin", "min": 0.03}],
                       "objective": {"maximize": "low_frequency_gain"}})
    result = design(spec)
    assert result.feasible
    assert result.controller.parameters["kp"] == pytest.approx(2 * (10 ** (-30 / 20) - 1), abs=1e-4)
