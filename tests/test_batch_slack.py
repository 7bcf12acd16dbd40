"""Vectorized requirement slacks (``Requirement.batch_slack``) against the scalar fallback and a dense grid.

Every registered requirement type is evaluated on seeded random loops (plants with and without a delay;
P, PI, PID and lead-lag controllers) both ways: its batch form (vectorized over all loops and frequencies)
and the base class's scalar fallback (``evaluate`` one loop at a time). They must agree to rounding. The
magnitudes behind the slacks are also checked against an independent brute-force dense grid.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant
from synth.requirements import (
    REQUIREMENT_TYPES,
    Bandwidth,
    MarginsRequirement,
    PeakComplementary,
    PeakControlSensitivity,
    PeakSensitivity,
    Requirement,
    Sensitivity,
    SlewRate,
    StaticSensitivity,
)
from synth.requirements.base import NEPER_PER_DB
from synth.spec import load_spec, parse_spec
from synth.synthesis.gainset import ScalarFamily, feasible_gain_set

TOL = 1e-6  # Np or rad: the vectorized and scalar slacks agree far closer than the gain-set's EXACT_BAND


def _plant(rng: np.random.Generator, delay: bool) -> Plant:
    poles = -rng.uniform(0.3, 30.0, size=rng.integers(1, 4))
    zeros = -rng.uniform(0.2, 20.0, size=rng.integers(0, poles.size))
    num = np.poly(zeros) * rng.uniform(0.5, 20.0) * np.prod(-poles) / max(np.prod(-zeros), 1e-12)
    return Plant(num, np.poly(poles), delay=float(rng.uniform(0.001, 0.03)) if delay else 0.0)


def _controllers(rng: np.random.Generator) -> list[Controller]:
    out = []
    for _ in range(6):
        kp = float(rng.uniform(0.05, 3.0))
        out.append(Controller("P", {"kp": kp}))
        out.append(Controller("PI", {"kp": kp, "ki": float(rng.uniform(0.0, 5.0) * kp)}))
        out.append(Controller("PID", {"kp": kp, "ki": float(rng.uniform(0.1, 3.0)), "kd": float(rng.uniform(0, 0.05)),
                                      "tf": float(rng.uniform(0.002, 0.02))}))
        z = float(rng.uniform(0.5, 10.0))
        out.append(Controller("leadlag", {"k": kp, "z": z, "p": z * float(rng.uniform(1.5, 10.0))}))
    return out


def _requirements() -> list[Requirement]:
    """Each registered type's example, plus the built-in types with other fields set."""
    return [
        *(cls(**cls.example) for cls in REQUIREMENT_TYPES.values()),
        Sensitivity(max_db=-6, band=(0.5, 3.0)),
        StaticSensitivity(max_db=-10),
        Bandwidth(min=1.0, max=50.0),
        SlewRate(rate_limit=50.0, max_error=1.0, band=(0.0, 10.0)),
        PeakSensitivity(max_db=4, band=(0.1, 10.0)),
        PeakComplementary(max_db=2),
        PeakControlSensitivity(max_db=10),
        MarginsRequirement(gain_margin_db=6, phase_margin_deg=40, delay_margin=0.01),
    ]


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    finite = np.isfinite(a) & np.isfinite(b)
    return bool(np.array_equal(np.isfinite(a), np.isfinite(b)) and np.array_equal(a[~finite], b[~finite])
                and np.all(np.abs(a[finite] - b[finite]) <= TOL))


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("delay", [False, True])
def test_batch_form_agrees_with_the_scalar_fallback_on_every_type(seed: int, delay: bool):
    rng = np.random.default_rng(100 * seed + delay)
    plant = _plant(rng, delay)
    batch = LoopBatch(plant, _controllers(rng))
    for req in _requirements():
        fast = req.batch_slack(batch)
        slow = Requirement.batch_slack(req, batch)  # the scalar fallback: evaluate() one loop at a time
        assert fast.shape == (len(batch),)
        assert _same(fast, slow), (req, np.c_[fast, slow])


