"""The coherent band stops where the input stops exciting: a sweep from 0.3 rad/s estimated down to 0.21 rad/s
had coherence 0.98 there and a magnitude 7.7 dB off; white noise keeps its band.
Plant responses from scipy.signal.lsim (not synth's simulator)."""

from __future__ import annotations

import numpy as np
from scipy.signal import lsim

from synth.data import record_from_arrays
from synth.ident.coherence import coherent_band
from synth.ident.spectra import frequency_response
from synth.ident.sweep_design import design_sweep

NUM, DEN = [-0.5, 1.0], [1.0, 2.0, 1.0]  # (1 - 0.5 s) / (s + 1)^2


def exact_db(w: float) -> float:
    s = 1j * w
    return float(20 * np.log10(abs((1 - 0.5 * s) / (s + 1) ** 2)))


def run(u: np.ndarray, t: np.ndarray, seed: int = 2):
    y = lsim((NUM, DEN), u, t)[1] + 0.005 * np.random.default_rng(seed).normal(size=t.size)
    return frequency_response(record_from_arrays(t, u, y))


def test_a_sweep_s_band_starts_where_the_sweep_does():
    t = np.arange(0, 120, 0.01)
    k = 120 / np.log(100)
    u = np.sin(0.3 * k * (np.exp(t / k) - 1))  # 0.3 -> 30 rad/s, equal time per decade
    r = run(u, t)
    uncut = coherent_band(r.w, r.coherence, r.band.threshold)
    assert uncut.w_min < 0.22  # what the coherence alone says
    assert r.band.w_min > 0.25 and "cut below" in r.band.note
    i = int(np.argmin(abs(r.w - r.band.w_min)))
    j = int(np.argmin(abs(r.w - uncut.w_min)))
    err_new = abs(20 * np.log10(abs(r.H[i])) - exact_db(r.w[i]))
    err_old = abs(20 * np.log10(abs(r.H[j])) - exact_db(r.w[j]))
    assert err_old > 6 and err_new < err_old / 2
    assert r.band.to_dict()["note"] == r.band.note


def test_white_noise_keeps_its_band():
    t = np.arange(0, 200, 0.01)
    r = run(np.random.default_rng(5).normal(size=t.size), t)
    assert r.band.note == "" and "note" not in r.band.to_dict()
    assert r.band.w_min == coherent_band(r.w, r.coherence, r.band.threshold).w_min



def test_synth_s_own_sweep_loses_only_its_biased_top_edge():
    """A 0.3-10 rad/s sweep of synth's design: the band keeps its whole bottom and is cut by at most 0.06
    decade at the top, where the input falls away and the estimate is more than 1 dB off."""
    ts, us = design_sweep(0.3, 10).signal(sample_rate=100)
    rs = run(us, ts)
    uncut = coherent_band(rs.w, rs.coherence, rs.band.threshold)
    assert rs.band.w_min == uncut.w_min <= 0.3
    assert 0.87 * 10 <= rs.band.w_max < uncut.w_max
    cut = (rs.w > rs.band.w_max) & (rs.w <= uncut.w_max)
    err = np.abs(20 * np.log10(np.abs(rs.H[cut])) - [exact_db(w) for w in rs.w[cut]])
    assert np.all(err > 1.0)
