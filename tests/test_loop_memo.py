"""Answers kept for loops asked about again: the same answers, computed once."""

from __future__ import annotations

import synth.synthesis.pattern as pattern_module
import synth.timeresp as timeresp
from synth.controllers import Controller
from synth.forked import allow_fork
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements import StepResponse
from synth.spec import parse_spec
from synth.synthesis.pattern import pattern_search


def test_a_kept_step_is_the_requirements_own_and_the_loops_own(monkeypatch):
    """The delayed step is kept by loop and requirement: asking again gives the first answer without simulating;
    another limit, or the same controller behind another delay, is judged on its own step."""
    plant = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    # overshoot about 7.9 % behind 20 ms; a point no other test asks about (the memo is the process's)
    pi = Controller("PI", {"kp": 1.1305, "ki": 12.031})
    runs: list[int] = []
    original = timeresp.linear_step
    monkeypatch.setattr(timeresp, "linear_step", lambda *a, **k: runs.append(1) or original(*a, **k))
    first = StepResponse(max_overshoot=10).evaluate(Loop(plant, pi))
    simulated = len(runs)
    again = StepResponse(max_overshoot=10).evaluate(Loop(plant, Controller("PI", {"kp": 1.1305, "ki": 12.031})))
    assert simulated >= 1 and len(runs) == simulated  # kept: not simulated again
    tighter = StepResponse(max_overshoot=5).evaluate(Loop(plant, pi))
    longer = StepResponse(max_overshoot=10).evaluate(Loop(Plant(plant.num, plant.den, 0.04), pi))
    assert 7.0 < first.value < 9.0 and first.met
    assert again.value == first.value and again.message == first.message
    assert tighter.value == first.value and not tighter.met  # the same step, judged against its own limit
    assert longer.value > first.value + 1.0  # 20 ms more delay: more overshoot, not the kept step


def test_the_pattern_search_checks_each_point_once(monkeypatch):
    """Exploratory moves come back to points they tried; each point is checked once (the search's path and
    its count of checks are as before: the count includes the points it came back to)."""
    allow_fork(False)  # no helper: every check is made in this process, where the spy sees it
    spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))"},
                       "requirements": [{"type": "peak_sensitivity", "max_db": 6}],
                       "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 20]}},
                       "objective": {"maximize": "integral_gain"}})
    seen: list[tuple[float, ...]] = []
    original = pattern_module.quick_check

    def spy(spec, controller, *args, **kwargs):
        seen.append(tuple(controller.parameters.values()))
        return original(spec, controller, *args, **kwargs)

    monkeypatch.setattr(pattern_module, "quick_check", spy)
    result = pattern_search(spec, Controller("PI", {"kp": 1.0, "ki": 2.0}), [("integral_gain", "maximize", 1.0)])
    assert result.improved and result.controller.parameters["ki"] > 5.0
    assert len(seen) == len(set(seen))  # no point checked twice
    assert result.checks > len(seen)  # the search did come back to points it had tried


def test_a_requirement_that_also_simulates_keeps_its_linear_step():
    """``under: both`` carries the spec's simulation block, whose lists do not hash: the kept step is keyed by the
    limits and the band alone (a TypeError before)."""
    from synth.sim.spec import SimulationSpec

    sim = SimulationSpec.model_validate({"dt": 0.001, "actuator": [{"type": "saturation", "min": -1, "max": 1}]})
    loop = Loop(Plant.from_string("1/(s+1)", delay=0.1), Controller("PI", {"kp": 1.0, "ki": 2.0}))
    both = StepResponse(max_overshoot=15, under="both", simulation=sim).evaluate(loop)
    tighter = StepResponse(max_overshoot=8, under="both", simulation=sim).evaluate(Loop(loop.plant, loop.controller))
    linear = StepResponse(max_overshoot=15).evaluate(Loop(loop.plant, loop.controller))
    assert 9.0 < linear.value < 10.0 and linear.met  # the linear step overshoots 9.5 %
    assert both.met and both.value == linear.value and "simulated step" in both.message
    assert not tighter.met and tighter.value == linear.value  # the linear step breaks 8 %, judged on its own limit