def test_every_built_in_type_has_a_batch_form():
    built_in = {"sensitivity", "sensitivity_static", "peak_sensitivity", "peak_complementary",
                "peak_control_sensitivity", "bandwidth", "slew_rate", "margins"}
    assert {name for name, cls in REQUIREMENT_TYPES.items() if cls.has_batch_form()} >= built_in


def _dense(lo: float, hi: float) -> np.ndarray:
    return np.geomspace(lo, hi, int(4000 * np.log10(hi / lo)))


@pytest.mark.parametrize("seed", [3, 4])
def test_batch_magnitudes_against_a_dense_grid(seed: int):
    """Peaks and crossings of the batch forms, recomputed from the plant and controller polynomials on a
    grid of 4000 points per decade (no refinement, no synth frequency-response code)."""
    rng = np.random.default_rng(seed)
    plant = _plant(rng, delay=True)
    controllers = _controllers(rng)
    batch = LoopBatch(plant, controllers)
    lo = batch.frequency_ranges[:, 0].min()
    hi = batch.frequency_ranges[:, 1].max() * 10
    w = _dense(lo, hi)
    s = 1j * w
    G = np.polyval(plant.num, s) / np.polyval(plant.den, s) * np.exp(-s * plant.delay)
    for i, c in enumerate(controllers):
        num, den = c.tf()
        C = np.polyval(num, s) / np.polyval(den, s)
        L = C * G
        own_lo, own_hi = batch.frequency_ranges[i]
        mine = (w >= own_lo) & (w <= own_hi * 10)
        ms_db = 20 * np.log10(np.max(np.abs(1 / (1 + L[mine]))))
        slack = PeakSensitivity(max_db=0.0).batch_slack(batch)[i]
        if batch.closed_loop_unstable()[i]:  # no finite peak: unmet by the root count
            assert slack == -batch.unstable_root_counts()[i]
        else:
            assert -slack / NEPER_PER_DB >= ms_db - 1e-9  # the refined peak is at least the grid's
        if ms_db < 20 and not batch.closed_loop_unstable()[i]:  # a sharper resonance is only bounded below
            assert -slack / NEPER_PER_DB == pytest.approx(ms_db, abs=1e-3)
        wb_ = _dense(0.1, 100.0)
        demand = np.max(5.0 * np.abs(np.polyval(num, 1j * wb_) / np.polyval(den, 1j * wb_)) * wb_)
        rate = SlewRate(rate_limit=1.0, max_error=5.0, band=(0.1, 100.0)).batch_slack(batch)[i]
        assert np.exp(-rate) == pytest.approx(demand, rel=1e-4)
        T = np.abs(L[mine] / (1 + L[mine]))
        t0 = Loop(plant, c).T0()
        below = np.flatnonzero(T < t0 * 10 ** (-3 / 20))
        if batch.closed_loop_unstable()[i]:  # no bandwidth: the requirement is unmet by the root count
            assert Bandwidth(min=1.0).batch_slack(batch)[i] < 0
        elif below.size and below[0] > 0:
            wb = np.exp(Bandwidth(min=1.0).batch_slack(batch)[i])
            assert wb == pytest.approx(w[mine][below[0]], rel=2e-3)


def test_margins_batch_against_a_dense_grid():
    plant = Plant.from_string("1/(s+1)^3")
    batch = LoopBatch(plant, [Controller("P", {"kp": k}) for k in (1.0, 2.0, 4.0)])
    pm, _ = batch.phase_and_delay_margins()
    w = _dense(0.01, 100.0)
    for i, k in enumerate((1.0, 2.0, 4.0)):
        L = k / (1j * w + 1) ** 3
        j = np.argmin(np.abs(np.abs(L) - 1))
        if k > 1:
            assert pm[i] == pytest.approx(180 + np.degrees(np.angle(L[j])), abs=0.05)
    assert batch.upper_gain_margins() == pytest.approx([8.0, 4.0, 2.0])


X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"


