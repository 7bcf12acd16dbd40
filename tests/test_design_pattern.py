"""The compass-search fallback (``synth.synthesis.pattern``): where every NLP polish from the random screen
failed, the screened point was returned unoptimized; pattern search on the exact check improves it.

Seed 1, problem 4 of ``benchmarks/design_problems.py``: a lead-lag on a non-minimum-phase plant with a
delay, whose optimum sits in a corner of the box (smallest zero, largest pole). Every polish from the screen
left the stabilizing set; the design was the screened point itself, 8.25 % below the reference's best
bandwidth. From that point, pattern search must reach a design that passes the reference's independent
dense check (``benchmarks/design_reference.check_point``) within 0.5 % of the reference's best.
"""

import pytest

from synth.controllers import Controller
from synth.spec import parse_spec
from synth.synthesis.integral_action import objective_terms
from synth.synthesis.pattern import BOUNDARY_CHECKS, PATTERN_CHECKS, pattern_search

SPEC = {"name": "rand_1_4", "plant": {"tf": "20.7413*(1-s/3.49742)/((s+14.6471)*(s+0.155887))", "delay": 0.168246},
        "controller": {"type": "leadlag", "bounds": {"k": [0.0, 15.0583], "z": [0.076462, 30.5848],
                                                     "p": [0.076462, 76.462]}},
        "requirements": [{"type": "peak_complementary", "max_db": 4.58151}, {"type": "bandwidth", "min": 1.08927}],
        "objective": {"maximize": "bandwidth"}}
SCREENED = {"k": 7.868609194224416, "z": 0.076462, "p": 69.65279761379293}  # synth's answer before the fallback
REFERENCE_BEST = 942.8984921685903  # rad/s, the reference's best (300 random starts + Nelder-Mead), its measure


def test_pattern_search_takes_a_screened_point_to_the_reference_optimum():
    reference = pytest.importorskip("benchmarks.design_reference")
    from synth.plant import Plant

    spec = parse_spec(SPEC)
    result = pattern_search(spec, Controller("leadlag", SCREENED), objective_terms(spec))
    assert result.improved and result.checks <= PATTERN_CHECKS
    plant = Plant.from_string(SPEC["plant"]["tf"])
    before = reference.check_point(plant.num, plant.den, SPEC["plant"]["delay"], SPEC, SCREENED)
    after = reference.check_point(plant.num, plant.den, SPEC["plant"]["delay"], SPEC,
                                  dict(result.controller.parameters))
    assert before.feasible(0.0) and after.feasible(0.0)
    assert before.objective < 0.95 * REFERENCE_BEST
    assert after.objective >= 0.995 * REFERENCE_BEST


def test_pattern_search_moves_a_parameter_the_objective_does_not_read_to_make_room():
    # maximize ki under a peak |S| bound: ki alone stalls at the bound; kp must grow with it
    spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))"},
                       "requirements": [{"type": "peak_sensitivity", "max_db": 6}],
                       "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 20]}},
                       "objective": {"maximize": "integral_gain"}})
    result = pattern_search(spec, Controller("PI", {"kp": 1.0, "ki": 2.0}), [("integral_gain", "maximize", 1.0)])
    from synth.design import design

    best = design(spec).controller.parameters["ki"]  # the certified NLP design: 8.12
    assert result.controller.parameters["ki"] == pytest.approx(best, rel=0.01)
    assert result.controller.parameters["kp"] > 4.0


def test_a_check_that_cannot_be_made_is_a_failed_trial_not_a_crash(monkeypatch):
    # seed 3 problem 1: a trial's Nyquist count did not converge (RuntimeError) and ended the design
    import synth.synthesis.pattern as pattern

    spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))"},
                       "requirements": [{"type": "peak_sensitivity", "max_db": 6}],
                       "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 20]}},
                       "objective": {"maximize": "integral_gain"}})
    real = pattern.quick_check

    def flaky(spec_, c, per_decade=80, margins=True):
        if c.parameters["kp"] > 1.2:
            raise RuntimeError("Nyquist count failed to converge (winding -2.000)")
        return real(spec_, c, per_decade, margins)

    monkeypatch.setattr(pattern, "quick_check", flaky)
    result = pattern.pattern_search(spec, Controller("PI", {"kp": 1.0, "ki": 2.0}),
                                    [("integral_gain", "maximize", 1.0)])
    assert result.improved and result.controller.parameters["kp"] <= 1.2


