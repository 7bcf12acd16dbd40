"""A bandwidth or step limit met by a loop that barely follows the reference says so (a black-box test, session 62:
``P(kp=1e-05)`` on ``1/(s+1)`` "met" a bandwidth floor and an overshoot limit without a word)."""

import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements import Bandwidth, StepResponse

PLANT = Plant.from_string("1/(s+1)")
NOTE = "measured relative to |T(0)|"


@pytest.mark.parametrize(("kp", "noted"), [(1e-5, True), (2.0, True), (2.5, False), (3.0, False)])
def test_the_note_marks_loops_below_minus_3_db_of_tracking(kp, noted):
    # |T(0)| = kp / (1 + kp): 1e-5, 0.667 (below 10^(-3/20) = 0.708), 0.714, 0.75
    loop = Loop(PLANT, Controller("P", {"kp": kp}))
    for requirement in (Bandwidth(min=0.5), StepResponse(max_overshoot=1, max_settling_time=5)):
        result = requirement.evaluate(loop)
        assert result.met  # the documented definitions are relative: the verdict stays, the note says what it means
        assert (NOTE in result.message) == noted, result.message
    if noted:
        assert f"|T(0)| = {kp / (1 + kp):.3g}" in Bandwidth(min=0.5).evaluate(loop).message


def test_integral_action_gets_no_note():
    loop = Loop(PLANT, Controller("PI", {"kp": 1e-3, "ki": 1e-3}))
    assert NOTE not in StepResponse(max_settling_time=1e4).evaluate(loop).message


def test_the_design_that_met_them_with_a_vanishing_gain_says_so(run_cli, tmp_path):
    spec = tmp_path / "v1.yaml"
    spec.write_text('name: v1\nplant: {tf: "1/(s+1)"}\ncontroller: {type: P, bounds: {kp: [0, 10]}}\n'
                    "requirements:\n  - {type: bandwidth, min: 0.5}\n"
                    "  - {type: step_response, max_overshoot: 1, max_settling_time: 5}\n", encoding="utf-8")
    res = run_cli("design", str(spec), "--no-report")
    assert res.code == 0, res.err
    assert res.out.count(NOTE) == 2 and "the loop follows a slow reference to" in res.out
