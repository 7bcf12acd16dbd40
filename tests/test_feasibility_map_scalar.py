"""The report's feasibility map with a requirement that has no vectorized form (a step-response limit): a
coarser grid, the requirement simulated only where the loop is stable, and there the same slack as the check."""

from __future__ import annotations

import numpy as np

from synth.check import check
from synth.controllers import Controller
from synth.loop import Loop
from synth.report.figures import MAP_GRID, MAP_GRID_SCALAR, feasibility_grid, map_grid_size
from synth.requirements.margins import UNSTABLE_SLACK
from synth.spec import parse_spec

SPEC = {"name": "pi_step", "plant": {"tf": "6/((s+1)*(s+2)*(s+3))"},
        "controller": {"type": "PI", "bounds": {"kp": [0, 12], "ki": [0, 8]}},
        "requirements": [{"type": "step_response", "max_overshoot": 15, "max_settling_time": 8},
                         {"type": "peak_sensitivity", "max_db": 8}],
        "objective": {"maximize": "integral_gain"}}


def test_the_map_of_a_step_limit_is_coarser_and_simulates_only_stable_loops() -> None:
    spec = parse_spec(SPEC)
    assert map_grid_size(spec) == MAP_GRID_SCALAR < MAP_GRID
    assert map_grid_size(parse_spec({**SPEC, "requirements": SPEC["requirements"][1:]})) == MAP_GRID
    design = Controller("PI", {"kp": 3.0, "ki": 2.0})
    xa, xb, A, B, slack = feasibility_grid(spec, design)
    assert (xa, xb) == ("kp", "ki") and slack.shape == (3, MAP_GRID_SCALAR, MAP_GRID_SCALAR)
    stable = slack[0] > 0
    assert 0 < stable.sum() < stable.size  # high gains destabilize this third-order plant
    assert np.all(slack[1][~stable] <= UNSTABLE_SLACK)
    step = spec.requirements[0]
    rng = np.random.default_rng(0)
    for j, i in zip(*np.nonzero(stable)):
        if rng.random() < 0.15:  # a sample of the stable points: the check's own slack
            c = Controller("PI", {"kp": float(A[i]), "ki": float(B[j])})
            assert Loop(spec.nominal_plant(), c).stability().stable
            assert slack[1, j, i] == step.slack(Loop(spec.nominal_plant(), c), 20)
    met = np.all(slack >= 0, axis=0)
    assert met.any() and not met.all()
    j, i = np.argwhere(met)[0]
    assert check(spec, Controller("PI", {"kp": float(A[i]), "ki": float(B[j])})).feasible
