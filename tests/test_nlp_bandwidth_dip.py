"""The polish's bandwidth objective holds ``|T| >= |T(0)|/sqrt(2)`` at 80 ratios of its bandwidth variable. A dip of
``|T|`` below that level between two samples ends the loop's bandwidth at the dip: the design benchmark's seed 18
#15 (a PID, phase margin 34.19 deg, maximize bandwidth) was polished from 83.5 rad/s to a design the NLP scored at
87.7 rad/s and whose bandwidth is 12.8 rad/s (its ``|T|`` 0.15 % under the level at 13 rad/s). The polish now holds
such a dip in another round from the same start."""

from __future__ import annotations

import numpy as np

from synth.controllers import Controller
from synth.loop import BANDWIDTH_LEVEL, Loop
from synth.plant import Plant
from synth.requirements import MarginsRequirement, StaticSensitivity
from synth.synthesis.nlp import polish

PLANT = Plant.from_string("21526.6/((s+27.4543)*(s+36.3058)*(s+18.7702))")
BOUNDS = {"kp": (0.0, 4.13855), "ki": (0.0, 32.1901), "kd": (0.0, 0.532077), "tf": (0.0128566, 0.0128566)}
START = Controller("PID", {"kp": 1.891372977703147, "ki": 22.386506541008902, "kd": 0.20900283091099567,
                           "tf": 0.0128566})
REQUIREMENTS = [StaticSensitivity(max_db=-16.6435), MarginsRequirement(phase_margin_deg=34.1907)]


def test_a_dip_between_the_ratios_samples_is_held_in_another_round():
    result = polish(REQUIREMENTS, [PLANT], START, BOUNDS, [("bandwidth", "maximize", 1.0)],
                    np.geomspace(0.01, 1e4, 173))
    assert result.success
    loop = Loop(PLANT, result.controller)
    start_bandwidth = Loop(PLANT, START).bandwidth()
    assert abs(start_bandwidth - 83.47) < 0.01
    # the answer is better than its start, not at the dip (12.8 rad/s before the fix), and its |T| stays at or
    # above the level all the way up to its bandwidth (checked on a grid 10x denser than the check's)
    assert loop.bandwidth() > 87.0
    w = np.geomspace(0.01, loop.bandwidth() * 0.999, 20000)
    assert np.min(np.abs(loop.T(w))) >= BANDWIDTH_LEVEL * loop.T0() * (1 - 1e-9)
    assert loop.stability().stable
    assert all(r.slack >= 0 for r in (req.evaluate(loop) for req in REQUIREMENTS))
    # the dip's round is in the history: the first round's answer fell short of its NLP's bandwidth
    assert len(result.history) >= 2
    first = Controller.from_string(result.history[0]["controller"])
    assert Loop(PLANT, first).bandwidth() < 20.0
