"""The first-order test of a converged design on the exact requirements (synth.synthesis.ascent_probe), against
python-control's margins, closed-loop poles and a dense |S| (written here, apart from synth's check).

The case was found by a black-box test of ``synth design``: a PID on a double integrator with a zero, both the
downward gain margin and the phase margin binding. The NLP polish converged at ``ki = 0.0221`` and the verdict
called it a local optimum; every point on the segment to ``ki = 0.0263`` passes the check."""

from __future__ import annotations

import control as ct
import numpy as np
import pytest

from synth.controllers import Controller
from synth.design import design
from synth.loop import Loop
from synth.objectives import score
from synth.spec import parse_spec
from synth.synthesis.ascent_probe import ascent_probe, climb
from synth.synthesis.integral_action import objective_terms

TYPE3 = {"name": "type3_pid", "plant": {"tf": "8.67756*(s+0.674272)/(s*(s+0.132228)*(s+3.23829)*s)"},
         "controller": {"type": "PID", "bounds": {"kp": [0, 10], "ki": [0, 10], "kd": [0, 5], "tf": [0.05, 0.05]}},
         "requirements": [{"type": "margins", "gain_margin_db": 6, "phase_margin_deg": 35},
                          {"type": "peak_sensitivity", "max_db": 8}],
         "objective": {"maximize": "integral_gain"}}
CLAIMED = {"kp": 0.00259446, "ki": 0.0220636, "kd": 1.01669, "tf": 0.05}  # the design called a local optimum


def _independent(p: dict[str, float]) -> tuple[bool, float, float, float]:
    """(stable, smallest gain margin in dB either way, phase margin in deg, peak |S| in dB) by python-control."""
    s = ct.tf("s")
    G = 8.67756 * (s + 0.674272) / (s * (s + 0.132228) * (s + 3.23829) * s)
    L = (p["kp"] + p["ki"] / s + p["kd"] * s / (p["tf"] * s + 1)) * G
    stable = bool(np.all(np.real(ct.poles(ct.feedback(L, 1))) < 0))
    gms, pms = ct.stability_margins(L, returnall=True)[:2]
    gm = float(np.min(np.abs(20 * np.log10(gms))))
    w = np.logspace(-4, 3, 200_000)
    peak = float(20 * np.log10(np.max(np.abs(1 / (1 + L(1j * w))))))
    return stable, gm, float(np.min(pms)), peak


def test_the_claimed_optimum_fails_the_first_order_test():
    spec = parse_spec(TYPE3)
    stable, gm, pm, _ = _independent(CLAIMED)
    assert stable and abs(gm - 6.0) < 0.01 and abs(pm - 35.0) < 0.01  # both margins bind there
    better = ascent_probe(spec, Controller("PID", CLAIMED), objective_terms(spec), 0.05)
    assert better is not None and better.parameters["ki"] > CLAIMED["ki"]
    top, steps = climb(spec, Controller("PID", CLAIMED), objective_terms(spec), 0.05)
    assert steps >= 5 and top.parameters["ki"] > 4 * CLAIMED["ki"]
    stable, gm, pm, peak = _independent(top.parameters)
    assert stable and gm >= 6.0 - 1e-3 and pm >= 35.0 - 1e-3 and peak <= 8.0


def test_the_design_is_no_longer_called_a_local_optimum_there():
    result = design(parse_spec(TYPE3))
    p = result.controller.parameters
    assert result.feasible and p["ki"] > 4 * CLAIMED["ki"]
    stable, gm, pm, peak = _independent(p)
    assert stable and gm >= 6.0 - 1e-3 and pm >= 35.0 - 1e-3 and peak <= 8.0
    assert "first-order test" in result.method


@pytest.mark.parametrize("seed", range(4))
def test_at_a_pi_optimum_the_probe_finds_no_real_way_up(seed):
    """PI designs maximizing ki under a peak |S| bound on random stable plants: the converged design of two
    parameters with one binding limit is a true local optimum: the probe finds no step that gains 0.1 %."""
    rng = np.random.default_rng(seed)
    poles = 10 ** rng.uniform(-0.5, 1, 2)
    spec = parse_spec({"name": "pi", "plant": {"tf": f"{float(np.prod(poles)):.6g}/((s+{poles[0]:.6g})*(s+{poles[1]:.6g}))"},
                       "controller": {"type": "PI", "bounds": {"kp": [0, 20], "ki": [0, 200]}},
                       "requirements": [{"type": "peak_sensitivity", "max_db": float(rng.uniform(3, 8))}],
                       "objective": {"maximize": "integral_gain"}})
    result = design(spec)
    assert result.feasible
    assert ascent_probe(spec, result.controller, objective_terms(spec), 0.05) is None


def test_a_step_to_an_undefined_objective_is_no_gain():
    """The design benchmark's seed 22 #57: a PID with ``kp`` 2e-7 and ``ki`` 0 under a bandwidth objective, ``|T(0)|``
    3.4e-6. A step of the probe made the bandwidth NaN (``T(0)`` at 0), and a NaN compared as no worse."""
    spec = parse_spec({"name": "rand_22_57", "plant": {"tf": "2422.25*1/((s+3.42322)*(s+18.3444)*(s+9.40345)*"
                                                          "(s+0.267522))", "delay": 0.888018},
                       "controller": {"type": "PID", "bounds": {"kp": [0.0, 7.42816], "ki": [0.0, 21.7443],
                                                                "kd": [0.0, 2.53756], "tf": [0.0341614, 0.0341614]}},
                       "requirements": [{"type": "peak_sensitivity", "max_db": 1.32784},
                                        {"type": "slew_rate", "rate_limit": 25.7297, "max_error": 1.79649,
                                         "band": [0.0292728, 8.93756]}],
                       "objective": {"maximize": "bandwidth"}})
    start = Controller("PID", {"kp": 2.2479950309640476e-07, "ki": 0.0, "kd": 0.044147755269378613, "tf": 0.0341614})
    top, _ = climb(spec, start, objective_terms(spec), 0.05)
    terms = objective_terms(spec)
    assert np.isfinite(score(Loop(spec.nominal_plant(), top), terms))
    assert score(Loop(spec.nominal_plant(), top), terms) >= score(Loop(spec.nominal_plant(), start), terms)
