"""The NLP's bandwidth measures |T| against T(0) (``t0_squared``). A PI or PID designed without integral action
(``ki`` fixed at 0, the second design of every PI/PID spec) has a finite T(0) = kp G(0) / (1 + kp G(0)); the
NLP used 1, as with integral action, and so polished PD designs for the wrong bandwidth."""

from __future__ import annotations

import warnings

import casadi as ca
import numpy as np
import pytest

import synth
from benchmarks.design_problems import generate
from synth.controllers import Controller
from synth.loop import Loop
from synth.objectives import score
from synth.plant import Plant
from synth.synthesis.convex_settings import ConvexSettings, design_grid
from synth.synthesis.delay_grid import controller_gain_bound
from synth.synthesis.nlp import polish
from synth.synthesis.nlp_problem import SymbolicController, t0_squared
from synth.synthesis.parametrization import parametrize


@pytest.mark.parametrize("kind", ["PI", "PID"])
def test_t0_of_a_design_without_integral_action_is_the_loops_own(kind):
    plant = Plant.from_string("38969.4*(1-s/205.74)/((s+21.7238)*(s+609.62))", delay=0.0077)
    params = {"kp": 0.4, "ki": 0.0} | ({"kd": 0.003, "tf": 0.0016} if kind == "PID" else {})
    bounds = {"kp": (0.0, 18.0), "ki": (0.0, 0.0)} | ({"kd": (0.0, 0.3), "tf": (0.0016, 0.0016)} if kind == "PID"
                                                       else {})
    start = Controller(kind, params)
    ctrl = SymbolicController(kind, start, bounds)
    value = float(ca.Function("t0", [ctrl.u], [t0_squared(ctrl, plant)])(ctrl.u0))
    assert value == pytest.approx(Loop(plant, start).T0() ** 2, rel=1e-12)  # 0.541**2, not 1
    free = SymbolicController(kind, start, {**bounds, "ki": (0.0, 100.0)})
    assert t0_squared(free, plant) == 1.0  # with integral action (ki > 0 is designed separately from ki = 0)


def test_pd_polish_reaches_the_reference_optimum():
    # the design benchmark's seed 8 #272 (a right-half-plane zero, 7.7 ms delay, maximize bandwidth under
    # |KS| <= 9.8 dB and |S| <= -7 dB below 2.5 rad/s): the reference's best PD is kp 0.4253, kd 0.00319 at
    # 293.06 rad/s; the polish of synth's design without integral action from kp 1.06, kd 0.0020 (243.2 rad/s)
    # stopped at 243.2 rad/s with T(0) taken as 1
    p = generate(273, 8)[272]
    spec = synth.parse_spec(p.spec)
    bounds = {k: tuple(v) for k, v in p.spec["controller"]["bounds"].items()} | {"ki": (0.0, 0.0)}
    plants, reqs, terms = spec.plants(), list(spec.requirements), spec.objective.terms()
    grid = design_grid(plants, reqs, ConvexSettings(), controller_gain_bound(parametrize("PID", bounds)))
    start = Controller("PID", {"kp": 1.061279552563334, "ki": 0.0, "kd": 0.0019940850455683803, "tf": 0.0015914})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = polish(reqs, plants, start, bounds, terms, grid)
        assert result.success
        assert synth.check(spec, result.controller, 400).feasible
    assert score(Loop(plants[0], result.controller), terms) >= 293.06 * (1 - 1e-3)
    assert np.isclose(result.controller.parameters["kp"], 0.4253, rtol=0.01)


@pytest.mark.parametrize("kind, params, bounds", [
    ("PID", {"kp": 1.0, "ki": 0.0, "kd": 0.01, "tf": 0.005},
     {"kp": (0.0, 5.0), "ki": (0.0, 0.0), "kd": (0.0, 0.5), "tf": (0.005, 0.005)}),
    ("leadlag", {"k": 2.0, "z": 1.0, "p": 10.0}, {"k": (0.0, 10.0), "z": (0.1, 10.0), "p": (1.0, 100.0)}),
])
def test_t0_behind_an_integrating_plant_is_one(kind, params, bounds):
    # the servo of benchmarks/cli_speed.py: G(0) is infinite, so T(0) = 1 whatever the controller's C(0) (the
    # first version of the fix above gave inf/inf = nan there, and IPOPT stopped on NaN constraints)
    plant = Plant.from_string("400/(s*(s^2+4*s+400))", delay=0.002)
    ctrl = SymbolicController(kind, Controller(kind, params), bounds)
    assert t0_squared(ctrl, plant) == 1.0
    assert Loop(plant, Controller(kind, params)).T0() == pytest.approx(1.0)


def test_t0_of_a_rational_controller_whose_a0_reaches_zero():
    # seed 8 #190: the reference's best rational controller has a0 = 0 (an integrator). T(0) was written with
    # C(0) = b0 / a0, so a polish started there had NaN in its Jacobian and stopped; now n G0 / (d + n G0)
    plant = Plant.from_string("0.201541/(s-0.0942153)", delay=0.0726835)
    bounds = {"b0": (-4.85, 4.85), "b1": (-27.2, 27.2), "b2": (-152.9, 152.9), "a0": (0.0, 14.3), "a1": (0.0, 80.2)}
    for a0 in (0.0, 0.3):
        start = Controller("rational", {"b0": 0.469, "b1": 16.38, "b2": -1.074, "a0": a0, "a1": 5.11})
        ctrl = SymbolicController("rational", start, bounds)
        t0 = t0_squared(ctrl, plant)
        value, jac = ca.Function("t0", [ctrl.u], [t0, ca.jacobian(t0, ctrl.u)])(ctrl.u0)
        assert float(value) == pytest.approx(Loop(plant, start).T0() ** 2, rel=1e-9)
        assert np.all(np.isfinite(np.asarray(jac)))
