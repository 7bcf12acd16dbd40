"""The NLP polish from a controller without gain, minimizing the control effort or peak |T|: the peak's helper
variable started at 0 with the upper bound 1e3 times it, below its lower bound 1e-9, and IPOPT refused the problem
("Ill-posed problem detected: LBX[3] <= UBX[3] was violated"): a RuntimeError traceback from ``synth design`` on a
lead-lag with step limits, peak |S| <= 8 dB and the control effort minimized (benchmarks/held_structure.py, seed
71, problem 7)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.plant import Plant
from synth.requirements import PeakSensitivity
from synth.synthesis.nlp import polish


@pytest.mark.parametrize("objective", ["control_effort", "peak_complementary"])
def test_a_polish_from_a_controller_without_gain_is_a_result_not_an_error(objective: str) -> None:
    plant = Plant.from_string("(2.22*s + 7.0)/(s^2 + 5.5*s + 3.73)", delay=0.0687)
    start = Controller("leadlag", {"k": 0.0, "z": 1.0, "p": 10.0})
    result = polish([PeakSensitivity(type="peak_sensitivity", max_db=8)], [plant], start,
                    {"k": (0.0, 5.3), "z": (0.04, 39.5), "p": (0.08, 158.0)}, [(objective, "minimize", 1.0)],
                    np.geomspace(0.01, 1e3, 200))
    # no gain is the least effort and the lowest peak |T| there is: the polish stays next to k = 0 (an interior
    # point method keeps off the bound)
    assert result.controller.parameters["k"] <= 1e-4
