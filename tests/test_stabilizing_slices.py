"""Around a design on an open-loop unstable plant, the verdict says how far each gain may move (issue 15, item 2).

Plant ``10/((s - 1)(s + 5))`` under PI: the closed-loop polynomial is ``s^3 + 4 s^2 + (10 kp - 5) s + 10 ki``,
and Routh's conditions give the stabilizing set in closed form: ``ki > 0`` and ``kp > 1/2 + ki/4``. With ki
fixed, kp is stabilizing above ``1/2 + ki/4``; with kp fixed, ki between 0 and ``4 kp - 2``. synth's slices
(D-decomposition with its own stability code) are checked against these at random design points, to 1e-5:
synth counts a closed-loop pole within its stability floor (about 1e-6 of the loop's frequency scale) of the axis
as not stable, which moves each end by about that much.
"""

import numpy as np
import pytest

from synth import Controller, design, parse_spec
from synth.synthesis.stabilizing_slices import open_loop_unstable, stabilizing_slices

SPEC = {"name": "upi", "plant": {"tf": "10/((s-1)*(s+5))"},
        "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}},
        "requirements": [{"type": "bandwidth", "min": 2.0}, {"type": "margins", "gain_margin_db": 3}],
        "objective": {"maximize": "bandwidth"}}


@pytest.mark.parametrize("seed", range(5))
def test_each_gains_slice_matches_routh(seed):
    rng = np.random.default_rng(seed)
    ki = float(rng.uniform(0.1, 5.0))
    kp = float(rng.uniform(0.5 + ki / 4 + 0.05, 5.0))
    slices = stabilizing_slices(parse_spec(SPEC), Controller("PI", {"kp": kp, "ki": ki}))
    [(kp_lo, kp_hi)] = slices["kp"]
    assert kp_lo == pytest.approx(0.5 + ki / 4, rel=1e-5) and kp_hi == 5.0
    [(ki_lo, ki_hi)] = slices["ki"]
    assert 0.0 <= ki_lo < 1e-4 and ki_hi == pytest.approx(min(5.0, 4 * kp - 2), rel=1e-5)


def test_the_design_verdict_and_json_say_where_the_stabilizing_set_is():
    spec = parse_spec(SPEC)
    assert open_loop_unstable(spec)
    result = design(spec)
    assert result.feasible
    ki = result.controller.parameters["ki"]
    kp_lo = result.to_dict()["stabilizing_slices"]["kp"][0][0]
    assert kp_lo == pytest.approx(0.5 + ki / 4, rel=1e-5)
    assert "Around this design the loop stays stable" in result.verdict
    # the intervals' ends that the stability floor sets (not a root crossing the axis) are named as such
    assert "every closed-loop root left of -1e-06 rad/s, synth's stability floor" in result.verdict


def test_a_stable_plant_gets_no_slices_sentence():
    stable = {**SPEC, "plant": {"tf": "10/((s+1)*(s+5))"}}
    spec = parse_spec(stable)
    assert not open_loop_unstable(spec)
    result = design(spec)
    assert result.feasible and "stabilizing_slices" not in result.to_dict()
    assert "Around this design" not in result.verdict
