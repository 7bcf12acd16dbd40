"""A seeded sample of the randomized-truth verification of ``synth.design`` (issue 15, item 1).

Thirty problems of ``benchmarks/design_problems.py`` (seed 2026; the controller structure of each is fixed
below) against the independent reference of ``benchmarks/design_reference.py`` with a cheap search budget.
The sample covers every controller structure (P, PI, PID, lead-lag, rational) and plant kind (unstable
poles, integrators, right-half-plane zeros, lightly damped pairs, delays). It was chosen by cost only: the
problems of indices 0-92 whose synth design and reference search took the least CPU time in one run, per
structure, before the outcome was looked at. (The PID pair was chosen again in session 57, when the first pair,
#14 and #90, had come to take 9-19 s each: over all 93 problems as PIDs, timed in one run, the two cheapest on which
synth gives a verdict, #48 and #70, 0.5 and 0.8 s (the median PID: 13 s); #55, #74, #47 and #82, as cheap, end
"undetermined" and would test no PID design.) Asserted: synth never says "infeasible" where the reference
holds a point that passes its dense check, synth's design always passes that check, synth never crashes (a
one-line ``SynthError`` is a refusal, not a crash), and its objective is never more than 5 % worse than the
reference's best and within 1 % of it in at least 95 % of the feasible problems. Eight more problems have
biproper plants (seed 2027, ``BIPROPER_SAMPLE``). The full benchmark is
``python benchmarks/design_verification.py`` (benchmarks/README.md).
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np
import pytest

from benchmarks.design_problems import problem
from benchmarks.design_reference import check_point
from benchmarks.design_verification import _gap, degenerate_reference, run_problem

pytestmark = [pytest.mark.xdist_group("design_verification"),  # one worker: the records are cached per process
              pytest.mark.slow]

SEED = 2026
SAMPLE = [
    (6, "P"), (10, "P"), (12, "P"), (16, "P"), (18, "P"), (22, "P"), (24, "P"), (28, "P"), (30, "P"), (34, "P"),
    (36, "P"), (40, "P"), (42, "P"), (46, "P"), (48, "P"),
    (17, "PI"), (19, "PI"), (31, "PI"), (43, "PI"), (47, "PI"),
    (48, "PID"), (70, "PID"),
    (3, "leadlag"), (82, "leadlag"), (85, "leadlag"), (91, "leadlag"),
    (80, "rational"), (86, "rational"), (89, "rational"), (92, "rational"),
]
WRONG = ("false infeasible", "false feasible", "false feasible (pole within eps of the axis)", "error")
BIPROPER_SEED = 2027
BIPROPER_SAMPLE = [(5, "P"), (10, "P"), (6, "PI"), (1, "PI"), (12, "PID"), (13, "leadlag"), (3, "leadlag"),
                   (4, "rational")]
"""Biproper plants (zeros up to the order; session 21): of problems 0-20 of seed 2027, each run once with its
structure fixed to ``CONTROLLERS[i % 5]``, the two cheapest per structure in CPU time (one PID, one rational: the
next cost 5-10 s), chosen from the times alone before the outcomes were looked at."""


@cache
def _record(index: int, kind: str, biproper: bool = False) -> dict[str, Any]:
    seed, share = (BIPROPER_SEED, 1.0) if biproper else (SEED, 0.0)
    return run_problem(problem(seed, index, controllers=(kind,), biproper=share), time_limit=120.0, budget=0.3)


@pytest.mark.parametrize(("index", "kind"), SAMPLE, ids=[f"{i}-{k}" for i, k in SAMPLE])
def test_design_agrees_with_reference(index: int, kind: str) -> None:
    rec = _record(index, kind)
    detail = (f"problem {index}: {rec['spec']} -> synth {rec['synth_status']} {rec.get('synth_params')} "
              f"{rec.get('synth_error', '')}, reference {rec['ref_best']}")
    assert rec["outcome"] not in WRONG, detail
    if "objective_gap" in rec and not degenerate_reference(rec):
        assert rec["objective_gap"] <= 0.05, detail


@pytest.mark.parametrize(("index", "kind"), BIPROPER_SAMPLE, ids=[f"biproper-{i}-{k}" for i, k in BIPROPER_SAMPLE])
def test_design_agrees_with_reference_on_a_biproper_plant(index: int, kind: str) -> None:
    rec = _record(index, kind, biproper=True)
    assert "biproper" in rec["features"]
    detail = (f"problem {index}: {rec['spec']} -> synth {rec['synth_status']} {rec.get('synth_params')} "
              f"{rec.get('synth_error', '')}, reference {rec['ref_best']}")
    assert rec["outcome"] not in WRONG, detail
    if "objective_gap" in rec and not degenerate_reference(rec):
        assert rec["objective_gap"] <= 0.05, detail


def test_objective_within_one_percent_in_95_percent_of_the_sample() -> None:
    gaps = [rec["objective_gap"] for rec in (_record(i, k) for i, k in SAMPLE)
            if "objective_gap" in rec and rec["outcome"] == "agree feasible" and not degenerate_reference(rec)]
    assert len(gaps) >= 5
    assert sum(g <= 0.01 for g in gaps) >= 0.95 * len(gaps), [(i, k, round(r.get("objective_gap", 0), 4)) for i, k in SAMPLE
                                                             for r in [_record(i, k)]]


def test_a_claimed_local_optimum_has_no_better_feasible_neighbour() -> None:
    """Where synth's verdict says "a local optimum" (of its grid problem keeping |1 + L| >= 0.05, or over the
    exact feasible set of one parameter), no point within 1 % of each free parameter that passes the
    reference's dense check without tolerance and keeps |1 + L| >= 0.05 is better by more than 0.1 %."""
    claimed = 0
    for index, kind in SAMPLE:
        rec = _record(index, kind)
        if not (rec.get("synth_optimality") or {}).get("local") or "synth_params" not in rec:
            continue
        claimed += 1
        p = problem(SEED, index, controllers=(kind,))
        bounds = p.spec["controller"]["bounds"]
        here = check_point(p.num, p.den, p.delay, p.spec, rec["synth_params"])
        rng = np.random.default_rng(index)
        for _ in range(30):
            trial = {k: float(np.clip(v * (1 + 0.01 * rng.uniform(-1, 1)), *bounds[k])) if k in bounds else v
                     for k, v in rec["synth_params"].items()}
            e = check_point(p.num, p.den, p.delay, p.spec, trial)
            if e.feasible(0.0) and (e.values.get("min|1+L|") or 0.0) >= 0.05 and e.objective is not None:
                assert _gap(p.spec, e.objective, here.objective) <= 1e-3, (index, kind, rec["synth_params"], trial)
    assert claimed >= 10


def test_sample_covers_every_structure_and_plant_kind() -> None:
    kinds = {k for _, k in SAMPLE}
    features = {f.split("(")[0] for i, k in SAMPLE for f in problem(SEED, i, controllers=(k,)).features}
    assert kinds == {"P", "PI", "PID", "leadlag", "rational"} and len(SAMPLE) >= 30
    assert features == {"unstable", "integrator", "rhp_zero", "light", "delay"}

