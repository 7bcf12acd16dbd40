"""A lightly damped mode swept from rest to rest: the coherent band holds it and its peak is the plant's.

A black-box test's noise-free 120 s sweep through ``25/(s^2 + 0.5 s + 25)`` gave a coherent band ending at
4.83 rad/s, below the mode, its last points 1.9 dB low: the mode rings longer than the shorter windows, whose
coherence then falls with their length (leakage, not noise). For runs from rest to rest the whole-run ratio
replaces the composite there (:mod:`synth.ident.resonance_leakage`). Random modes; the records simulated by
scipy on a ten times finer grid; the reference is the transfer function itself.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.ident.spectra import frequency_response


def _sweep_record(seed: int, noise: float):
    rng = np.random.default_rng(seed)
    wn, zeta = rng.uniform(3.0, 8.0), rng.uniform(0.03, 0.07)
    num, den = [wn**2], [1.0, 2 * zeta * wn, wn**2]
    w0, w1, T, fs, fine = wn / 10, 5 * wn, 120.0, 100.0, 10
    t = np.arange(int((2 + T + 30) * fs * fine)) / (fs * fine)
    tt = t - 2.0
    k = np.log(w1 / w0) / T
    u = np.sin(w0 * (np.exp(k * tt) - 1) / k) * np.clip(np.minimum(tt, T - tt) / 2.0, 0.0, 1.0) ** 2
    u[(tt < 0) | (tt > T)] = 0.0
    _, y, _ = signal.lsim((num, den), u, t)
    y = y[::fine] + noise * np.std(y) * rng.normal(size=y[::fine].size)
    return record_from_arrays(t[::fine], u[::fine], y), num, den, wn


@pytest.mark.parametrize(("seed", "noise"), [(0, 0.0), (1, 0.0), (2, 0.01), (3, 0.03)])
def test_the_band_holds_a_lightly_damped_mode_and_its_peak_is_the_plants(seed: int, noise: float) -> None:
    record, num, den, wn = _sweep_record(seed, noise)
    fr = frequency_response([record])
    assert fr.band.w_min < 0.8 * wn and fr.band.w_max > 1.25 * wn, (fr.band.w_min, fr.band.w_max, wn)
    near = (fr.w > 0.9 * wn) & (fr.w < 1.1 * wn)
    truth = np.polyval(num, 1j * fr.w[near]) / np.polyval(den, 1j * fr.w[near])
    off_db = np.abs(20 * np.log10(np.abs(fr.H[near]) / np.abs(truth)))
    assert np.max(off_db) < 0.5, off_db
    assert np.all(np.abs(fr.H[near] / truth - 1.0) <= np.maximum(3.0 * fr.random_error[near], 0.02))
