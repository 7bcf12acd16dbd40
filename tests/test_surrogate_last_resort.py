"""The certified loop's last resort for a spec with nothing but step-response limits and an integral objective:
the search of the bounds on the exact check runs first, and the plain design (whose stages see none of the
requirements) is made only when that search finds nothing.

The design found is checked against an independent step: scipy's ``lsim`` of the closed loop built here from the
polynomials, on a dense even grid.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lsim

from synth.design import design
from synth.spec import parse_spec
from synth.synthesis.multi import design_convex
from synth.synthesis.surrogate import design_certified

PLANT = ([5.0], np.poly([-1.0, -2.0, -3.0]))


def _recording(calls: list[list[str]]):
    def design_fn(spec):
        calls.append(sorted(r.type for r in spec.requirements))
        return design_convex(spec)
    return design_fn


def _pid_step(kp: float, ki: float, kd: float, tf: float, t: np.ndarray) -> np.ndarray:
    """Unit step of the PID loop around 5/((s+1)(s+2)(s+3)), C = kp + ki/s + kd s/(tf s + 1), by lsim."""
    c_num = np.polyadd(np.polyadd(kp * np.array([tf, 1.0, 0.0]), ki * np.array([tf, 1.0])), [kd, 0.0, 0.0])
    c_den = np.array([tf, 1.0, 0.0])
    ol_num, ol_den = np.polymul(c_num, PLANT[0]), np.polymul(c_den, PLANT[1])
    _, y, _ = lsim((ol_num, np.polyadd(ol_den, ol_num)), np.ones_like(t), t)
    return y


def test_step_limits_alone_are_designed_by_the_exact_search_without_the_plain_design() -> None:
    spec = parse_spec({"name": "pid_step", "plant": {"tf": "5/((s+1)*(s+2)*(s+3))"},
                       "controller": {"type": "PID", "bounds": {"kp": [0, 20], "ki": [0, 20], "kd": [0, 10],
                                                                "tf": [0.01, 0.01]}},
                       "requirements": [{"type": "step_response", "max_overshoot": 5, "max_settling_time": 4}],
                       "objective": {"maximize": "integral_gain"}})
    calls: list[list[str]] = []
    result = design_certified(spec, _recording(calls))
    assert result.feasible and result.certificate.passed
    assert all("step_response" not in c for c in calls), calls  # the plain design was never made
    assert "found by a search of the bounds on the exact check" in result.method
    p = result.controller.parameters
    assert p["ki"] > 4.5  # the step benchmark's grid best for this plant and these limits is about 5.1
    t = np.linspace(0.0, 60.0, 120001)
    y = _pid_step(p["kp"], p["ki"], p["kd"], p["tf"], t)
    assert 100.0 * (y.max() - 1.0) <= 5.0 + 0.01
    outside = np.nonzero(np.abs(y - 1.0) > 0.02)[0]
    assert t[outside[-1] + 1] <= 4.0 + 1e-3  # last exit from the 2 % band


def test_when_the_exact_search_finds_nothing_the_plain_design_is_made_and_reported() -> None:
    spec = parse_spec({"name": "too_fast", "plant": {"tf": "1/((s+1)*(s+2)*(s+3))"},
                       "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}},
                       "requirements": [{"type": "step_response", "max_settling_time": 0.05}],
                       "objective": {"maximize": "integral_gain"}})
    calls: list[list[str]] = []
    result = design_certified(spec, _recording(calls))
    assert not result.feasible and result.controller is None
    assert calls[-1] == ["step_response"]  # the plain design, made last
    assert "a search of the bounds on the exact check found no controller that passes" in result.method
    assert "no design under peak |S|, |T| <= 0.05 dB passes them either" in result.method


def test_a_design_under_the_surrogate_states_its_objective_value() -> None:
    """A black-box test's lead-lag with step limits: every other design's verdict gave the objective's value, the
    surrogate's did not (the reader could not compare it with a design of their own)."""
    spec = parse_spec({"name": "pi_step", "plant": {"tf": "1/((s+1)*(s+2))"},
                       "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}},
                       "requirements": [{"type": "step_response", "max_overshoot": 10}],
                       "objective": {"maximize": "integral_gain"}})
    result = design(spec)
    assert result.feasible and "; step_response: designed with" in result.verdict
    value = result.objective["value"]
    assert f"(maximize integral_gain: {value:.4g} u/(y*s)); step_response" in result.verdict, result.verdict
