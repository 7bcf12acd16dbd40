"""The random screen of the parameter box in the multi-parameter design (synth.synthesis.screen).

Two problems of the randomized-truth benchmark (benchmarks/design_problems.py, seed 1) that the local stages
got wrong, checked against the independent reference (benchmarks/design_reference.py): #27, a PID on an
unstable plant that synth called infeasible although the reference holds a point that passes its dense check,
and #19, a rational controller whose design was a local optimum 15.8 % below the reference's best.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import synth
from benchmarks.design_problems import problem
from benchmarks.design_reference import check_point
from benchmarks.design_verification import run_problem
from synth.spec import parse_spec
from synth.synthesis.screen import screen_improving, screen_points, screen_starts


def _design(index: int) -> tuple[object, object]:
    p = problem(1, index)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return p, synth.design(synth.parse_spec(p.spec))


@pytest.mark.slow
def test_false_infeasible_pid_on_an_unstable_plant_is_now_a_design_the_reference_accepts() -> None:
    # the design with integral action alone (the job that finds it; the one without runs the same stages again)
    from synth.design import design_jobs

    p = problem(1, 27)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        jobs, _ = design_jobs(synth.parse_spec(p.spec))
        d = jobs[0]()
    assert "unstable" in p.features and p.spec["controller"]["type"] == "PID"
    assert d.feasible, d.verdict
    assert check_point(p.num, p.den, p.delay, p.spec, dict(d.controller.parameters)).feasible(1e-3)


@pytest.mark.slow
def test_local_optimum_of_a_rational_design_is_left_for_a_screened_start() -> None:
    rec = run_problem(problem(1, 19), time_limit=120.0, budget=0.3)
    assert rec["outcome"] == "agree feasible"
    assert rec["objective_gap"] <= 0.03, rec["objective_gap"]  # 15.8 % before the screen


SPEC = {"name": "pi", "plant": {"tf": "10/((s-1)*(s+5))"}, "requirements": [{"type": "bandwidth", "min": 2.0},
        {"type": "margins", "gain_margin_db": 3}],
        "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}}, "objective": {"maximize": "bandwidth"}}


def test_screen_is_reproducible_and_inside_the_bounds() -> None:
    spec = parse_spec(SPEC)
    a, b = screen_points(spec, 64), screen_points(spec, 64)
    assert [c.parameters for c in a] == [c.parameters for c in b]
    kp = np.array([c.parameters["kp"] for c in a])
    assert kp.min() >= 0 and kp.max() <= 5 and np.sum(kp < 0.05) >= 3  # log-uniform half reaches small gains


def test_screened_starts_are_stable_and_improving_ones_score_better() -> None:
    spec = parse_spec(SPEC)
    from synth.loop import Loop
    from synth.objectives import score

    for c in screen_starts(spec, 3):  # P-like gains below 0.5 leave the unstable pole in place
        assert Loop(spec.nominal_plant(), c).stability().stable
    terms = [("bandwidth", "maximize", 1.0)]
    for c in screen_improving(spec, terms, 3.0):
        assert score(Loop(spec.nominal_plant(), c), terms) > 3.0
        assert synth.check(spec, c).feasible or min(r.slack for r in synth.check(spec, c).requirements) > -0.05


def test_design_jobs_with_and_without_integral_action_combine_to_the_serial_design() -> None:
    from synth.design import design, design_jobs

    spec = parse_spec({"name": "pi", "plant": {"tf": "4/((s+1)*(s+3))", "delay": 0.05},
                       "controller": {"type": "PI", "bounds": {"kp": [0, 10], "ki": [0, 20]}},
                       "requirements": [{"type": "peak_sensitivity", "max_db": 6}],
                       "objective": {"maximize": "crossover"}})
    jobs, combine = design_jobs(spec)
    assert len(jobs) == 2  # crossover can be larger without integral action: both designs run (and here it is)
    combined, serial = combine([job() for job in jobs]), design(spec)
    assert combined.controller.parameters == serial.controller.parameters
    assert combined.objective["value"] == serial.objective["value"] > 0


@pytest.mark.slow
@pytest.mark.parametrize(("seed", "index", "record"), [(14, 69, "seed14_s25_40-79.jsonl")])
def test_a_rational_design_finds_the_basin_a_small_screen_missed(seed: int, index: int, record: str) -> None:
    """Seed 14 #69 (a rational controller of order (0, 3) on an integrating fourth-order plant with a lightly damped
    mode behind 22 ms, minimize peak |S|): with 384 screened controllers synth's design was 8.2 % worse than the
    reference's best (a basin with b0 at its bound and a2 near 0); the screen of 1536 for a rational controller
    finds it. Judged against the stored reference (its best point and its check)."""
    import json
    from pathlib import Path

    from benchmarks.design_verification import generate

    stored = next(r for r in map(json.loads, (Path(__file__).resolve().parents[1] / "reports" / "design_verification"
                                              / record).read_text().splitlines()) if r["index"] == index)
    rec = run_problem(generate(index + 1, seed)[index], time_limit=120.0, stored=stored)
    assert rec["outcome"] == "agree feasible" and rec["synth_passes_reference"], rec["outcome"]
    assert rec["objective_gap"] <= 0.01, rec["objective_gap"]  # was 0.082


@pytest.mark.slow
def test_a_pid_on_an_unstable_plant_reaches_the_basin_only_a_near_miss_leads_to() -> None:
    """Seed 16 #118 (a PID on 483/((s - 1.73)(s + 1.55)(s + 19.3)), gain margin 9.3 dB and delay margin 12 ms,
    |S| <= -24.4 dB up to 0.96 rad/s, maximize bandwidth): the local stages stop at ki ~ 0 with 22.69 rad/s
    and no screened controller both meets the requirements and scores better, so the design was 12.8 % below
    the reference's best (kp 0.70, ki 2.99, kd 0.82). An NLP polish from the screened controller that scores
    better and misses the requirements by the least reaches it. Judged against the stored reference."""
    import json
    from pathlib import Path

    from benchmarks.design_verification import generate

    record = Path(__file__).resolve().parents[1] / "reports" / "design_verification" / "seed16_s27_partial.jsonl"
    stored = next(r for r in map(json.loads, record.read_text().splitlines()) if r["index"] == 118)
    rec = run_problem(generate(119, 16)[118], time_limit=120.0, stored=stored)
    assert rec["outcome"] == "agree feasible" and rec["synth_passes_reference"], rec["outcome"]
    assert rec["objective_gap"] <= 0.01, rec["objective_gap"]  # was 0.128
    assert "misses them by the least led to this design" in rec["synth_verdict"]


def test_near_misses_score_better_stay_stable_and_miss_a_requirement() -> None:
    from synth.loop import Loop
    from synth.objectives import score
    from synth.synthesis.screen import screen_near_improving

    spec = parse_spec({**SPEC, "requirements": [{"type": "bandwidth", "min": 2.0},
                                                {"type": "margins", "gain_margin_db": 3, "phase_margin_deg": 60}]})
    terms = [("bandwidth", "maximize", 1.0)]
    near = screen_near_improving(spec, terms, 3.0, keep=3)
    assert len(near) == 3
    for c in near:
        assert score(Loop(spec.nominal_plant(), c), terms) > 3.0
        assert Loop(spec.nominal_plant(), c).stability().stable
        assert not synth.check(spec, c).feasible
    worst = [min(r.slack for r in synth.check(spec, c).requirements) for c in near]
    assert worst == sorted(worst, reverse=True)  # least violating first


def test_a_second_near_miss_apart_from_the_first_reaches_another_basin() -> None:
    """Seed 26 #41 (a lead-lag on 697.5/(s (s + 65.4)) behind 47 ms, |S| <= -15 dB on [0.022, 2.2] rad/s, peak
    |KS| <= 24.9 dB, bandwidth >= 3.5 rad/s, minimize peak |S|): the local stages and the polish from the least
    violating near miss end at a lead (k at its bound 3.05, z 47.5, p 125) with 5.43 dB, 10.2 % above the
    reference's best, a lag (k 0.66, z 4.33, p 1.23) with 4.58 dB. Every near miss close to the first is a lead;
    the second start, the least violating one apart from it in the box, is a lag and polishes to the reference's
    basin. Judged against the stored reference (its best point and its check)."""
    import json
    from pathlib import Path

    from benchmarks.design_verification import generate

    stored = next(r for r in map(json.loads, (Path(__file__).resolve().parents[1] / "reports" / "design_verification"
                                              / "seed26_s44.jsonl").read_text().splitlines()) if r["index"] == 41)
    rec = run_problem(generate(42, 26)[41], time_limit=120.0, stored=stored)
    assert rec["outcome"] == "agree feasible" and rec["synth_passes_reference"], rec["outcome"]
    assert rec["objective_gap"] <= 0.01, rec["objective_gap"]  # was 0.102
    assert rec["synth_params"]["z"] > rec["synth_params"]["p"]  # a lag
    # since session 50 the screen of 1536 points holds a lag that meets the requirements; the near misses (the
    # draw of 384) are still a lead and, apart from it, a lag: the second start alone reaches the basin
    from synth.synthesis.screen import screen_near_improving

    spec = synth.parse_spec(stored["spec"])
    first, second = screen_near_improving(spec, spec.objective.terms(), -5.43 * (1 - 0.01), keep=2)
    assert first.parameters["z"] < first.parameters["p"] and second.parameters["z"] > second.parameters["p"]


def test_near_misses_are_found_below_a_first_pool_of_unstable_loops() -> None:
    """Seed 28 #20 (a lead-lag on a plant with a mode of damping 0.2 behind 9 ms, |S| <= -18.2 dB up to 4.65 rad/s,
    phase margin 41.3 deg, maximize bandwidth): of the 308 screened controllers that score above 134.7 rad/s, the
    192 that meet the sensitivity bound best all destabilize the loop. Their roots alone were counted, so the
    screen offered no near miss although stable ones score better further down."""
    import json
    from pathlib import Path

    from synth.loop import Loop
    from synth.synthesis.screen import NEAR_POOL, SCREEN_POINTS, screen_near_improving, screen_scores

    stored = next(r for r in map(json.loads, (Path(__file__).resolve().parents[1] / "reports" / "design_verification"
                                              / "seed28_s49.jsonl").read_text().splitlines()) if r["index"] == 20)
    spec, terms = parse_spec(stored["spec"]), [("bandwidth", "maximize", 1.0)]
    assert np.sum(screen_scores(spec, screen_points(spec, SCREEN_POINTS), terms) > 134.7) > NEAR_POOL
    near = screen_near_improving(spec, terms, 134.7, keep=2, n=SCREEN_POINTS)
    assert len(near) == 2
    for c in near:
        assert Loop(spec.nominal_plant(), c).stability().stable
        assert not synth.check(spec, c).feasible


def test_a_lead_lag_screen_holds_the_thin_ridge_of_better_designs() -> None:
    """Seed 28 #20 again: the designs better than the local stages' 137.6 rad/s fill 0.1 % of the box, a thin
    ridge up to the reference's 146.1 rad/s. The screen of 384 held one point scoring above 134.7 rad/s that meets
    the requirements, in the local stages' basin (136.3 rad/s); a lead-lag's screen now draws 1536, which hold
    points on the ridge (the design then ends at 145.9 rad/s, 0.13 % below the reference)."""
    import json
    from pathlib import Path

    from synth.loop import Loop
    from synth.objectives import score
    from synth.synthesis.screen import screen_size

    stored = next(r for r in map(json.loads, (Path(__file__).resolve().parents[1] / "reports" / "design_verification"
                                              / "seed28_s49.jsonl").read_text().splitlines()) if r["index"] == 20)
    spec, terms = parse_spec(stored["spec"]), [("bandwidth", "maximize", 1.0)]
    assert screen_size(spec) == 1536
    best = screen_improving(spec, terms, 134.7)[0]
    assert score(Loop(spec.nominal_plant(), best), terms) > 143.0 and synth.check(spec, best).feasible
