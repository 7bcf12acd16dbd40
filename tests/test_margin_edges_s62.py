"""Two edges a black-box test found (session 62): a gain crossover exactly at L = +1, and a root at the origin."""

import control
import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant


def test_a_crossover_at_plus_one_is_180_degrees_from_minus_one_as_python_control_says():
    # P(2) on s/(s+1)^2: L(j1) = 2j/(1+j)^2 = +1 exactly, |L| tangent to 1 there
    plant = Plant.from_string("s/(s+1)^2")
    loop = Loop(plant, Controller("P", {"kp": 2.0}))
    reference = control.stability_margins(control.tf([2.0, 0.0], [1.0, 2.0, 1.0]))[1]
    assert loop.margins().phase_margin_deg == 180.0 == pytest.approx(reference, abs=1e-5)
    pm, dm = LoopBatch(plant, [Controller("P", {"kp": 2.0})]).phase_and_delay_margins()
    assert pm[0] == 180.0 and dm[0] == pytest.approx(np.pi)  # an extra delay of pi s turns L(j1) to -1


@pytest.mark.parametrize("kp", [0.5, 1.0, 3.0, 8.0])
def test_the_wrap_agrees_with_python_control_on_ordinary_loops(kp):
    plant = Plant.from_string("4/((s+1)*(s+2))")
    pm = Loop(plant, Controller("P", {"kp": kp})).margins().phase_margin_deg
    reference = control.stability_margins(control.tf([4.0 * kp], [1.0, 3.0, 2.0]))[1]
    if kp < 0.5 + 1e-12:  # |L| = 2 kp / |(jw+1)(jw+2)| never reaches 1: no crossover, no phase margin
        assert pm == np.inf
    else:
        assert pm == pytest.approx(reference, abs=1e-6)


def test_a_root_at_the_origin_is_marginally_stable_in_the_table_too(run_cli, tmp_path):
    spec = tmp_path / "c1.yaml"
    spec.write_text('name: c1\nplant: {tf: "1/(s*(s+1))", delay: 0.2}\ncontroller: {type: P, bounds: {kp: [0, 5]}}\n'
                    "requirements:\n  - {type: margins, gain_margin_db: 6}\n", encoding="utf-8")
    res = run_cli("check", str(spec), "-c", "P(0)")
    assert res.code == 1
    row = next(line for line in res.out.splitlines() if line.startswith("closed-loop stability"))
    assert "marginally stable" in row and "unstable root" not in row
