"""Frequency-response fit (NAVFIT cost, exact delay) and step verification."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.errors import ModelError
from synth.ident.freqfit import coherence_weight, fit_cost, fit_frequency_response
from synth.ident.simulate import simulate_plant
from synth.ident.spectra import frequency_response, rate_to_attitude
from synth.ident.step_verification import verify_step
from synth.ident.sweep_design import design_sweep
from synth.plant import Plant

ROLL = Plant.from_string("31.6/((s+0.49)*(s+2.30))", delay=0.041)        # the seed's hover roll model


def test_cost_matches_hand_computation():
    H = np.array([1.0 + 0j, 2j, -0.5 + 0.5j])
    G = np.array([1.2 + 0.1j, 1.5j + 0.3, -0.4 + 0.6j])
    g2 = np.array([0.9, 0.6, 0.99])
    total = 0.0
    for h, g, c in zip(H, G, g2):
        ddb = 20 * np.log10(abs(g)) - 20 * np.log10(abs(h))
        ddeg = (np.degrees(np.angle(g) - np.angle(h)) + 180) % 360 - 180
        wg = (1.58 * (1 - np.exp(-c))) ** 2
        total += wg * (1.0 * ddb ** 2 + 0.01745 * ddeg ** 2)
    assert fit_cost(G, H, g2) == pytest.approx(20 / 3 * total, rel=1e-12)
    assert coherence_weight(0.0) == 0.0


def test_exact_data_recovers_orders_and_delay():
    G = Plant.from_string("3*(s+2)/((s+0.5)*(s^2+2*s+9))", delay=0.07)
    w = np.geomspace(0.1, 30, 80)
    fit = fit_frequency_response((w, G.freqresp(w), np.ones(w.size)), "1/3")
    np.testing.assert_allclose(fit.plant.num, G.num, rtol=1e-5)
    np.testing.assert_allclose(fit.plant.den, G.den, rtol=1e-5)
    assert fit.plant.delay == pytest.approx(0.07, abs=1e-6) and fit.J < 1e-8
    fixed = fit_frequency_response((w, G.freqresp(w), np.ones(w.size)), "1/3", delay=0.05)
    assert fixed.plant.delay == 0.05 and fixed.J > 1e-3 and not fixed.delay_fitted


def _roll_runs(seed: int, noise: float = 0.05):
    rate = Plant(np.r_[ROLL.num, 0.0], ROLL.den, ROLL.delay)                # roll rate p = s * phi
    rng = np.random.default_rng(seed)
    runs = []
    for _ in range(2):
        t, u = design_sweep(0.4, 12.0).signal(1.0, 50.0)
        u = u + 0.02 * rng.standard_normal(t.size)
        y = simulate_plant(rate, t, u, "zero")
        runs.append(record_from_arrays(t, u, y + noise * np.std(y) * rng.standard_normal(t.size)))
    return runs


@pytest.mark.parametrize("seed", [1, 2])
def test_recovers_seed_roll_model_from_noisy_sweep(seed):
    resp = rate_to_attitude(frequency_response(_roll_runs(seed), 0.4, 12.0))
    fit = fit_frequency_response(resp, "k*exp(-Td*s)/((s+p1)*(s+p2))", w_range=(0.4, 10.0))
    p = fit.parameters
    slow, fast = sorted([p["p1"], p["p2"]])
    assert p["k"] == pytest.approx(31.6, rel=0.04)
    assert slow == pytest.approx(0.49, rel=0.08)       # leakage bias at the lowest frequencies
    assert fast == pytest.approx(2.30, rel=0.06)
    # the simulated input is held between 50 Hz samples: the staircase lags the samples by half a
    # sample, so the data's delay is 0.041 s + 0.01 s
    assert p["Td"] == pytest.approx(0.041 + 0.5 / 50.0, abs=0.004)
    orders = fit_frequency_response(resp, "0/2", w_range=(0.4, 10.0))
    assert orders.J == pytest.approx(fit.J, rel=1e-4)   # the same model class, the same optimum
    assert orders.plant.dc_gain() == pytest.approx(fit.plant.dc_gain(), rel=1e-4)


def test_structure_errors_are_one_line():
    w = np.geomspace(1, 10, 20)
    data = (w, ROLL.freqresp(w), np.ones(20))
    with pytest.raises(ModelError, match="numerator order <= denominator order"):
        fit_frequency_response(data, "3/2")
    with pytest.raises(ModelError, match="has its own delay"):
        fit_frequency_response(data, "k*exp(-T*s)/(s+p)", delay=0.1)
    with pytest.raises(ModelError, match="cannot fit"):
        fit_frequency_response(data, "2/3", w_range=(1, 1.3))
    with pytest.raises(ModelError, match="delay must be"):
        fit_frequency_response(data, "0/2", delay=-1.0)
    with pytest.raises(ModelError, match="'O/2' has no s and no delay"):  # the letter O for a zero, delay held
        fit_frequency_response(data, "O/2", delay=0.0)


def test_step_verification_fit_percent():
    G = Plant.from_string("2/(s+1)", delay=0.1)
    t = np.arange(0, 10, 0.01)
    u = np.where(t > 1, 1.0, 0.0)
    y = 3.0 + simulate_plant(G, t, u)
    assert verify_step(G, record_from_arrays(t, u, y)).fit_percent == pytest.approx(100.0, abs=1e-9)
    # a model with 10 % more gain: the error is 0.1 (y - 3), so NRMSE = 0.1 ||y - 3|| / ||y - mean y||
    v = verify_step(Plant.from_string("2.2/(s+1)", delay=0.1), record_from_arrays(t, u, y))
    expected = 0.1 * np.linalg.norm(y - 3.0) / np.linalg.norm(y - y.mean())
    assert v.nrmse == pytest.approx(expected, rel=1e-9) and v.fit_percent == pytest.approx(100 * (1 - expected))
