"""Disturbance spectra: a synthesized signal with a known PSD checks level, floor, slope, spike and share."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal as sps
from scipy.optimize import brentq

from synth.data.disturbance import disturbance_from_arrays
from synth.errors import DataError
from synth.ident.bandwidth_suggestion import suggest_bandwidth
from synth.ident.psd import analyze_psd, analyze_records
from synth.ident.spectrum_features import fit_trend, noise_floor, share_frequency
from synth.ident.welch import welch_psd
from synth.sim.signals import psd_signal

DT = 0.001
ALPHA = np.exp(-30 * DT)          # two cascaded discrete first-order low-passes, corner 30 rad/s
SIGMA_E, SIGMA_F = 3.0, 0.01      # drive of the disturbance, white floor
A, W0 = 0.5, 200.0                # supply spike


def disturbance_psd(w: np.ndarray) -> np.ndarray:
    """Exact one-sided PSD [unit^2/(rad/s)] of white noise (variance SIGMA_E^2) through the two filters."""
    z = np.exp(-1j * w * DT)
    h = ((1 - ALPHA) / (1 - ALPHA * z)) ** 2
    return SIGMA_E**2 * DT / np.pi * np.abs(h) ** 2


FLOOR = SIGMA_F**2 * DT / np.pi


def synth_signal(seed: int, seconds: float = 120.0, spike: bool = True) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = int(seconds / DT)
    t = np.arange(n) * DT
    b, a = np.convolve([1 - ALPHA], [1 - ALPHA]), np.convolve([1, -ALPHA], [1, -ALPHA])
    x = sps.lfilter(b, a, SIGMA_E * rng.normal(size=n + 5000))[5000:]
    x = x + SIGMA_F * rng.normal(size=n)
    if spike:
        x = x + A * np.sin(W0 * t + 0.3)
    return x


@pytest.fixture(scope="module")
def analysis():
    return analyze_psd([synth_signal(1), synth_signal(2)], DT)


def test_psd_level_matches_theory(analysis):
    w, S = analysis.w, analysis.psd
    theory = disturbance_psd(w) + FLOOR
    for lo, hi in ((2, 20), (40, 80), (100, 150)):
        sel = (w >= lo) & (w <= hi)
        ratio_db = 10 * np.log10(np.mean(S[sel]) / np.mean(theory[sel]))
        assert abs(ratio_db) < 0.3, (lo, hi, ratio_db)


def test_parseval_total_power(analysis):
    x = np.concatenate([synth_signal(1), synth_signal(2)])
    assert analysis.total_power == pytest.approx(np.var(x), rel=0.03)


def test_noise_floor_against_white_noise_level(analysis):
    assert analysis.floor_db == pytest.approx(10 * np.log10(FLOOR), abs=0.15)
    assert analysis.floor_source == "median of the upper half"


def test_floor_median_bias_correction_with_few_segments():
    rng = np.random.default_rng(5)
    x = rng.normal(size=8192)
    w, S, k = welch_psd([x], DT, segment=4096 * DT)  # 3 segments: the raw median sits ~0.5 dB low
    floor, _ = noise_floor(w, S, k)
    theory = DT / np.pi
    assert abs(10 * np.log10(floor / theory)) < 0.15
    assert 10 * np.log10(np.median(S) / theory) < -0.35


def test_spike_found_at_the_right_frequency_with_its_power(analysis):
    assert len(analysis.spikes) == 1
    (s,) = analysis.spikes
    assert abs(s.w - W0) < 0.25 * analysis.resolution
    assert s.power == pytest.approx(A**2 / 2, rel=0.1)
    assert s.amplitude == pytest.approx(A, rel=0.05)
    assert s.height_db > 20


def test_share_frequency_against_the_analytic_integral(analysis):
    wgrid = np.linspace(0, np.pi / DT, 2_000_001)
    cum = np.cumsum(disturbance_psd(wgrid)) * (wgrid[1] - wgrid[0])
    w90 = float(np.interp(0.9 * cum[-1], cum, wgrid))
    assert analysis.share_frequency == pytest.approx(w90, rel=0.04)
    # the spike's power (A^2/2 at 200 rad/s) lies above w90: counting it moves the share frequency up
    assert analysis.share_frequency_with_spikes > analysis.share_frequency
    disturbance_power = cum[-1]
    assert analysis.disturbance_power == pytest.approx(disturbance_power, rel=0.05)


def test_default_trend_band_ends_where_disturbance_meets_the_floor(analysis):
    knee = brentq(lambda w: 10 * np.log10(disturbance_psd(np.array([w]))[0] / FLOOR + 1) - 3.0, 10, 3000)
    assert analysis.trend.band[1] == pytest.approx(knee, rel=0.15)
    assert any("trend band" in n for n in analysis.notes)


def test_log_log_trend_slope_of_a_power_law():
    # PSD proportional to w^-2 (-20 dB/decade) from 1 to 3000 rad/s, synthesized exactly on the FFT grid
    table = ((1.0, 1e-2), (3000.0, 1e-2 / 3000.0**2))
    x = psd_signal(table, 200_000, DT, np.random.default_rng(4))
    w, S, _ = welch_psd([x], DT)
    trend = fit_trend(w, S, (3.0, 500.0))
    assert trend.slope_db_per_decade == pytest.approx(-20.0, abs=0.5)
    assert trend.value_db(30.0) == pytest.approx(10 * np.log10(1e-2 / 30.0**2), abs=0.5)


def test_several_records_average_segment_weighted():
    x1, x2 = synth_signal(3, 20.0), synth_signal(4, 40.0)
    w, S, k = welch_psd([x1, x2], DT, segment=2.0)
    parts = []
    for x in (x1, x2):
        f, p = sps.welch(x, fs=1 / DT, window="hann", nperseg=2000, noverlap=1000)
        parts.append((p[1:] / (2 * np.pi), 1 + (x.size - 2000) // 1000))
    expect = sum(p * n for p, n in parts) / sum(n for _, n in parts)
    assert k == 19 + 39 and np.allclose(S, expect, rtol=1e-12)
    assert np.allclose(w, 2 * np.pi * f[1:])


def test_noise_record_sets_the_floor():
    rng = np.random.default_rng(9)
    noise = [0.02 * rng.normal(size=60_000)]
    a = analyze_psd([synth_signal(6, 60.0)], DT, noise=noise)
    assert a.floor_source == "noise record"
    assert a.floor_db == pytest.approx(10 * np.log10(0.02**2 * DT / np.pi), abs=0.2)


def test_bandwidth_suggestion_rule(analysis):
    s = suggest_bandwidth(analysis, factor=1.5)
    assert s.min_bandwidth == pytest.approx(1.5 * analysis.share_frequency)
    assert s.spec_entry() == {"type": "bandwidth", "min": float(f"{1.5 * analysis.share_frequency:.3g}")}
    assert "bandwidth >= 1.5 x" in s.to_dict()["rule"]


def test_share_frequency_simple_cases():
    w = np.arange(1.0, 11.0)
    assert share_frequency(w, np.ones(10), 0.5) == pytest.approx(5.5)
    assert share_frequency(w, np.r_[np.ones(5), np.zeros(5)], 0.5) == pytest.approx(3.0)


def test_to_dict_serializes(analysis):
    from synth.outputs import dump_json

    d = analysis.to_dict(curves=True)
    text = dump_json(d)
    assert '"share_frequency"' in text and '"floor_db"' in text and len(d["curves"]["w"]) == analysis.w.size


# ---------------------------------------------------------------------------------------------- errors
def test_too_short_for_the_lowest_frequency():
    with pytest.raises(DataError, match=r"lowest frequency 0.1 rad/s needs segments of 125.7 s"):
        welch_psd([np.random.default_rng(0).normal(size=10_000)], DT, w_min=0.1)


def test_records_with_different_sample_rates():
    t = np.arange(0, 5, DT)
    a = disturbance_from_arrays(t, np.sin(t), source="a.csv")
    b = disturbance_from_arrays(t[::2], np.sin(t[::2]), source="b.csv")
    with pytest.raises(DataError, match=r"^b.csv: sample interval 0.002 s differs from the 0.001 s of a.csv"):
        analyze_records([a, b])


@pytest.mark.parametrize(("t", "x", "match"), [
    (np.arange(20.0), np.r_[np.nan, np.ones(19)], "column 'y': 1 value"),
    (np.arange(20.0), np.ones(20), "the signal is constant"),
    (np.arange(10.0), np.arange(10.0), "at least 16 samples"),
    (np.arange(20.0), np.arange(19.0), "different lengths"),
])
def test_bad_arrays(t, x, match):
    with pytest.raises(DataError, match=match):
        disturbance_from_arrays(t, x)


def test_bad_options():
    x = [np.random.default_rng(0).normal(size=4000)]
    with pytest.raises(DataError, match="share must lie strictly between 0 and 1"):
        analyze_psd(x, DT, share=1.0)
    with pytest.raises(DataError, match="psd: band: expected two increasing"):
        analyze_psd(x, DT, band=(10.0, 5.0))
    with pytest.raises(DataError, match="detrend must be"):
        welch_psd(x, DT, detrend="quadratic")


@pytest.mark.parametrize("seed", range(4))
def test_a_tone_over_white_noise_is_named_not_called_insignificant(seed):
    """A black-box finding: a pure sine over white noise was reported as "not significant" although it carried
    98 % of the mean square. The broadband part is (it is noise); the withheld reason now says so and gives the
    tone's power, A^2 / 2 for amplitude A (the reference), and the share frequency with the spikes counted lies
    at the tone."""
    rng = np.random.default_rng(seed)
    dt, amplitude, w0 = 0.005, float(rng.uniform(0.5, 3.0)), float(rng.uniform(20.0, 150.0))
    t = np.arange(0.0, 60.0, dt)
    x = amplitude * np.sin(w0 * t + rng.uniform(0, 2 * np.pi)) + 0.05 * amplitude * rng.standard_normal(t.size)
    a = analyze_psd([x], dt)
    assert a.share_frequency is None and a.suggestion_withheld.startswith("not significant: the broadband power")
    carried = float(a.suggestion_withheld.split("spike(s) carry ")[1].split(" ")[0])
    assert carried == pytest.approx(amplitude ** 2 / 2, rel=0.03)
    assert abs(a.share_frequency_with_spikes - w0) <= 2.5 * a.resolution
