"""Stability verdicts do not depend on the unit of time. Found by a black-box test: PI loops on slow plants (poles at
1e-3 rad/s, a thermal process) were "not certified stable" whatever their margins, because the count on the loop
shifted by the stability floor (1e-6 of the plant's slowest frequency: 1e-9 rad/s) told the integrator's shifted pole
from the axis by an absolute 1e-9. The same loops with time scaled 1000x faster were stable."""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant


def _scaled(plant: Plant, a: float) -> Plant:
    """``G(s a)``: every pole and zero divided by ``a``, the delay times ``a`` (time ``a`` times slower)."""
    num = plant.num * a ** np.arange(plant.num.size - 1, -1, -1.0)
    den = plant.den * a ** np.arange(plant.den.size - 1, -1, -1.0)
    return Plant(num / den[0], den / den[0], plant.delay * a)


def _pade_rightmost(plant: Plant, kp: float, ki: float, order: int = 10) -> float:
    """Largest real part of the closed loop's roots with the delay as a Pade approximant (an independent check)."""
    import control

    delay_num, delay_den = control.pade(plant.delay, order) if plant.delay > 0 else ([1.0], [1.0])
    num = np.polymul(np.polymul([kp, ki], plant.num), delay_num)
    den = np.polymul(np.polymul([1.0, 0.0], plant.den), delay_den)
    size = max(num.size, den.size)
    return float(np.max(np.roots(np.pad(num, (size - num.size, 0)) + np.pad(den, (size - den.size, 0))).real))


def test_the_thermal_process_of_the_report_is_stable():
    plant = Plant.from_string("0.5/((1000*s+1)*(100*s+1))", delay=50.0)
    loop = Loop(plant, Controller("PI", {"kp": 10.0, "ki": 0.02}))
    assert _pade_rightmost(plant, 10.0, 0.02) < -1e-3  # the rightmost root: -0.0025 (orders 6-14 agree)
    result = loop.stability()
    assert result.stable and result.unstable_poles == 0, result.describe()


@pytest.mark.parametrize("seed", range(4))
def test_verdicts_are_the_same_in_seconds_and_in_hours(seed):
    rng = np.random.default_rng(seed)
    agree = 0
    for _ in range(12):
        poles = -np.exp(rng.uniform(np.log(0.2), np.log(20.0), rng.integers(1, 4)))
        den = np.poly(poles)
        plant = Plant(np.array([abs(den[-1]) * rng.uniform(0.5, 5.0)]), den, float(rng.uniform(0.0, 0.5)))
        controllers = [Controller("PI", {"kp": float(rng.uniform(0.05, 3.0)), "ki": float(rng.uniform(0.01, 3.0))})
                       for _ in range(10)]
        fast = [Loop(plant, c).stability().stable for c in controllers]
        for a in (1e3, 1e4):  # the same loops with time a times slower: ki / a
            slow_plant = _scaled(plant, a)
            slow = [Controller("PI", {"kp": c.parameters["kp"], "ki": c.parameters["ki"] / a}) for c in controllers]
            assert [Loop(slow_plant, c).stability().stable for c in slow] == fast
            counts = LoopBatch(slow_plant, slow).unstable_root_counts()
            assert [bool(n == 0) for n in counts] == fast
        margin = [_pade_rightmost(plant, c.parameters["kp"], c.parameters["ki"]) for c in controllers]
        for stable, rightmost in zip(fast, margin):
            if abs(rightmost) > 1e-3:  # away from the edge, where a Pade root and the exact one may differ
                assert stable == (rightmost < 0)
                agree += 1
    assert agree >= 60


def test_a_pi_design_on_a_thermal_process_is_the_fast_design_in_slow_time():
    """The black-box test's design: 0.5/((1000 s + 1)(100 s + 1)) behind 50 s, margins 6 dB / 45 deg, maximize ki.
    It answered ki = 2.7e-12 ("certified"); the same problem 1000 times faster gives ki = 15.87, i.e. 0.01587."""
    from synth.design import design
    from synth.spec import parse_spec

    def spec(scale: float) -> str:
        return f"""
name: thermal
plant: {{tf: "0.5/(({1000 / scale:g}*s+1)*({100 / scale:g}*s+1))", delay: {50 / scale:g}}}
controller: {{type: PI, bounds: {{kp: [0, 30], ki: [0, {0.1 * scale:g}]}}}}
requirements:
  - {{type: margins, gain_margin_db: 6, phase_margin_deg: 45}}
objective: {{maximize: integral_gain}}"""

    slow, fast = design(parse_spec(spec(1.0))), design(parse_spec(spec(1000.0)))
    assert slow.feasible and fast.feasible
    assert fast.controller.parameters["ki"] > 10.0  # far from zero: a real integral gain
    assert slow.controller.parameters["ki"] * 1000.0 == pytest.approx(fast.controller.parameters["ki"], rel=1e-3)
    assert slow.controller.parameters["kp"] == pytest.approx(fast.controller.parameters["kp"], rel=1e-3)
