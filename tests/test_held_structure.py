"""The certified outer loop's designs under the surrogate hold a free structural parameter (a PID's filter) at its
value in the design without the step limits (synth.synthesis.surrogate): one convex run per design instead of
the structural grid's eleven or more, the result still meeting the limits in an independent step."""

from __future__ import annotations

import warnings

import pytest

import synth
from benchmarks.held_structure import spec_of
from benchmarks.step_design_verification import meets, problem, step_metrics
from synth.requirements.base import fmt


@pytest.mark.slow
def test_a_pid_with_a_free_filter_is_designed_with_the_filter_held_and_meets_its_step_limits() -> None:
    spec = spec_of(71, 0)  # a PID whose filter is free over two decades; overshoot <= 5 %, settling <= 96.9 s
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = synth.design(synth.parse_spec(spec))
    assert result.feasible and result.certificate.passed
    lo, hi = spec["controller"]["bounds"]["tf"]
    held = result.extras["surrogate"]["held"]
    assert set(held) == {"tf"} and lo <= held["tf"] <= hi
    assert f"tf held at {fmt(held['tf'])} s" in result.verdict
    # the step of the closed loop from its poles and residues (the benchmark's reference, no synth code)
    p = dict(result.controller.parameters)
    num, den = problem(71, 0, 0.5)["_plant"]
    assert meets(step_metrics(num, den, "PID", p), {"max_overshoot": 5.0, "max_settling_time": 96.89527018136233},
                 0.0, 0.0)
    # the search of the filter's whole grid in every design of the bisection reached ki = 3.921 (d4d891e)
    assert p["ki"] >= 0.99 * 3.921


@pytest.mark.slow
def test_when_no_level_passes_with_the_structure_held_the_bisection_searches_its_grid(monkeypatch) -> None:
    from synth.spec import Spec

    fixed = Spec.with_parameter_fixed

    def nothing_designs(spec, key, value):  # every design with the filter held: no gain left to design with
        spec = fixed(spec, key, value)
        return fixed(fixed(spec, "kp", 0.0), "ki", 0.0) if key == "tf" else spec

    monkeypatch.setattr(Spec, "with_parameter_fixed", nothing_designs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = synth.design(synth.parse_spec(spec_of(71, 0)))
    assert result.feasible and result.extras["surrogate"]["held"] is None and "held at" not in result.verdict
    # d4d891e's design reached ki = 3.921 here; since the convex stage keeps its best iterate that passes the exact
    # check when its last refinement fails it (session 71, synth.synthesis.convex_exact), 3.984: not below it, and
    # meeting the step limits in the benchmark's independent step
    p = dict(result.controller.parameters)
    assert p["ki"] >= (1 - 2e-3) * 3.921
    num, den = problem(71, 0, 0.5)["_plant"]
    assert meets(step_metrics(num, den, "PID", p), {"max_overshoot": 5.0, "max_settling_time": 96.89527018136233},
                 0.0, 0.0)
