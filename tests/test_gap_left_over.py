"""diagnose: a verdict whose model still leaves many noise floors of error says so.

An integrating plant behind 0.2 s, its first command -1 (so the fit's rest, read from that first sample, is not the
record's): "explained by drift: it removes 100 % of the held-out error above the noise floor", while what drift
left was hundreds of noise variances (a black-box helper). The summary now says how much is left.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from synth.gap.diagnose import diagnose
from synth.plant import Plant


def test_an_effect_that_leaves_most_of_the_error_says_so():
    rng = np.random.default_rng(44)
    dt, n = 0.01, 3000
    t = np.arange(n) * dt
    u = np.where((t % 4.0) < 2.0, -1.0, 1.0)
    b, a, _ = signal.cont2discrete(([1.0], [1.0, 1.0, 0.0]), dt, "zoh")
    u_late = np.r_[np.full(20, u[0]), u[:-20]]  # 0.2 s of delay; the input held at its first value before
    y = signal.lfilter(b.ravel(), a, u_late) + 0.01 * rng.standard_normal(n)
    d = diagnose(Plant.from_string("1/(s^2+s)"), (t, u, y), candidates=["drift", "delay"], n_null=9)
    att = d.attribution
    assert d.verdict["effects"] == ["drift"]
    drift = next(e for e in att.effects if e.effect == "drift")
    assert drift.j_heldout > 100 * att.noise_floor  # hundreds of noise variances left
    assert f"What is left is still {drift.j_heldout / att.noise_floor:.3g} times the noise floor" in d.summary
