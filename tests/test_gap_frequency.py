"""Gap localization in frequency: prewhitened cross-correlation, coherence, error model, bands."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from synth.data import record_from_arrays
from synth.errors import DataError
from synth.gap.where.coherence import input_residual_coherence
from synth.gap.where.error_model import fit_error_model
from synth.gap.where.frequency import localize_frequency
from synth.gap.where.residual import model_residual
from synth.gap.where.xcorr import prewhitened_xcorr
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

DT = 0.01
G = Plant.from_string("2/(0.1*s+1)")


def coloured_input(n: int, rng: np.random.Generator) -> np.ndarray:
    """Low-passed random input (strongly coloured: a pole at 0.95)."""
    return lfilter([1.0], [1.0, -0.95], rng.normal(size=n))


def coloured_noise(n: int, sigma: float, rng: np.random.Generator) -> np.ndarray:
    return sigma * lfilter([np.sqrt(1 - 0.9**2)], [1.0, -0.9], rng.normal(size=n))


def test_prewhitened_bound_false_alarm_rate_is_near_five_percent_and_the_naive_one_is_not():
    exceed, naive = [], []
    for seed in range(30):
        rng = np.random.default_rng(seed)
        u, e = coloured_input(3000, rng), coloured_noise(3000, 1.0, rng)
        exceed.append(prewhitened_xcorr(u, e, DT, max_lag=30).exceed)
        naive.append(prewhitened_xcorr(u, e, DT, max_lag=30, prewhiten=False).exceed)
    rate, rate_naive = np.mean(exceed), np.mean(naive)
    assert 0.03 < rate < 0.075, rate  # 30 x 61 lags: 5 % +- about 1 % (lags are nearly independent)
    assert rate_naive > 0.3, rate_naive


def test_cross_correlation_finds_an_unmodelled_delay_at_its_lag():
    rng = np.random.default_rng(1)
    t = np.arange(0, 60, DT)
    u = coloured_input(t.size, rng)
    y = simulate_plant(Plant.from_string("2/(0.1*s+1)", delay=0.05), t, u) + coloured_noise(t.size, 0.05, rng)
    xc = prewhitened_xcorr(u, model_residual(G, record_from_arrays(t, u, y)).e, DT)
    assert xc.to_dict()["causal_significant"]
    assert 0 <= xc.lags[np.argmax(np.abs(xc.r))] <= 8  # the peak is right after the input acts
    assert np.mean(xc.exceed[xc.lags < 0]) < 0.1  # no feedback: negative lags only at the false-alarm rate


def test_coherence_threshold_false_alarm_rate():
    frac = [input_residual_coherence(*np.random.default_rng(s).normal(size=(2, 4096)), DT).fraction_significant
            for s in range(20)]
    assert 0.03 < np.mean(frac) < 0.07


def test_correct_model_with_coloured_noise_has_no_band_in_most_seeds():
    t = np.arange(0, 40, DT)
    with_band, wald_alarms = 0, 0
    for seed in range(20):
        rng = np.random.default_rng(100 + seed)
        u = coloured_input(t.size, rng)
        y = simulate_plant(G, t, u) + coloured_noise(t.size, 0.2, rng)
        f = localize_frequency(model_residual(G, record_from_arrays(t, u, y)))
        with_band += bool(f.bands)
        wald_alarms += f.error_model.significant_overall
    assert with_band <= 3 and wald_alarms <= 3


def test_extra_lag_is_significant_in_the_right_band_and_matches_the_true_error():
    rng = np.random.default_rng(7)
    t = np.arange(0, 60, DT)
    u = rng.normal(size=t.size)  # white: excites every frequency
    true = Plant.from_string("2/((0.1*s+1)*(0.02*s+1))")
    y = simulate_plant(true, t, u) + coloured_noise(t.size, 0.05, rng)
    f = localize_frequency(model_residual(G, record_from_arrays(t, u, y)), plant=G)
    m = f.error_model
    assert m.significant_overall and len(f.bands) == 1
    # the true error relative to the model, |1/(0.02 s + 1) - 1|, reaches 10 % at w = 0.1005/0.02 = 5.0 rad/s
    rel = np.abs(true.freqresp(m.w) / G.freqresp(m.w) - 1.0)
    w10 = m.w[np.argmax(rel >= 0.1)]
    assert f.bands[0].w0 == pytest.approx(w10, rel=0.25) and f.bands[0].w1 > 200.0
    # the error model's magnitude matches the true error's (continuous vs ZOH: a few % at 30 rad/s)
    err = true.freqresp(m.w) - G.freqresp(m.w)
    for w in (10.0, 30.0, 100.0):
        k = np.argmin(abs(m.w - w))
        assert abs(m.response[k]) == pytest.approx(abs(err[k]), rel=0.1)


def test_error_model_rejects_an_unexciting_input():
    with pytest.raises(DataError, match="does not excite"):
        fit_error_model(np.ones(500), np.random.default_rng(0).normal(size=500), DT, na=0, nb=3)



@pytest.mark.parametrize("seed", range(6))
def test_an_input_of_a_few_sines_keeps_the_taps_it_pins_down_and_the_response_there(seed: int):
    """k sines pin down at most 2k input taps (fewer where slow sines' lags are collinear to rounding): the model
    keeps those of the ten asked, says so, and its response at the sines' frequencies is the true error's (it used
    to refuse the whole diagnosis, naming an option the user never set). Random sines (1-3, 0.3-20 rad/s), offsets
    and true errors (a gain and a delay of 0-3 samples)."""
    rng = np.random.default_rng(seed)
    t = np.arange(4000) * DT
    k = int(rng.integers(1, 4))
    w = np.sort(rng.uniform(0.3, 20.0, size=k))
    u = rng.uniform(-500, 500) + sum(rng.uniform(5, 30) * np.sin(wi * t + rng.uniform(0, 6)) for wi in w)
    gain, lag = rng.uniform(0.1, 2.0), int(rng.integers(0, 4))
    uc = u - u.mean()
    e = gain * np.r_[np.zeros(lag), uc[:uc.size - lag]] + 0.05 * rng.normal(size=t.size)
    m = fit_error_model(u, e, DT, na=0, nb=10, w=w)
    assert 2 <= m.b.size <= 2 * k and m.nb_asked == 10
    assert m.to_dict()["nb_asked"] == 10 and f"{m.b.size} kept" in m.to_dict()["note"]
    truth = gain * np.exp(-1j * w * lag * DT)
    assert np.max(np.abs(m.response - truth)) < 0.01 * gain
    assert m.significant_overall and m.significant.all()
    rich = fit_error_model(rng.normal(size=4000), rng.normal(size=4000), DT)
    assert rich.b.size == 10 and "nb_asked" not in rich.to_dict()
