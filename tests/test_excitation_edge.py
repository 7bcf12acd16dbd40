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
    # the composite was 7.7 dB off below the sweep's start; the local rational method (a record not at rest) is
    # 0.86 dB off there, 2.8 of its random errors: still worse than inside the band, which stays cut
    assert err_new < 0.5 and err_old > 2 * err_new
    assert r.band.to_dict()["note"] == r.band.note


def test_white_noise_keeps_its_band():
    t = np.arange(0, 200, 0.01)
    r = run(np.random.default_rng(5).normal(size=t.size), t)
    assert r.band.note == "" and "note" not in r.band.to_dict()
    assert r.band.w_min == coherent_band(r.w, r.coherence, r.band.threshold).w_min



def test_synth_s_own_sweep_keeps_its_whole_band():
    """A 0.3-10 rad/s sweep of synth's design: the band keeps its whole bottom and, since issue 16 (session 45:
    the fade-out now lies above w_max), its whole top too; before, it lost up to 0.06 decade below 10 rad/s,
    where the faded input left the estimate more than 1 dB off. The edge test still cuts where the sweep's
    fade-out above w_max leaves only leakage."""
    ts, us = design_sweep(0.3, 10).signal(sample_rate=100)
    rs = run(us, ts)
    uncut = coherent_band(rs.w, rs.coherence, rs.band.threshold)
    assert rs.band.w_min == uncut.w_min <= 0.3
    assert 10 <= rs.band.w_max < uncut.w_max
    kept = rs.band.contains(rs.w) & (rs.w <= 10)
    err = np.abs(20 * np.log10(np.abs(rs.H[kept])) - [exact_db(w) for w in rs.w[kept]])
    assert np.all(err < 1.0)
