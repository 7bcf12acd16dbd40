"""A step limit on loops whose closed-loop poles span more than 50:1 (found by a black-box test): the first horizon
follows the fastest pole, and eight doublings of it did not reach the slow pole's settling, so ordinary loops
were "undetermined" (not met) and a design whose every controller meets the limits was called infeasible. The
reference is scipy's step of the closed loop on a dense grid, written here apart from synth."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy import signal

import synth
from synth.spec import parse_spec


def _reference(num: list[float], den: list[float], horizon: float) -> tuple[float, float]:
    """Overshoot [%] and 2 % settling time [s] of ``num/den``'s unit step (scipy, 400,001 samples)."""
    t = np.linspace(0.0, horizon, 400_001)
    _, y = signal.step(signal.lti(num, den), T=t)
    final = num[-1] / den[-1]
    outside = np.flatnonzero(np.abs(y - final) > 0.02 * abs(final))
    return 100.0 * max(0.0, y.max() / final - 1.0), float(t[outside[-1] + 1])


def test_a_pi_whose_poles_span_6000_to_1_is_judged_with_its_settling_time():
    """``1/((s+1)(0.001 s+1))`` under PI(1, 0.3): poles -999, -1.84, -0.163; synth said "undetermined within
    3.075 s" (0.012 s doubled 8 times)."""
    spec = parse_spec({"name": "wide", "plant": {"tf": "1/((s+1)*(0.001*s+1))"},
                       "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}},
                       "requirements": [{"type": "step_response", "max_overshoot": 20, "max_settling_time": 30}]})
    res = next(r for r in synth.check(spec, "PI(kp=1, ki=0.3)").requirements if r.type == "step_response")
    # closed loop: (s + 0.3) / (0.001 s^3 + 1.001 s^2 + 2 s + 0.3)
    overshoot, settling = _reference([1.0, 0.3], [0.001, 1.001, 2.0, 0.3], 60.0)
    assert res.met and "undetermined" not in res.message, res.message
    shown = float(re.search(r"settling time ([0-9.]+) s", res.message).group(1))
    assert shown == pytest.approx(settling, abs=0.01), (res.message, settling)
    assert res.value == pytest.approx(overshoot, abs=1e-3)


def test_a_pid_design_on_an_integrator_is_feasible_where_every_filter_meets_the_limits():
    """``12.98/s``, PID with kp, ki, kd fixed and the filter's time constant in [0.005, 0.02]: every one meets
    20 % overshoot and 20 s settling (the reference: 13.2 %, 13.5 s), and the design said "infeasible"."""
    spec = parse_spec({"name": "pid_filter", "plant": {"tf": "12.98/s"},
                       "controller": {"type": "PID", "bounds": {"kp": [0.1017, 0.1017], "ki": [0.1848, 0.1848],
                                                                "kd": [0.2449, 0.2449], "tf": [0.005, 0.02]}},
                       "requirements": [{"type": "step_response", "max_overshoot": 20, "max_settling_time": 20}]})
    result = synth.design(spec)
    assert result.status == "feasible", result.verdict
    for tf in (0.005, 0.02):
        # C = kp + ki/s + kd s/(tf s + 1); closed loop of 12.98 C/s, with the denominators multiplied out
        kp, ki, kd, g = 0.1017, 0.1848, 0.2449, 12.98
        cnum = np.polyadd(np.polymul([kp * tf + kd, kp], [1.0, 0.0]),
                          np.polymul([ki], [tf, 1.0]))  # (kp (tf s + 1) + kd s) s + ki (tf s + 1)
        lnum, lden = g * cnum, np.polymul([1.0, 0.0, 0.0], [tf, 1.0])  # over s * s (tf s + 1)
        overshoot, settling = _reference(list(lnum), list(np.polyadd(lden, lnum)), 60.0)
        assert overshoot < 20.0 and settling < 20.0, (tf, overshoot, settling)
