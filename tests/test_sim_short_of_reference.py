"""A step that settles on a saturation short of the reference says so, and a step-response limit is not met by it.

A black-box test: ``1/(s+1)``, saturation at +-1, a step to 2 under PI(1, 2) was "settled" with rise 2.2 s, overshoot
0 % and settling 3.9 s, all towards the output's final value 1, half the reference; `synth check` passed a
step_response requirement under simulation. Random first-order plants and limits too low for the reference, against
the closed forms: the output rests at ``k * limit``, a PI's command winds at ``ki * (r - k * limit)``.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.plant import Plant
from synth.sim.blocks import Saturation
from synth.sim.loops import NonlinearLoop
from synth.sim.verdict import step_verdict


@pytest.mark.parametrize("seed", range(3))
def test_a_step_beyond_the_saturation_is_short_of_the_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    k, tau, limit = rng.uniform(0.5, 3.0), rng.uniform(0.2, 2.0), rng.uniform(0.5, 2.0)
    r = k * limit * rng.uniform(1.3, 3.0)            # out of the actuator's reach
    kp, ki = rng.uniform(0.5, 2.0), rng.uniform(0.5, 3.0)
    loop = NonlinearLoop(Plant([k], [tau, 1.0]), Controller("PI", {"kp": kp, "ki": ki}),
                         actuator=[Saturation(-limit, limit)])
    v = step_verdict(loop, 0.0, r)
    assert v.verdict == "settled"
    text = v.evidence.criterion
    short = float(text.split("the output rests ")[1].split(" %")[0])
    assert short == pytest.approx(100 * (r - k * limit) / r, rel=0.01), text
    rate = float(text.split("command moving at ")[1].split(" input")[0])
    assert rate == pytest.approx(ki * (r - k * limit), rel=0.02), text


def test_a_reachable_step_has_no_such_note_and_check_fails_the_unreachable(run_cli, tmp_path) -> None:
    loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("PI", {"kp": 1, "ki": 2}),
                         actuator=[Saturation(-1, 1)])
    assert "short of" not in step_verdict(loop, 0.0, 0.5).evidence.criterion
    spec = tmp_path / "unreach.yaml"
    spec.write_text("name: unreach\nplant: {tf: \"1/(s+1)\"}\ncontroller: {type: PI}\nrequirements:\n"
                    "  - {type: step_response, max_overshoot: 5, max_settling_time: 5, under: simulation}\n"
                    "simulation: {dt: 0.001, actuator: [{type: saturation, min: -1, max: 1}], step: [0, 2]}\n")
    res = run_cli("check", str(spec), "-c", "PI(kp=1, ki=2)")
    assert res.code == 1 and "NOT met" in res.out and "short of the reference 2" in res.out, res.out
