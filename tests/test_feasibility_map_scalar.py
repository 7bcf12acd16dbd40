"""The report's feasibility map with a requirement that has no vectorized form (a step-response limit behind a
delay): a coarser grid, the requirement simulated only where the loop is stable, and there the same slack as the
check. Without the delay the step limit is vectorized (:mod:`synth.exact_steps`): the full grid, the same slacks."""

from __future__ import annotations

import numpy as np
import pytest

from synth.check import check
from synth.controllers import Controller
from synth.loop import Loop
from synth.report.feasibility_map import MAP_GRID, MAP_GRID_SCALAR, column_refined_slack, feasibility_grid, map_grid_size
from synth.requirements import StepResponse
from synth.requirements.margins import UNSTABLE_SLACK
from synth.spec import parse_spec

SPEC = {"name": "pi_step", "plant": {"tf": "6/((s+1)*(s+2)*(s+3))", "delay": 0.05},
        "controller": {"type": "PI", "bounds": {"kp": [0, 12], "ki": [0, 8]}},
        "requirements": [{"type": "step_response", "max_overshoot": 15, "max_settling_time": 8},
                         {"type": "peak_sensitivity", "max_db": 8}],
        "objective": {"maximize": "integral_gain"}}


def test_the_map_of_a_step_limit_is_coarser_and_simulates_only_stable_loops(monkeypatch: pytest.MonkeyPatch) -> None:
    spec = parse_spec(SPEC)
    assert map_grid_size(spec) == MAP_GRID_SCALAR < MAP_GRID
    assert map_grid_size(parse_spec({**SPEC, "requirements": SPEC["requirements"][1:]})) == MAP_GRID
    assert map_grid_size(parse_spec({**SPEC, "plant": {"tf": SPEC["plant"]["tf"]}})) == MAP_GRID
    design = Controller("PI", {"kp": 3.0, "ki": 2.0})
    simulated, counted = [], []
    original = StepResponse._linear
    monkeypatch.setattr(StepResponse, "_linear", lambda self, loop: simulated.append(1) or original(self, loop))
    import synth.requirements.step_response as step_module
    unstable = step_module.closed_loop_unstable
    monkeypatch.setattr(step_module, "closed_loop_unstable", lambda loop: counted.append(1) or unstable(loop))
    xa, xb, A, B, slack = feasibility_grid(spec, design)
    monkeypatch.undo()
    assert not counted  # the D-decomposition's counts stand: no loop's roots counted again before its step
    assert (xa, xb) == ("kp", "ki") and slack.shape == (3, MAP_GRID_SCALAR, MAP_GRID_SCALAR)
    stable = slack[0] > 0
    assert 0 < stable.sum() < stable.size  # high gains destabilize this third-order plant
    assert np.all(slack[1][~stable] <= UNSTABLE_SLACK)
    # every other ki of each column simulated, and in between only near the limit's boundary
    assert stable[::2].sum() <= len(simulated) < 0.75 * stable.sum()
    step = spec.requirements[0]
    rng = np.random.default_rng(0)
    for j, i in zip(*np.nonzero(stable)):
        if j % 2 == 0 or rng.random() < 0.3:  # every simulated row, a sample of the others
            c = Controller("PI", {"kp": float(A[i]), "ki": float(B[j])})
            assert Loop(spec.nominal_plant(), c).stability().stable
            exact = step.slack(Loop(spec.nominal_plant(), c), 20)
            if j % 2 == 0:  # the check's own slack
                assert slack[1, j, i] == exact
            else:  # the check's, or between its neighbours' with their (and the check's) sign
                assert (slack[1, j, i] >= 0) == (exact >= 0)
    met = np.all(slack >= 0, axis=0)
    assert met.any() and not met.all()
    j, i = np.argwhere(met)[0]
    assert check(spec, Controller("PI", {"kp": float(A[i]), "ki": float(B[j])})).feasible


def test_column_refinement_simulates_the_boundary_and_interpolates_elsewhere() -> None:
    rows, columns = 9, 3
    counts = np.zeros((rows, columns), dtype=int)
    counts[6:, 2] = 1  # the top of the last column unstable
    truth = np.array([[(3.5 - j) * (i + 1) for i in range(columns)] for j in range(rows)])  # changes sign at j = 3.5
    calls = []
    slack, computed = column_refined_slack(lambda j, i: calls.append((j, i)) or float(truth[j, i]), counts)
    assert len(calls) == computed.sum() and len(set(calls)) == len(calls)
    assert computed[::2][counts[::2] == 0].all()  # every stable even row
    assert computed[3].all() and not computed[1].any() and not computed[5, :2].any()
    assert computed[5, 2]  # its upper neighbour is unstable: simulated
    assert not computed[7, 2] and slack[7, 2] <= UNSTABLE_SLACK
    stable = counts == 0
    assert np.allclose(slack[stable], truth[stable])  # linear in j: the mean is exact


def test_without_a_delay_the_map_of_a_step_limit_is_the_full_grid_with_the_checks_slacks() -> None:
    spec = parse_spec({**SPEC, "plant": {"tf": SPEC["plant"]["tf"]}})
    _, _, A, B, slack = feasibility_grid(spec, Controller("PI", {"kp": 3.0, "ki": 2.0}))
    assert slack.shape == (3, MAP_GRID, MAP_GRID)
    stable = slack[0] > 0
    assert 0 < stable.sum() < stable.size and np.all(slack[1][~stable] <= UNSTABLE_SLACK)
    step = spec.requirements[0]
    rng = np.random.default_rng(1)
    for j, i in zip(*np.nonzero(stable)):
        if rng.random() < 0.03:
            c = Controller("PI", {"kp": float(A[i]), "ki": float(B[j])})
            assert slack[1, j, i] == pytest.approx(step.slack(Loop(spec.nominal_plant(), c), 20), rel=1e-9, abs=1e-12)
    met = np.all(slack >= 0, axis=0)
    assert met.any() and not met.all()
