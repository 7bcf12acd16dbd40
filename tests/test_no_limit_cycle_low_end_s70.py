"""The describing-function margin where the critical locus is met only as w -> 0 (black-box helper, session 70)."""

from __future__ import annotations

import math

import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements.no_limit_cycle import NoLimitCycle


def test_a_loop_on_the_negative_axis_at_dc_gets_the_limit_not_the_grid_edge():
    """3.02/(s - 0.684) under a positive-gain lead-lag sits on the negative real axis at w = 0; with a rate limit
    the smallest factor reaching the locus is approached as w -> 0: 1/|L(0)|, -3.3924 dB. The grid's lowest
    point gave -3.367 dB at 0.00463 rad/s."""
    loop = Loop(Plant.from_string("3.02/(s - 0.684)"), Controller("leadlag", {"k": 1.139, "z": 0.46316, "p": 1.5761}))
    req = NoLimitCycle(actuator=[{"type": "rate_limit", "rate": 0.833}], delay=(0.0597, 0.767), min_gain_margin_db=3.0,
                       confirm=False)
    limit_db = -20 * math.log10(abs(1.139 * 0.46316 / 1.5761 * 3.02 / -0.684))
    r = req.evaluate(loop)
    assert r.value == pytest.approx(limit_db, abs=2e-3)
    assert not r.met
