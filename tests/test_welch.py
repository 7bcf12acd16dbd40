"""``welch_psd`` computes scipy.signal.welch's estimate with numpy alone (importing scipy.signal costs about 0.5 s);
it must agree with scipy's on any length, segment, detrend and sample time."""

import numpy as np
import pytest
from scipy import signal

from synth.ident.welch import welch_coherence, welch_density, welch_psd


@pytest.mark.parametrize("detrend", ["constant", "linear"])
def test_welch_psd_is_scipys_welch(detrend):
    rng = np.random.default_rng(7 if detrend == "constant" else 8)
    for _ in range(12):
        n, dt = int(rng.integers(64, 20000)), float(10 ** rng.uniform(-4, -1))
        nper = int(rng.integers(8, n + 1))
        t = np.arange(n) * dt
        x = rng.normal(size=n) + 3.0 * np.sin(2 * np.pi * rng.uniform(0.01, 0.4) / dt * t) + 0.1 * t / dt / n + 5.0
        w, S, count = welch_psd([x], dt, segment=nper * dt, detrend=detrend)
        f, p = signal.welch(x, fs=1.0 / dt, window="hann", nperseg=nper, noverlap=nper // 2, detrend=detrend,
                            scaling="density")
        assert count == 1 + (n - nper) // (nper - nper // 2)
        np.testing.assert_allclose(w, 2 * np.pi * f[1:], rtol=1e-12)
        np.testing.assert_allclose(S, p[1:] / (2 * np.pi), rtol=1e-9, atol=1e-12 * float(np.max(p)))


def test_several_records_are_averaged_segment_by_segment():
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=5000), 2.0 * rng.normal(size=3000)
    _, S, count = welch_psd([a, b], 0.01, segment=2.56)
    _, pa = signal.welch(a, fs=100.0, window="hann", nperseg=256, noverlap=128)
    _, pb = signal.welch(b, fs=100.0, window="hann", nperseg=256, noverlap=128)
    ka, kb = 1 + (5000 - 256) // 128, 1 + (3000 - 256) // 128
    assert count == ka + kb
    np.testing.assert_allclose(S, (ka * pa[1:] + kb * pb[1:]) / (ka + kb) / (2 * np.pi), rtol=1e-9)


def test_welch_density_and_coherence_are_scipys():
    """The gap diagnosis's spectra (any overlap, odd and even segments) against scipy.signal's welch and
    coherence."""
    rng = np.random.default_rng(11)
    for _ in range(12):
        n, dt = int(rng.integers(64, 20000)), float(10 ** rng.uniform(-4, -1))
        nper = int(rng.integers(8, n // 2 + 1))
        hop = int(rng.integers(1, nper + 1))
        u = rng.normal(size=n) + 2.0
        y = np.convolve(u, rng.normal(size=5), mode="same") + 0.5 * rng.normal(size=n)
        f, p = welch_density(u, dt, nper, hop)
        fs, ps = signal.welch(u, fs=1.0 / dt, window="hann", nperseg=nper, noverlap=nper - hop)
        np.testing.assert_allclose(f, fs, rtol=1e-12)
        np.testing.assert_allclose(p, ps, rtol=1e-9, atol=1e-12 * float(np.max(ps)))
        f, g = welch_coherence(u, y, dt, nper, hop)
        fs, gs = signal.coherence(u, y, fs=1.0 / dt, window="hann", nperseg=nper, noverlap=nper - hop)
        np.testing.assert_allclose(g[1:], gs[1:], rtol=1e-8, atol=1e-12)