@pytest.mark.parametrize("text, family, bounds", [
    (f"""
name: pi_delay
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: PI, bounds: {{kp: [1.0, 1.0], ki: [0, 30]}}}}
requirements:
  - {{type: sensitivity, max_db: -15, band: [0.01, 5]}}
  - {{type: peak_sensitivity, max_db: 6}}
  - {{type: margins, gain_margin_db: 6, phase_margin_deg: 45}}
""", ScalarFamily("PI", "ki", {"kp": 1.0}), (0.0, 30.0)),
    (f"""
name: p_strict
plant: {{tf: "{X4}", delay: 0.005}}
controller: {{type: P, bounds: {{kp: [0, 8]}}}}
requirements:
  - {{type: sensitivity, max_db: -15, band: [0, 30]}}
  - {{type: bandwidth, min: 60, max: 300}}
  - {{type: peak_complementary, max_db: 3}}
  - {{type: peak_control_sensitivity, max_db: 20}}
""", ScalarFamily("P", "kp", {}), (0.0, 8.0)),
])
def test_vectorized_gain_set_equals_the_scalar_one(text: str, family: ScalarFamily, bounds: tuple[float, float]):
    spec = parse_spec(text)
    args = (list(spec.requirements), spec.plants(), family, bounds)
    fast = feasible_gain_set(*args, n_bracket=41)
    slow = feasible_gain_set(*args, n_bracket=41, vectorized=False)
    assert fast.to_dict() == slow.to_dict()


def test_x4_gain_set_is_unchanged():
    spec = load_spec("specs/x4_rotor.yaml")
    gs = feasible_gain_set(list(spec.requirements), spec.plants(), ScalarFamily("P", "kp", {}), (0, 20))
    assert gs.as_list() == [[2.568562917725855, 20.0]]


def _any_plant(rng: np.random.Generator) -> Plant:
    """Stable or unstable poles, minimum- or non-minimum-phase zeros, either sign, with or without a delay."""
    poles = rng.uniform(-8.0, 2.0, size=rng.integers(1, 4))
    zeros = rng.uniform(-6.0, 3.0, size=rng.integers(0, poles.size))
    num = np.poly(zeros) * rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 20.0)
    return Plant(num, np.poly(poles), delay=float(rng.choice([0.0, 0.0, 0.01, 0.1])))


def _gain_sweep(rng: np.random.Generator) -> list[Controller]:
    gains = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 30.0, 30))])
    if rng.random() < 0.5:
        return [Controller("P", {"kp": float(k)}) for k in gains]
    z = float(rng.uniform(0.5, 10.0))
    p = z * float(rng.uniform(1.5, 10.0))
    return [Controller("leadlag", {"k": float(k), "z": z, "p": p}) for k in gains]


def test_gain_swept_batches_count_stability_like_each_loop():
    """A batch whose controllers differ by a gain reads stability off the D-decomposition set: on random
    plants (unstable, non-minimum-phase, delayed) it must match each loop's own root or Nyquist count."""
    rng = np.random.default_rng(2026)
    for _ in range(25):
        plant, controllers = _any_plant(rng), _gain_sweep(rng)
        batch = LoopBatch(plant, controllers)
        assert batch.gain_multiples() is not None
        expected = [Loop(plant, c).stability().unstable_poles > 0 for c in controllers]
        assert batch.closed_loop_unstable().tolist() == expected, plant


def test_gain_swept_limit_cycle_and_delay_margin_batches_match_the_scalar_slack():
    """The describing-function margin scales with the loop gain and the delay margin is read from every
    loop's crossovers: both vectorized forms agree with the scalar evaluation loop by loop."""
    from synth.requirements import DelayMargin, NoLimitCycle

    rng = np.random.default_rng(7)
    reqs = [DelayMargin(min=0.01),
            NoLimitCycle(actuator=[{"type": "saturation", "min": -1, "max": 1}], delay=(0.0, 0.02)),
            NoLimitCycle(actuator=[{"type": "rate_limit", "rate": 50.0}], min_gain_margin_db=3.0)]
    for _ in range(6):
        plant, controllers = _any_plant(rng), _gain_sweep(rng)
        batch = LoopBatch(plant, controllers)
        for req in reqs:
            scalar = np.array([req.slack(Loop(plant, c)) for c in controllers])
            fast = req.batch_slack(batch)
            finite = np.isfinite(scalar)
            assert np.array_equal(finite, np.isfinite(fast)), (req.type, plant)
            assert np.allclose(fast[finite], scalar[finite], rtol=0, atol=TOL), (req.type, plant)


