"""A sweep through an integrating plant: the composite's low end is biased, and its random error must not hide it.

The output of ``k / (s (s + p))`` under a log sweep never comes back to rest, and every window's estimate at the
sweep's lowest frequencies is off by 10-40 % (noise-free too, whatever the window length), while the composite's
random error there counts the noise only (0.2-5 %). Where the local rational method's error was over three times the
composite's, the composite stayed with that error: points 10-200 random errors from the truth. The composite's error
now carries the bias its neighbours show against the method (:mod:`synth.ident.composite_bias`), and the method is
also chosen where its error is no larger than that honest one. The reference is the exact ``k / (s (s + p))``.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lsim

from synth.data import record_from_arrays
from synth.ident.composite_bias import composite_bias
from synth.ident.spectra import frequency_response


def _integrating_sweep(seed: int):
    rng = np.random.default_rng(seed)
    p = 10 ** rng.uniform(-0.3, 1.0)
    k = p * 10 ** rng.uniform(-0.5, 0.5)
    w0, w1 = p / 10 ** rng.uniform(0.5, 1.5), p * 10 ** rng.uniform(0.3, 1.0)
    T = float(rng.uniform(6, 15) * 2 * np.pi / w0)
    dt = float(np.pi / w1 / rng.uniform(10, 25))
    t = np.arange(0, T, dt)
    c = np.log(w1 / w0) / T
    u = np.sin(w0 * (np.exp(c * t) - 1) / c) * np.minimum(1, np.minimum(t, T - t) / (0.03 * T))
    y = lsim(([k], [1, p, 0]), u, t)[1]
    y = y + rng.uniform(0.01, 0.1) * np.std(y) * rng.standard_normal(t.size)
    return record_from_arrays(t, u, y), k, p


def test_the_low_end_of_integrating_plants_is_mostly_within_its_errors() -> None:
    within, worst = [], []
    for seed in range(6):
        record, k, p = _integrating_sweep(seed)
        resp = frequency_response(record)
        w = resp.w
        truth = k / (1j * w * (1j * w + p))
        band = (w >= resp.band.w_min) & (w <= resp.band.w_max)
        low = band & (w < 20 * 2 * np.pi / max(resp.windows))   # the whole-run low end
        assert low.sum() >= 12
        z = np.abs(resp.H / truth - 1) / resp.random_error
        within.append(np.mean(z[low] < 3))
        worst.append(z[low].max())
    # on 846c757: 0.72 of the points within 3 random errors (0.65-0.85 per record), no record's worst point
    # within 15 errors (40-225); now 0.81 (0.72-0.94), 2 of 6. Not solved: at the sweep's first 0.1-0.2
    # decade both estimates can be off (the method's own error too small there), 20-40 % at 0.2-5 %.
    assert np.mean(within) >= 0.78
    assert sum(x < 15 for x in worst) >= 2


def test_one_outlying_neighbour_does_not_make_the_composite_biased() -> None:
    rng = np.random.default_rng(3)
    n = 9
    Hm = np.exp(1j * rng.uniform(0, 1, n))
    Hc = Hm * (1 + 0.01 * rng.standard_normal(n))
    Hm_off = Hm.copy()
    Hm_off[2] *= 5.0                         # the method far off at one used point
    used = np.ones(n, bool)
    used[4] = False
    bias = composite_bias(Hc, np.full(n, 0.01), Hm_off, np.full(n, 0.02), used)
    assert np.all(bias == 0.0)
    Hc_biased = Hm * 0.7                     # the composite 30 % low everywhere: measured at every point
    bias = composite_bias(Hc_biased, np.full(n, 0.01), Hm, np.full(n, 0.02), used)
    assert np.allclose(bias, 0.3 / 0.7 - 2 * np.hypot(0.01, 0.02))
