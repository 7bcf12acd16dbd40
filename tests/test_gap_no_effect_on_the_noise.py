"""diagnose: no further effect on top of one that has reached the noise.

A pure rate limit at low noise: the rate limit alone took the held-out error to the noise (2.52e-5 against a noise
variance of 2.5e-5), and forward selection added a resonance that took it to 2.39e-5, below the noise: fitting the
noise (a black-box helper; a saturation got a static nonlinearity the same way). A further effect is now tried only
where the accepted model's held-out error is above the noise floor by more than the relevance margin (here the
rate limit's is within it, and before, a supply sag was fitted on top, though not accepted).
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from synth.gap.diagnose import diagnose
from synth.plant import Plant


def _rate_limited(u: np.ndarray, rate: float, dt: float) -> np.ndarray:
    out = np.empty_like(u)
    y = u[0]
    for i, x in enumerate(u):
        y += float(np.clip(x - y, -rate * dt, rate * dt))
        out[i] = y
    return out


def test_a_rate_limit_at_the_noise_gets_no_second_effect():
    rng = np.random.default_rng(57)
    dt, n = 0.01, 4000
    t = np.arange(n) * dt
    u = np.repeat(rng.integers(0, 2, n // 50).astype(float), 50)  # levels held 0.5 s
    b, a, _ = signal.cont2discrete(([1.0], [0.5, 1.0]), dt, "zoh")
    y = signal.lfilter(b.ravel(), a, _rate_limited(u, 2.0, dt)) + 0.005 * rng.standard_normal(n)
    d = diagnose(Plant.from_string("1/(0.5*s+1)"), (t, u, y), candidates=["rate_limit", "supply_sag", "resonance"],
                 n_null=9)
    assert d.verdict["effects"] == ["rate_limit"]
    assert not any("+" in e.effect for e in d.attribution.effects)  # no further effect tried on top (before: sag)
    rl = next(e for e in d.attribution.effects if e.effect == "rate_limit")
    assert abs(rl.parameters["rate"] - 2.0) < 0.1
    assert rl.j_heldout < 1.1 * 0.005**2 * 1.2  # at the noise
