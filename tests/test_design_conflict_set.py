"""The deletion filter behind an infeasible verdict's conflict set, where it cannot find a stabilizing start.

Seed 12 #184 of the design benchmark: a lead-lag on an unstable plant with an integrator. The filter holds the
lead-lag's pole at the middle of its range, where no controller of the bounds stabilizes the loop; its start
search raised, and ``synth design`` ended in a traceback instead of its infeasible verdict.
"""

from __future__ import annotations

import warnings

import pytest

import synth
from benchmarks.design_problems import problem
from synth.synthesis.conflict_set import conflict_set
from synth.synthesis.convex_settings import ConvexSettings

SPEC = problem(12, 184).spec


def test_the_filter_without_a_start_gives_no_conflict_set() -> None:
    assert SPEC["controller"]["type"] == "leadlag"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert conflict_set(synth.parse_spec(SPEC), ConvexSettings()) is None


@pytest.mark.slow
def test_the_design_says_infeasible_and_names_the_requirements_by_their_prices() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = synth.design(synth.parse_spec(SPEC))
    assert d.status == "infeasible" and d.controller is None
    assert d.extras["diagnosis"]["conflict_set_method"] == "elastic prices"
    assert set(d.extras["diagnosis"]["conflicting"]) <= {r["type"] for r in SPEC["requirements"]}
    assert d.extras["diagnosis"]["conflicting"]
