"""A delay alias the start-up prefers by less than 3.84 noise variances is not taken.

A black-box test: ``2.5(s+1.1)/((s+1)(s+4)) e^(-0.017 s)`` under a +-1 square wave of 2 s, the record cut from
the periodic steady state (5 ms samples, noise 0.005). The averaged period fits 0.017 s and 1.017 s with the gain
reversed alike; the start-up from 'rest' preferred the reversed alias by 0.814 noise variances, and the whole
record was fitted from there: k = -2.50, delay 1.017 s, exit 0. docs/identification.md says that below 3.84 the note
only states the ambiguity: now it does, and the periodic fit's delay stays.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lsim

from synth.data import record_from_arrays
from synth.ident.identification import identify


def test_a_weakly_preferred_alias_leaves_the_delay_and_says_it_is_ambiguous() -> None:
    rng = np.random.default_rng(8)
    dt, sub = 0.005, 20
    tf = np.arange(0, 60, dt / sub)
    uf = np.where((tf % 2) < 1, 1.0, -1.0)
    delayed = np.r_[np.full(68, uf[0]), uf[:-68]]                  # 0.017 s: 68 fine steps
    yf = lsim(([2.5, 2.75], np.polymul([1, 1.0], [1, 4.0])), delayed, tf, interp=False)[1]
    t, u, y = tf[::sub], uf[::sub], yf[::sub]
    keep = t >= 30                                                  # cut from the periodic steady state
    result = identify(record_from_arrays(t[keep] - 30, u[keep], y[keep] + 0.005 * rng.standard_normal(keep.sum())),
                      "k*(s+z)/((s+p1)*(s+p2))", delay="fit")
    fit = result.fit
    assert fit.parameters["k"] > 0 and abs(fit.delay - 0.017) < 0.002, fit.parameters
    assert "the delay is known only up to the 2 s period" in result.whole_record_note
    assert "by 0.814 noise variances" not in result.whole_record_note
