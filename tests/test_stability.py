"""Closed-loop stability, exact with delay: cross-checks against python-control, closed forms and
high-order Pade approximations."""

import control
import numpy as np
import pytest
from scipy.optimize import brentq

from synth.plant import Plant
from synth.stability import closed_loop_stability
from synth.stability_sets import affine_stability_intervals, gain_margin_factors

from .conftest import X4_PLANT


def _random_loop(rng):
    n = rng.integers(1, 5)
    poles = rng.uniform(-5, 1.5, n)  # some open-loop unstable
    den = np.poly(poles)
    m = rng.integers(0, n)
    num = rng.uniform(0.2, 5) * np.poly(rng.uniform(-6, 2, m)) if m else np.array([rng.uniform(0.2, 20)])
    return num, den


def test_delay_free_matches_python_control():
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(300):
        num, den = _random_loop(rng)
        L = control.tf(num, den)
        poles = control.poles(control.feedback(L, 1))
        if np.min(np.abs(poles.real)) < 1e-6:
            continue  # too close to the boundary for a fair comparison
        expected = bool(np.all(poles.real < 0))
        got = closed_loop_stability(num, den, 0.0)
        assert got.stable == expected
        assert got.unstable_poles == int(np.sum(poles.real > 0))
        checked += 1
    assert checked > 250


def test_nyquist_count_with_tiny_delay_agrees_with_roots():
    """With a delay far below every time constant the count must equal the delay-free one."""
    rng = np.random.default_rng(11)
    for _ in range(120):
        num, den = _random_loop(rng)
        roots = np.roots(np.polyadd(den, num))
        if np.min(np.abs(roots.real)) < 0.05 or np.max(np.abs(roots)) > 30:
            continue
        expected = int(np.sum(roots.real > 0))
        assert closed_loop_stability(num, den, 1e-5).unstable_poles == expected


def test_delay_against_pade_roots():
    """Away from the stability boundary, high-order Pade roots count the same right-half-plane roots."""
    rng = np.random.default_rng(3)
    compared = 0
    for _ in range(200):
        num, den = _random_loop(rng)
        tau = rng.uniform(0.01, 0.5)
        pn, pd = control.pade(tau, 10)
        char = np.polyadd(np.polymul(den, pd), np.polymul(num, pn))
        roots = np.roots(char)
        small = roots[np.abs(roots) < 5.0 / tau]  # where the Pade approximation is accurate
        if np.min(np.abs(small.real)) < 0.05:
            continue
        expected = int(np.sum(small.real > 0))
        assert closed_loop_stability(num, den, tau).unstable_poles == expected
        compared += 1
    assert compared > 100


def test_integrator_with_delay_closed_form():
    # k exp(-tau s)/s is stable iff k*tau < pi/2
    for tau in [0.01, 0.1, 1.0]:
        k_crit = np.pi / 2 / tau
        assert closed_loop_stability(np.array([0.99 * k_crit]), np.array([1.0, 0.0]), tau).stable
        assert not closed_loop_stability(np.array([1.01 * k_crit]), np.array([1.0, 0.0]), tau).stable


def _critical_gain_reference(tau):
    """Independent: phase crossover of H exp(-tau s) by brentq, K = 1/|H|."""
    G = Plant.from_string(X4_PLANT)

    def phase(w):
        return np.unwrap(np.angle(G.freqresp(np.array([1e-3, w]))))[-1] - w * tau + np.pi

    w180 = brentq(phase, 1.0, 1e4)
    return 1.0 / abs(G.freqresp(np.array([w180]))[0])


@pytest.mark.parametrize("tau, expected", [(0.005, 13.9), (0.01, 7.1), (0.015, 4.83), (0.02, 3.69)])
def test_x4_critical_gain_with_delay(tau, expected):
    G = Plant.from_string(X4_PLANT)
    ivs = affine_stability_intervals(None, (np.array([1.0]), np.array([1.0])), G.num, G.den, tau, 0.0, 50.0)
    assert len(ivs) == 1 and ivs[0].lo == 0.0 and ivs[0].hi_is_boundary
    assert ivs[0].hi == pytest.approx(_critical_gain_reference(tau), rel=1e-9)
    assert ivs[0].hi == pytest.approx(expected, abs=0.01 if expected < 5 else 0.05)
    k = ivs[0].hi
    assert closed_loop_stability(0.999 * k * G.num, G.den, tau).stable
    assert not closed_loop_stability(1.001 * k * G.num, G.den, tau).stable


def test_delay_free_seed_plant_cannot_be_destabilized_by_positive_gain():
    G = Plant.from_string(X4_PLANT)
    ivs = affine_stability_intervals(None, (np.array([1.0]), np.array([1.0])), G.num, G.den, 0.0, -5.0, 1e3)
    assert len(ivs) == 1
    # Hurwitz: s^2 + (10.14 + 23 rho) s + (5.184 + 9.89 rho) needs both coefficients > 0;
    # the s-coefficient binds first (a root pair crossing at w = sqrt(5.184 - 9.89*10.14/23))
    assert ivs[0].lo == pytest.approx(-10.14 / 23, rel=1e-9)
    assert ivs[0].lo_frequency == pytest.approx(np.sqrt(5.184 - 9.89 * 10.14 / 23), rel=1e-6)
    assert ivs[0].hi == 1e3 and not ivs[0].hi_is_boundary


def test_gain_margin_matches_python_control_without_delay():
    rng = np.random.default_rng(5)
    checked = 0
    for _ in range(200):
        num, den = _random_loop(rng)
        if np.any(np.roots(den).real > -0.05):
            continue
        if not closed_loop_stability(num, den, 0.0).stable:
            continue
        gm, *_ = control.stability_margins(control.tf(num, den))
        _, k_hi, _, _ = gain_margin_factors(num, den, 0.0)
        if np.isinf(gm) or gm > 1e4:
            assert np.isinf(k_hi)
        else:
            assert k_hi == pytest.approx(gm, rel=1e-6)
        checked += 1
    assert checked > 40


def test_pi_on_integrating_plant_with_delay_against_pade():
    # L = (kp s + ki)/s * 1/(s (s+1)) * exp(-0.1 s): double integrator at the origin
    num = np.array([1.0, 0.3])
    den = np.polymul([1.0, 0.0], [1.0, 1.0, 0.0])
    for gain in [0.2, 0.5, 1.0, 2.0]:
        pn, pd = control.pade(0.1, 10)
        roots = np.roots(np.polyadd(np.polymul(den, pd), np.polymul(gain * num, pn)))
        roots = roots[np.abs(roots) < 50]
        expected = not np.any(roots.real > 0)
        assert closed_loop_stability(gain * num, den, 0.1).stable == expected
