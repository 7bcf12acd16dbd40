"""A feasible start given as ``controller.initial`` is never lost (benchmarks/design_initial.py runs the stored
design problems with the independent reference's points as starts).

Seed 19 #24 of the design benchmark: a lead-lag (k fixed at its bound) on 17.3/(s + 9.36) behind 15.8 ms,
maximizing bandwidth under a static-sensitivity bound. synth alone ends at 138 rad/s (z = 292, p = 127): its convex
runs fix the pole on their own grid and never reach the reference's basin, 144.1 rad/s at z = 5.35, p = 21.6 (a point
that passes synth's check). Given that point as ``initial``, synth used to start its convex stage there and still
answer 138 rad/s; the start is now a candidate and a polish runs from it.
"""

import pytest

from synth import check, design
from synth.controllers import Controller
from synth.loop import Loop
from synth.objectives import score
from synth.spec import parse_spec
from synth.synthesis.integral_action import objective_terms

SPEC = {"name": "rand_19_24", "plant": {"tf": "17.3423*1/((s+9.36186))", "delay": 0.0157582},
        "controller": {"type": "leadlag", "bounds": {"k": [0.0, 2.39046], "z": [0.729915, 291.966],
                                                     "p": [0.729915, 729.915]}},
        "requirements": [{"type": "sensitivity_static", "max_db": -6.4269}, {"type": "bandwidth", "min": 3.20907}],
        "objective": {"maximize": "bandwidth"}}
START = {"k": 2.39046, "z": 5.346957630567468, "p": 21.586876511349203}  # the reference's best point


@pytest.mark.slow
def test_a_feasible_start_the_stages_miss_is_kept_and_polished():
    spec = parse_spec({**SPEC, "controller": {**SPEC["controller"], "initial": START}})
    start = Controller("leadlag", START)
    assert check(spec, start).feasible
    terms = objective_terms(spec)
    start_bandwidth = score(Loop(spec.nominal_plant(), start), terms)
    assert start_bandwidth == pytest.approx(144.1, abs=0.05)
    result = design(spec)
    assert result.feasible and result.certificate.passed
    assert score(Loop(spec.nominal_plant(), result.controller), terms) >= start_bandwidth
    assert result.controller.parameters["z"] < 10.0  # the start's basin, not the stages' (z = 292)
    assert "NLP polish from the spec's initial controller" in result.method
