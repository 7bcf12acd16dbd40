"""diagnose: an effect's parameter intervals are the final fit's, not the grid point's it was refined from.

A black-box helper's resonance (1/(0.5 s + 1) behind wn = 25, zeta = 0.05, PRBS, 1 % noise): fitted zeta 0.04948
with the interval [0.05502, 0.05727], which excludes its own value (and the truth). The interval came from the best
grid point, the value from the point the frequency search refined it to.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from synth.gap.attribution.refit import fit_augmented
from synth.gap.effects import make_effect
from synth.plant import Plant


def _record(seed: int):
    rng = np.random.default_rng(seed)
    dt, n = 0.005, 4000
    t = np.arange(n) * dt
    u = np.repeat(rng.integers(0, 2, n // 20).astype(float), 20)  # PRBS held 0.1 s
    num = np.polymul([1.0], [625.0])
    den = np.polymul([0.5, 1.0], [1.0, 2 * 0.05 * 25.0, 625.0])
    b, a, _ = signal.cont2discrete((num, den), dt, "zoh")
    y = signal.lfilter(b.ravel(), a, u) + 0.01 * rng.standard_normal(n)
    return t, u, y


def test_each_interval_holds_its_own_estimate():
    t, u, y = _record(11)
    fit = fit_augmented(Plant.from_string("1/(0.5*s+1)"), t, u, y, make_effect("resonance"))
    assert abs(fit.params["wn"] - 25.0) < 0.1 and abs(fit.params["zeta"] - 0.05) < 0.003
    for name, (lo, hi) in fit.parameter_ci.items():
        assert lo <= fit.params[name] <= hi, (name, fit.params[name], lo, hi)
    lo, hi = fit.parameter_ci["zeta"]
    assert hi - lo < 0.01  # a real interval, not a wide one that holds anything
