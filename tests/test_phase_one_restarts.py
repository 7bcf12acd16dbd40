"""Restarts of the convex stage's phase 1 stop when they head to the infeasible total an earlier start reached
(synth.synthesis.phase_one_stop, ConvexSettings.restart_limit): the same verdicts in fewer solves."""

from __future__ import annotations

import numpy as np
import pytest

import synth
from benchmarks.design_problems import problem
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.multi import convex_runs
from synth.synthesis.phase_one_stop import heading_above


def test_a_geometric_tail_is_extrapolated_to_its_limit() -> None:
    rng = np.random.default_rng(64)
    for _ in range(200):
        limit, scale, ratio = 10 ** rng.uniform(-4, 0), 10 ** rng.uniform(-1, 1), rng.uniform(0.05, 0.85)
        totals = list(limit + scale * ratio ** np.arange(int(rng.integers(3, 12))))
        assert heading_above(totals, limit * (1 - 1e-6))
        assert not heading_above(totals, limit * (1 + 1e-3) + 1e-9 * scale)
    # a decrease that grows (the start is leaving a plateau), or a total that rose, is no tail to extrapolate
    assert not heading_above([1.0, 0.95, 0.5], 1e-3)
    assert not heading_above([1.0, 1.2, 1.1], 1e-3)
    # with no earlier total to compare against, nothing stops
    assert not heading_above([1.0, 0.5, 0.25], float("inf"))


@pytest.mark.parametrize("index", [1, 17, 57])
def test_the_convex_stage_gives_the_same_verdicts_in_fewer_solves(index: int) -> None:
    # seed 5 of the design benchmark's generator: an infeasible P and two PIs whose seven starts each crept to
    # the same elastic total (157, 64 and 108 solves before; 67, 25 and 41 with the stop)
    spec = synth.parse_spec(problem(5, index).spec)
    every = convex_runs(spec, ConvexSettings(restart_limit=0.0))
    stopped = convex_runs(spec, ConvexSettings())
    assert [r.status for _, r in stopped] == [r.status for _, r in every]
    assert "infeasible" in [r.status for _, r in every]
    for (_, a), (_, b) in zip(every, stopped):
        assert (a.objective_value is None) == (b.objective_value is None)
        if a.objective_value is not None:
            assert b.objective_value == pytest.approx(a.objective_value, rel=1e-6)
    assert sum(d.solves for d, _ in stopped) < 0.8 * sum(d.solves for d, _ in every)
