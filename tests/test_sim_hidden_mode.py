"""A still output over a controller command that ramps: a closed-loop root the output does not see.

A PI's integrator on a plant with a zero at the origin (``s N(s)/D(s)``) cancels: the output settles at
``1/(1 + L0)`` of the step (``L0 = ki N(0)/D(0)``) while the integrator integrates that error for ever, so the
command ramps at ``ki e`` per second. ``synth simulate`` called such a loop "settled" (a black-box test found it,
``synth check`` calling the same loop marginally stable); it is diverging. The reference here is that closed form,
on random plants; loops without the cancellation keep their verdicts.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.plant import Plant
from synth.sim.horizon import linear_loop_stable
from synth.sim.loops import NonlinearLoop
from synth.sim.verdict import step_verdict


def _random_case(seed: int) -> tuple[np.ndarray, np.ndarray, float, float]:
    """A stable plant s N(s)/D(s) (D of order 2-3, N of order 0-1) and PI gains that keep the visible loop stable."""
    rng = np.random.default_rng(seed)
    poles = -rng.uniform(0.5, 5.0, size=int(rng.integers(2, 4)))
    den = np.real(np.poly(poles)) * rng.uniform(0.5, 2.0)
    num = np.polymul([1.0, 0.0], [rng.uniform(0.2, 3.0)] if rng.random() < 0.5
                     else [rng.uniform(0.2, 3.0), rng.uniform(0.5, 5.0)])
    return num, den, float(rng.uniform(0.05, 0.5)), float(rng.uniform(0.2, 2.0))


@pytest.mark.parametrize("seed", range(5))
def test_a_pi_on_a_zero_at_the_origin_diverges_with_the_command_ramping_at_ki_times_the_error(seed: int) -> None:
    num, den, kp, ki = _random_case(seed)
    plant = Plant(num, den)
    loop = NonlinearLoop(plant, Controller("PI", {"kp": kp, "ki": ki}), dt=0.001)
    # the visible loop: D + (kp s + ki) N (the integrator's 1/s cancels the plant's s); stable for a still output
    visible = np.polyadd(den, np.polymul([kp, ki], num[:-1]))
    if np.any(np.roots(visible).real >= 0):
        pytest.skip("the visible part of this random loop is unstable")
    assert not linear_loop_stable(loop)
    v = step_verdict(loop, 0.0, 1.0)
    L0 = ki * num[-2] / den[-1]  # (kp s + ki)/s * s N'(s)/D(s) at s = 0
    error = 1.0 / (1.0 + L0)
    assert v.verdict == "diverging", v.evidence.criterion
    rate = float(v.evidence.criterion.split("moves at ")[1].split(" ")[0])
    assert rate == pytest.approx(ki * error, rel=0.01)
    assert v.metrics.final_value == pytest.approx(1.0 - error, rel=1e-3)


@pytest.mark.parametrize("seed", range(3))
def test_the_same_plants_without_the_cancellation_still_settle(seed: int) -> None:
    num, den, kp, ki = _random_case(seed)
    shifted = np.polymul([1.0, 0.3], num[:-1])  # the zero moved off the origin: no root hidden
    loop = NonlinearLoop(Plant(shifted, den), Controller("PI", {"kp": kp, "ki": ki}), dt=0.001)
    if not linear_loop_stable(loop):
        pytest.skip("this random loop is unstable")
    assert step_verdict(loop, 0.0, 1.0).verdict == "settled"
    p_only = NonlinearLoop(Plant(num, den), Controller("P", {"kp": kp}), dt=0.001)
    assert linear_loop_stable(p_only) and step_verdict(p_only, 0.0, 1.0).verdict == "settled"


def test_simulate_exits_1_with_the_diverging_verdict(run_cli, tmp_path) -> None:
    spec = tmp_path / "m.yaml"
    spec.write_text('name: m\nplant: {tf: "s/(s+1)^2"}\ncontroller: {type: PI}\n'
                    "requirements: [{type: margins, gain_margin_db: 6}]\n")
    res = run_cli("simulate", str(spec), "-c", "PI(kp=1, ki=1)", "--out", str(tmp_path / "o"))
    assert res.code == 1, res.out + res.err
    assert "verdict: diverging" in res.out and "a mode the output does not see" in res.out
    assert "moves at 0.5 input units/s" in res.out  # ki times the steady error 0.5


def test_a_first_horizon_that_is_the_cap_decides_on_its_two_halves_with_the_step_later_than_zero() -> None:
    """The run and its first half stand for two horizons when no longer run is allowed; with the step at 1 s that
    check indexed the run with a mask of the samples after the step (an IndexError, found reviewing the change)."""
    loop = NonlinearLoop(Plant.from_string("s/(s+1)^2"), Controller("PI", {"kp": 1, "ki": 1}), dt=0.001)
    v = step_verdict(loop, 0.0, 1.0, t_step=1.0, horizon=21.0, max_horizon=21.0)
    assert v.verdict == "diverging" and v.evidence.criterion.startswith("over the run and over its first half")
