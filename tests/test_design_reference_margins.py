"""The design benchmark's independent reference (``benchmarks/design_reference.py``) reads the ``margins`` gain
margin as docs/spec-format.md defines it: two-sided on a conditionally stable loop, the nearer of the upward and
the downward gain change that destabilizes the loop. Checked against closed forms. (Seed 11 #10: the reference
counted only the upward margin, 10.6 dB, on a loop that goes unstable when its gain drops by 4.8 dB, and called
synth's "infeasible" false.)"""

import numpy as np
import pytest

from benchmarks.design_reference import check_point

SPEC = {"requirements": [{"type": "margins", "gain_margin_db": 3.0}], "controller": {"type": "P", "bounds": {}}}


@pytest.mark.parametrize("kp", [0.5, 1.0, 2.0])
def test_unstable_first_order_plant_has_only_a_downward_gain_margin(kp: float) -> None:
    # kp * a / (s - b) is stable for kp * a > b: the gain may fall by kp * a / b
    a, b = 1.849, 0.410682
    e = check_point([a], [1.0, -b], 0.0, SPEC, {"kp": kp})
    assert e.stable
    assert e.values["0:margins:gm"] == pytest.approx(20 * np.log10(kp * a / b), abs=1e-9)


def test_stable_third_order_plant_has_only_the_upward_one() -> None:
    # kp / (s + 1)^3 reaches -1 at w = sqrt(3), where |L| = kp / 8
    e = check_point([1.0], [1.0, 3.0, 3.0, 1.0], 0.0, SPEC, {"kp": 2.0})
    assert e.values["0:margins:gm"] == pytest.approx(20 * np.log10(8 / 2.0), abs=1e-9)


def test_integrator_has_no_phase_crossing_at_zero_frequency() -> None:
    e = check_point([1.0], [1.0, 1.0, 0.0], 0.0, SPEC, {"kp": 1.0})
    assert e.values["0:margins:gm"] == np.inf
