"""hq on a measured response: a phase line that cannot measure the phase delay says so instead of failing or
returning a number the data do not show; a crossing's uncertainty counts the phase's scatter (session 68).

A black-box helper: a coherent band ending just above w180 exited 2 with no metric at all ("only 1 point(s) between
1.592 and 1.634 rad/s"); a rough phase whose line past w180 rose gave tau_p = -0.506 +- 0.18 s (truth 0.172 s).
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.ident.hq import crossing_sigma, hq_from_frd
from synth.plant import Plant

G = Plant.from_string("1/(s*(s+1))", delay=0.1)  # w180 3.111 rad/s


def test_a_band_ending_just_past_w180_keeps_the_other_metrics():
    w = np.geomspace(0.3, 3.3, 50)  # 2 w180 beyond the data, one point past w180: the line has no 3 points
    m = hq_from_frd(w, G.freqresp(w), np.full(50, 0.95), 10)
    assert m.w180 == pytest.approx(3.111, rel=2e-3) and m.phase_delay is None
    assert m.bandwidth_phase is not None and m.bandwidth_gain is not None
    assert any("phase delay undefined: the phase line needs 3 points" in n for n in m.notes)


def test_a_rising_phase_line_gives_no_phase_delay():
    w = np.geomspace(0.3, 5.0, 60)
    H = G.freqresp(w)
    past = w > 3.35
    at = np.degrees(np.angle(G.freqresp(np.array([3.35]))[0])) - 360.0  # -188 deg, past w180
    H[past] = np.abs(H[past]) * np.exp(1j * np.radians(at + 10.0 * (w[past] - 3.35)))  # the phase rises
    m = hq_from_frd(w, H, np.full(60, 0.95), 10, phase_fit="line")
    assert m.w180 is not None and m.phase_delay is None
    assert any("the phase line past w180 rises" in n for n in m.notes)


def test_a_crossing_of_rough_data_is_as_uncertain_as_its_scatter():
    rng = np.random.default_rng(3)
    w = np.geomspace(0.5, 2.0, 40)
    true = -180.0 - 37.0 * (w - 1.5)  # crosses at 1.5 rad/s with -37 deg/(rad/s)
    rough = true + 10.0 * rng.standard_normal(40)
    s = crossing_sigma(w, rough, 1.5, 2.0)
    assert 0.1 < s < 1.0  # about 10/37 = 0.27 rad/s; the 2 deg claimed alone gave 0.05
    assert crossing_sigma(w, true, 1.5, 2.0) == pytest.approx(2.0 / 37.0, rel=1e-6)
    assert crossing_sigma(w, np.full(40, -180.0) + rng.standard_normal(40), 1.5, 0.1) == np.inf  # flat: no slope