def test_limit_cycle_margin_of_a_scaled_loop_is_the_direct_one():
    """The requirement keeps the critical factor of the unit-gain loop and scales it; computed directly on
    each loop (no scaling, no cache) the factor must be the same."""
    from synth.freqgrid import log_grid
    from synth.requirements import NoLimitCycle
    from synth.requirements.no_limit_cycle import critical_gain_factor

    rng = np.random.default_rng(11)
    req = NoLimitCycle(actuator=[{"type": "rate_limit", "rate": 50.0}, {"type": "saturation", "min": -1, "max": 1}],
                       delay=(0.0, 0.01))
    for _ in range(5):
        plant = _plant(rng, delay=bool(rng.random() < 0.5))
        for c in _gain_sweep(rng)[1::6]:
            loop = Loop(plant, c)
            if loop.stability().unstable_poles:
                continue
            lo, hi = loop.frequency_range
            k, _, _ = critical_gain_factor(loop.L, log_grid(lo, hi * 10, 80), req.delay, req.kinds())
            got = req.evaluate(loop).details["gain_factor"]
            assert got == pytest.approx(k, rel=1e-9), (plant, c)


@pytest.mark.slow
def test_margins_batch_matches_the_scalar_slack_on_unstable_and_conditionally_stable_loops():
    """Two-sided gain margins (a lower limit on open-loop unstable plants), negative phase margins and delay
    margins past a negative phase margin: the vectorized margins equal the scalar ones loop by loop, and the
    unstable loops carry the scalar verdict (one unit of slack below zero per counted root)."""
    rng = np.random.default_rng(31)
    reqs = [MarginsRequirement(gain_margin_db=3.0), MarginsRequirement(phase_margin_deg=30.0),
            MarginsRequirement(gain_margin_db=6.0, phase_margin_deg=40.0, delay_margin=0.005)]
    for _ in range(8):
        plant = _any_plant(rng)
        controllers = _controllers(rng) + _gain_sweep(rng)[::4]
        batch = LoopBatch(plant, controllers)
        loops = [Loop(plant, c) for c in controllers]  # built once: the cached responses serve all three requirements
        for req in reqs:
            scalar = np.array([req.slack(loop) for loop in loops])
            assert _same(req.batch_slack(batch), scalar), (req, plant)


def test_root_counts_of_a_parameter_grid_match_each_loop():
    """The feasibility map reads the stability of a PI/PID/lead-lag plane column by column off a
    D-decomposition (affine_root_counts); every count must be each loop's own."""
    from synth.report.feasibility_map import column_root_counts

    rng = np.random.default_rng(5)
    for _ in range(6):
        plant = _any_plant(rng)
        for kind, name, base in [("PI", "ki", {"kp": float(rng.uniform(0.0, 5.0))}),
                                 ("PID", "kd", {"kp": float(rng.uniform(0.1, 3.0)), "ki": float(rng.uniform(0, 2)),
                                                "tf": 0.01}),
                                 ("leadlag", "k", {"z": 1.0, "p": 8.0})]:
            family = ScalarFamily(kind, name, {**base, name: 1.0})
            values = np.linspace(0.0, float(rng.uniform(1.0, 20.0)), 15)
            counts = column_root_counts(family, [plant], values)[0]
            expected = [Loop(plant, family.controller(float(v))).stability().unstable_poles for v in values]
            assert counts.tolist() == expected, (plant, kind)