def test_a_start_closer_to_minus_one_than_the_keeping_level_is_searched_not_returned():
    """Seed 11, problem 152 (unstable plant, rational (2, 3) controller, maximize bandwidth): the convex stage's
    design keeps |1 + L| >= 0.05 on its own grid, yet comes to 0.022 of -1 between its points. The search kept
    0.05 on a denser grid, so the start itself failed and the search returned after one check ("steps down to
    0e+00"). The start's own distance is now the floor: the search moves, and no accepted move comes closer to
    -1 than the start (dense |1 + L| from the polynomials)."""
    import numpy as np

    import synth
    from synth.loop import Loop
    from synth.objectives import score

    spec = parse_spec({"name": "rand_11_152", "plant": {"tf": "741.841*1/((s-2.6612)*(s+81.7929))"},
                       "controller": {"type": "rational", "order": [2, 3],
                                      "bounds": {"b0": [-58778.1, 58778.1], "b1": [-6820.15, 6820.15],
                                                 "b2": [-791.356, 791.356], "a0": [0.0, 864169.0],
                                                 "a1": [0.0, 100271.0], "a2": [0.0, 11634.7]}},
                       "requirements": [{"type": "sensitivity", "max_db": -7.28717, "band": [0.0, 1.01303]},
                                        {"type": "sensitivity_static", "max_db": -24.1099}],
                       "objective": {"maximize": "bandwidth"}})
    start = Controller("rational", {"b0": 44245.08023049825, "b1": 6788.779154205124, "b2": 790.7513040857376,
                                    "a0": 209.1817078145316, "a1": 4308.801793225167, "a2": 48.354781621968606})
    w = np.geomspace(1e-3, 1e5, 200_001)

    def closest(c: Controller) -> float:
        cn, cd = c.tf()
        s = 1j * w
        return float(np.min(np.abs(1.0 + 741.841 * np.polyval(cn, s)
                                   / (np.polyval([1.0, 81.7929 - 2.6612, -2.6612 * 81.7929], s) * np.polyval(cd, s)))))

    assert closest(start) < 0.05
    terms = objective_terms(spec)
    result = pattern_search(spec, start, terms, keeping=0.05)
    assert result.improved and result.checks > 1
    assert synth.check(spec, result.controller, 400).feasible
    plant = spec.nominal_plant()
    assert score(Loop(plant, result.controller), terms) > score(Loop(plant, start), terms)
    assert closest(result.controller) >= 0.9 * closest(start)


@pytest.mark.parametrize(("index", "start", "reference_best", "reached"), [
    (20, {"kp": 1.707171861208554, "ki": 0.06718624210324364}, 3.990492521051015, 0.98),
    (69, {"b0": 46.6384, "b1": 25.372, "a0": 1646.26}, 45.18344251006973, 0.93),
])
def test_moves_along_the_active_boundary_where_coordinate_moves_stall(index, start, reference_best, reached):
    """Seed 16 #20 (a PI on an integrating plant behind a delay: margins, static sensitivity, bandwidth floor)
    and #69 (a rational controller, peak |S| and |KS| bounds), both maximizing bandwidth: the design's answer
    sits on a requirement's boundary where moving any one parameter either breaks the bound or lowers the
    bandwidth, while moving two together along the boundary raises it (#20: 3.28 % below the reference's best,
    #69: 9.77 %), and the coordinate search found no better point. With the boundary moves it reaches within 2 %
    (#20) and 7 % (#69, within its check budget; the design's polish from there ends 1.6 % below), judged by
    the reference's own dense check."""
    reference = pytest.importorskip("benchmarks.design_reference")
    from benchmarks.design_problems import problem

    p = problem(16, index)
    spec = parse_spec(p.spec)
    result = pattern_search(spec, Controller(p.spec["controller"]["type"], start), objective_terms(spec),
                            max_checks=BOUNDARY_CHECKS, keeping=0.05, boundary_moves=True)
    before = reference.check_point(p.num, p.den, p.delay, p.spec, start)
    after = reference.check_point(p.num, p.den, p.delay, p.spec, dict(result.controller.parameters))
    assert before.feasible(0.0) and after.feasible(1e-3)
    assert before.objective < 0.975 * reference_best
    assert result.improved and after.objective >= reached * reference_best
