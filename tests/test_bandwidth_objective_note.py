"""A design that maximizes a bandwidth measured from a tiny |T(0)| says so in its verdict.

The -3 dB bandwidth is measured from |T(0)| (python-control's convention). A PID free to drop kp and ki
can make |T(0)| vanish (derivative action alone), and then |T| stays above 0.71 |T(0)| up to kHz: a huge
"bandwidth" for a loop that does not follow a slow reference at all. The design is what the spec asks for,
so the verdict keeps it and adds a note with |T(0)| (checked here against the closed loop's DC gain
computed from the polynomials, not synth's loop).
"""

import numpy as np

from synth import Controller, design, parse_spec
from synth.loop import Loop
from synth.results import objective_label


def _spec(kp_lo: float) -> dict:
    return {"name": "degen", "plant": {"tf": "2/((s+1)*(s+2))"},
            "controller": {"type": "PID", "bounds": {"kp": [kp_lo, 20], "ki": [0, 0], "kd": [0, 5],
                                                     "tf": [0.01, 0.01]}},
            "requirements": [{"type": "peak_sensitivity", "max_db": 6}], "objective": {"maximize": "bandwidth"}}


def _t0(kp: float) -> float:  # L(0) = kp * G(0) = kp, T(0) = L(0)/(1 + L(0))
    return kp / (1 + kp)


def test_a_tiny_static_gain_is_named_in_the_objective_and_the_verdict():
    spec = parse_spec(_spec(0.0))
    tiny = Controller("PID", {"kp": 1e-4, "ki": 0.0, "kd": 2.0, "tf": 0.01})
    label = objective_label(spec, Loop(spec.nominal_plant(), tiny))
    assert np.isclose(abs(Loop(spec.nominal_plant(), tiny).T0()), _t0(1e-4), rtol=1e-9)
    assert "|T(0)| = 0.0001 " in label["note"] and "-80 dB" in label["note"]
    result = design(spec)
    assert result.feasible
    t0 = _t0(result.controller.parameters["kp"])
    assert t0 < 1e-3  # the degenerate optimum this note is for (kp -> 0, derivative action alone)
    assert "Note: this bandwidth is measured 3 dB below |T(0)|" in result.verdict


def test_a_tracking_loop_gets_no_note():
    spec = parse_spec(_spec(5.0))  # kp >= 5: |T(0)| >= 0.83, within 3 dB of 1
    label = objective_label(spec, Loop(spec.nominal_plant(), Controller("PID", {"kp": 5.0, "ki": 0.0, "kd": 0.1,
                                                                                "tf": 0.01})))
    assert "note" not in label
