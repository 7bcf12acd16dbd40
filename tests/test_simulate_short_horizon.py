"""A horizon or cap too short for a verdict is bad input, one line naming the option (it ended in a traceback and
exit 1, which a script reads as "limit cycle")."""

from __future__ import annotations

import pytest

from synth.controllers import Controller
from synth.errors import ModelError
from synth.plant import Plant
from synth.sim.blocks import Saturation
from synth.sim.loops import NonlinearLoop
from synth.sim.verdict import MIN_SAMPLES_AFTER_STEP, step_verdict

SPEC = """\
name: short
plant:
  tf: "1/(s*(s+0.5)^2)"
controller:
  type: P
  bounds: {kp: [0, 5]}
requirements:
  - {type: margins, gain_margin_db: 6}
simulation:
  dt: 0.01
  actuator:
    - {type: saturation, min: -0.5, max: 0.5}
  step: [0, 1]
"""


@pytest.mark.parametrize(("option", "value", "samples"), [("--max-horizon", "0.02", "2"), ("--horizon", "0.02", "2"),
                                                          ("--max-horizon", "0.079", "7.9")])
def test_too_short_is_one_line_and_exit_2(tmp_path, run_cli, option, value, samples):
    spec = tmp_path / "short.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    res = run_cli("simulate", str(spec), "-c", "P(0.2)", option, value, "--out", str(tmp_path / "o"), "-q")
    assert res.code == 2
    lines = res.err.strip().splitlines()
    expected = "must be at most 1/20 of the horizon" if option == "--horizon" else f"leaves {samples} samples of 0.01 s"
    assert len(lines) == 1 and f"{option}: " in lines[0] and expected in lines[0], lines


def test_eight_samples_after_the_step_give_a_verdict(tmp_path, run_cli):
    spec = tmp_path / "short.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    res = run_cli("simulate", str(spec), "-c", "P(0.2)", "--max-horizon", "0.08", "--out", str(tmp_path / "o"), "-q")
    assert res.code == 3, res.err  # undetermined within 0.08 s: a verdict, with its exit code


def test_the_library_refuses_it_too():
    loop = NonlinearLoop(Plant.from_string("1/(s*(s+1))"), Controller("P", {"kp": 1.0}), actuator=[Saturation(-1, 1)],
                         dt=0.01)
    with pytest.raises(ModelError, match=r"max_horizon 1\.05 s leaves 5 samples"):
        step_verdict(loop, 0.0, 1.0, t_step=1.0, max_horizon=1.05)
    assert MIN_SAMPLES_AFTER_STEP == 8
