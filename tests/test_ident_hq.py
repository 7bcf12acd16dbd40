"""Handling-qualities metrics: the computed table of paper_checks.md, crossings, measured data, uncertainty."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from synth.errors import DataError, ModelError
from synth.ident.hq import coherence_random_error, fit_phase_line, hq_from_frd, hq_from_plant
from synth.ident.hq_metrics import find_crossings
from synth.ident.model_phase import continuous_phase
from synth.plant import Plant

# paper_checks.md, "Computed checks": plant, delay, w180, w_BW,phase, w_BW,gain, tau_p, each to the stated digits
TABLE = [
    ("1/(s^2+s+1)", 0.1, "3.262", "1.441", "2.351", "0.0761"),
    ("1/(s*(s+1))", 0.1, "3.111", "0.844", "2.149", "0.0744"),
    ("4/(s*(0.1*s+1))", 0.05, "13.07", "5.56", "8.29", "0.0360"),
]


def _same_digits(value: float, text: str) -> bool:
    decimals = len(text.split(".")[1])
    return f"{value:.{decimals}f}" == text


@pytest.mark.parametrize(("tf", "delay", "w180", "wp", "wg", "tau"), TABLE)
def test_paper_table_all_twelve_numbers(tf, delay, w180, wp, wg, tau):
    m = hq_from_plant(Plant.from_string(tf, delay=delay))
    got = (m.w180, m.bandwidth_phase, m.bandwidth_gain, m.phase_delay)
    assert all(_same_digits(v, t) for v, t in zip(got, (w180, wp, wg, tau))), (got, (w180, wp, wg, tau))


def test_second_order_with_delay_against_closed_form():
    # phase of exp(-0.1 s)/(s^2+s+1): -atan2(w, 1-w^2) - 0.1 w, solved independently
    phase = lambda w: -np.arctan2(w, 1 - w**2) - 0.1 * w  # noqa: E731
    gain_db = lambda w: -10 * np.log10((1 - w**2) ** 2 + w**2)  # noqa: E731
    w180 = brentq(lambda w: phase(w) + np.pi, 1.0, 10.0, xtol=1e-14)
    w135 = brentq(lambda w: phase(w) + 0.75 * np.pi, 0.5, 3.0, xtol=1e-14)
    wg = brentq(lambda w: gain_db(w) - gain_db(w180) - 6.0, 1.01, w180, xtol=1e-14)
    tau = -(phase(2 * w180) + np.pi) / (2 * w180)
    m = hq_from_plant(Plant.from_string("1/(s^2+s+1)", delay=0.1))
    assert m.w180 == pytest.approx(w180, rel=1e-10)
    assert m.bandwidth_phase == pytest.approx(w135, rel=1e-10)
    assert m.bandwidth_gain == pytest.approx(wg, rel=1e-10)
    assert m.phase_delay == pytest.approx(tau, rel=1e-10)
    # attitude response type (no integrator): the bandwidth is the phase bandwidth
    assert (m.response_type, m.bandwidth, m.bandwidth_limit) == ("attitude", m.bandwidth_phase, "phase")


def test_seed_phase_delay_at_20_rad_s_approaches_the_delay():
    # seed 2, sec. 6.2: eq. 2 evaluated at w1 = 20 rad/s gives 0.097 s, close to the 0.1 s delay
    phi = continuous_phase(Plant.from_string("1/(s^2+s+1)", delay=0.1), [20.0])[0]
    assert round(-(phi + 180) / (57.3 * 20), 3) == 0.097


@pytest.mark.parametrize("tf", ["1/(s^2+s+1)", "-2/(s+1)", "(s-1)/((s+1)*(s+2))", "1/(s^2-2*s+5)",
                                "(s^2+0.1*s+4)/(s*(s^2+0.2*s+9))"])
def test_continuous_phase_is_the_unwrapped_phase(tf):
    G = Plant.from_string(tf, delay=0.1)
    w = np.logspace(-3, 2, 4000)
    ph = continuous_phase(G, w)
    ref = np.degrees(np.unwrap(np.angle(G.freqresp(w))))
    diff = ph - ref
    assert np.ptp(diff) < 1e-8 and abs(diff[0] / 360 - round(diff[0] / 360)) < 1e-9
    assert np.cos(np.radians(ph[0])) * G.freqresp([1e-3])[0].real > 0  # same sign of the low-frequency gain


def test_rate_response_takes_the_lesser_and_attitude_the_phase_bandwidth():
    G = Plant.from_string("(s/2+1)/(s*(s/6+1))", delay=0.1)  # lead: the phase stays flat, gain-limited
    rate = hq_from_plant(G)
    assert rate.response_type == "rate" and rate.bandwidth_limit == "gain"
    assert rate.bandwidth == rate.bandwidth_gain < rate.bandwidth_phase
    # independent: |G| 6 dB above |G(w180)| solved from the closed form
    mag = lambda w: 20 * np.log10(np.abs((1j * w / 2 + 1) / (1j * w * (1j * w / 6 + 1))))  # noqa: E731
    wg = brentq(lambda w: mag(w) - mag(rate.w180) - 6.0, 0.1, rate.w180, xtol=1e-14)
    assert rate.bandwidth_gain == pytest.approx(wg, rel=1e-10)
    att = hq_from_plant(G, response_type="attitude")
    assert att.bandwidth == att.bandwidth_phase and att.bandwidth_limit == "phase"


def test_non_monotonic_phase_several_crossings_first_one_used():
    # a lightly damped pole pair at 4 rad/s then a zero pair at 5 rad/s: the phase dives through -180 deg,
    # comes back up, and falls again with the delay
    G = Plant.from_string("(s^2+0.2*s+25)/(s*(s^2+0.2*s+16))", delay=0.1)
    m = hq_from_plant(G)
    c180 = m.crossings["phase_-180"]
    assert [c.direction for c in c180] == [-1, 1, -1]
    # dense independent check: every crossing of the unwrapped phase on a 10^6 point grid
    w = np.linspace(0.01, 30, 1_000_000)
    ph = np.degrees(np.unwrap(np.angle(G.freqresp(w))))
    dense = w[np.flatnonzero(np.diff(np.sign(ph + 180)) != 0)]
    assert np.allclose([c.w for c in c180], dense, rtol=1e-4)
    assert m.w180 == c180[0].w
    assert any(n.startswith("w180: the curve crosses 3 times") for n in m.notes)
    assert len(m.crossings["phase_-135"]) == 3 and m.bandwidth_phase == m.crossings["phase_-135"][0].w


def test_narrow_resonance_is_bracketed():
    # damping 0.002: the phase jumps through -180 deg within 0.1 % of 5 rad/s; a plain grid would miss the re-rise
    G = Plant.from_string("(s^2+0.04*s+26)/(s*(s^2+0.02*s+25))", delay=0.02)
    w = np.linspace(4.9, 5.2, 2_000_001)
    ph = np.degrees(np.unwrap(np.angle(G.freqresp(w))))
    dense = w[np.flatnonzero(np.diff(np.sign(ph + 180)) != 0)]
    got = [c.w for c in hq_from_plant(G).crossings["phase_-180"] if 4.9 < c.w < 5.2]
    assert len(dense) == 2 and np.allclose(got, dense, rtol=1e-6)


def test_find_crossings_without_function_interpolates_in_log_w():
    w = np.array([1.0, 10.0])
    (c,) = find_crossings(w, np.array([0.0, -20.0]), -10.0)
    assert c.w == pytest.approx(np.sqrt(10.0)) and c.direction == -1


def test_no_minus_180_crossing_leaves_metrics_undefined():
    m = hq_from_plant(Plant.from_string("1/(s*(s+1))"))  # phase tends to -180 deg, never crosses it
    assert m.w180 is None and m.bandwidth_gain is None and m.phase_delay is None
    assert m.bandwidth == m.bandwidth_phase == pytest.approx(1.0)
    assert any("never falls through -180" in n for n in m.notes)


# ----------------------------------------------------------------------------------------- measured data
def test_measured_clean_response_matches_the_model():
    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    w = np.logspace(-1, 1.5, 150)
    m = hq_from_frd(w, G.freqresp(w))
    exact = hq_from_plant(G)
    assert m.response_type == "rate" and m.phase_method == "raw"
    for key in ("w180", "bandwidth_phase", "bandwidth_gain", "phase_delay"):
        assert getattr(m, key) == pytest.approx(getattr(exact, key), rel=2e-3), key
    assert m.uncertainty is None


def test_measured_attitude_type_detected():
    G = Plant.from_string("1/(s^2+s+1)", delay=0.1)
    w = np.logspace(-1, 1.5, 80)
    m = hq_from_frd(w, G.freqresp(w) * np.exp(2j * np.pi))
    assert m.response_type == "attitude" and m.bandwidth_limit == "phase"


def test_rough_phase_uses_the_least_squares_line():
    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    exact = hq_from_plant(G)
    w = np.linspace(0.2, 8.0, 200)
    rng = np.random.default_rng(3)
    noise = np.where(w > 1.2 * exact.w180, rng.normal(0.0, 12.0, w.size), 0.0)  # rough only above w180
    H = G.freqresp(w) * np.exp(1j * np.radians(noise))
    raw = hq_from_frd(w, H, phase_fit="raw")
    line = hq_from_frd(w, H)
    assert line.phase_method == "line" and line.phase_line is not None
    assert any("scatters" in n for n in line.notes)
    assert line.w180 == pytest.approx(exact.w180, rel=1e-3)
    # the line through the noisy phase recovers tau_p far better than the raw point at 2 w180
    assert abs(line.phase_delay - exact.phase_delay) < 0.006
    assert abs(line.phase_delay - exact.phase_delay) < abs(raw.phase_delay - exact.phase_delay)
    # the clean curve's least-squares line on the same band gives the same slope
    coef, _, _, _ = fit_phase_line(w, continuous_phase(G, w), line.phase_line.band)
    assert line.phase_line.slope == pytest.approx(coef[1], rel=0.1)


def test_line_extrapolates_when_2w180_is_beyond_the_data():
    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    w = np.linspace(0.2, 5.0, 120)  # w180 = 3.11, 2 w180 = 6.22 is outside
    m = hq_from_frd(w, G.freqresp(w))
    assert m.phase_method == "line" and any("beyond the data" in n for n in m.notes)
    # independent: numpy's straight line through the exact phase on [w180, 5] rad/s, read at 2 w180
    sel = w >= m.w180
    b, a = np.polyfit(w[sel], continuous_phase(G, w[sel]), 1)
    assert m.phase_delay == pytest.approx(-(a + b * 2 * m.w180 + 180) / np.degrees(2 * m.w180), rel=1e-9)
    # the phase still bends above w180, so the extrapolated line overstates tau_p, by under 10 %
    assert 1.0 < m.phase_delay / hq_from_plant(G).phase_delay < 1.1
    with pytest.raises(DataError, match="beyond the data"):
        hq_from_frd(w, G.freqresp(w), phase_fit="raw")


def test_uncertainty_from_coherence_formula_and_growth():
    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    w = np.logspace(-1, 1.5, 400)
    sig = {}
    for g2 in (0.98, 0.9, 0.7, 0.5):
        m = hq_from_frd(w, G.freqresp(w), coherence=np.full(w.size, g2), averages=20)
        sig[g2] = m.uncertainty
    for key in ("w180", "bandwidth_phase", "bandwidth_gain", "bandwidth", "phase_delay"):
        values = [sig[g][key] for g in (0.98, 0.9, 0.7, 0.5)]
        assert values == sorted(values) and len(set(values)) == len(values), key
    # w180: phase error sqrt(1-g2)/(sqrt(g2) sqrt(2 n_d)) over the analytic slope 1/(1+w^2) + 0.1 rad/(rad/s)
    w180 = hq_from_plant(G).w180
    e = np.sqrt(0.1) / (np.sqrt(0.9) * np.sqrt(40))
    assert sig[0.9]["w180"] == pytest.approx(e / (1 / (1 + w180**2) + 0.1), rel=0.01)


def test_uncertainty_matches_monte_carlo_spread():
    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    w = np.logspace(-1, 1.5, 120)
    g2, n_d = 0.9, 10
    e = float(coherence_random_error(g2, n_d))
    predicted = hq_from_frd(w, G.freqresp(w), coherence=np.full(w.size, g2), averages=n_d).uncertainty
    rng = np.random.default_rng(7)
    H0 = G.freqresp(w)
    w180s, w135s = [], []
    for _ in range(300):
        H = H0 * (1 + e * rng.normal(size=w.size)) * np.exp(1j * e * rng.normal(size=w.size))
        m = hq_from_frd(w, H, phase_fit="raw")
        w180s.append(m.w180)
        w135s.append(m.bandwidth_phase)
    # interpolating between two independent noisy points averages part of the noise away: the spread lies
    # between 1/sqrt(2) and 1 times the single-point prediction
    for spread, pred in ((np.std(w180s), predicted["w180"]), (np.std(w135s), predicted["bandwidth_phase"])):
        assert 0.6 * pred < spread < 1.1 * pred


def test_low_coherence_is_flagged():
    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    w = np.logspace(-1, 1.5, 100)
    coh = np.where(w > 4, 0.5, 0.95)
    m = hq_from_frd(w, G.freqresp(w), coherence=coh, averages=5)
    assert m.phase_method == "line"  # coherence at 2 w180 is 0.5 < 0.8
    assert any("2w180" in n and "coherence below" in n for n in m.notes)
    assert any("coherence at 2 w180 is 0.50" in n for n in m.notes)


def test_to_dict_serializes():
    from synth.outputs import dump_json

    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    w = np.logspace(-1, 1.5, 60)
    d = hq_from_frd(w, G.freqresp(w), coherence=np.full(60, 0.9)).to_dict(curves=True)
    text = dump_json(d)
    for key in ("w180", "bandwidth_phase", "bandwidth_gain", "bandwidth", "phase_delay", "uncertainty"):
        assert f'"{key}"' in text
    assert len(d["curves"]["w"]) == 60


# ---------------------------------------------------------------------------------------------- errors
@pytest.mark.parametrize(("kwargs", "match"), [
    ({"w": [1, 2, 2, 3], "H": [1, 1, 1, 1]}, "increase strictly"),
    ({"w": [1, 2, 3, 4], "H": [1, np.nan, 1, 1]}, "finite and non-zero"),
    ({"w": [1, 2, 3, 4], "H": [1, 1, 1]}, "w has 4 points but H has 3"),
    ({"w": [-1, 2, 3, 4], "H": [1, 1, 1, 1]}, "> 0"),
    ({"w": [1, 2, 3, 4], "H": [1, 1, 1, 1], "coherence": [1, 1, 1.2, 1]}, r"\[0, 1\]"),
    ({"w": [1, 2, 3, 4], "H": [1, 1, 1, 1], "averages": 0}, "averages must be >= 1"),
    ({"w": [1, 2], "H": [1, 1]}, "at least 4"),
])
def test_bad_measured_input(kwargs, match):
    with pytest.raises(DataError, match=match):
        hq_from_frd(**kwargs)


def test_bad_options():
    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    with pytest.raises(ModelError, match="response_type must be one of"):
        hq_from_plant(G, response_type="acceleration")
    with pytest.raises(ModelError, match="phase_fit must be one of"):
        hq_from_frd([1, 2, 3, 4], [1, 1, 1, 1], phase_fit="spline")
    with pytest.raises(DataError, match="the phase line needs 3"):
        fit_phase_line(np.arange(1.0, 10.0), np.zeros(9), (20.0, 30.0))
