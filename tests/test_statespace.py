"""synth.statespace against scipy.signal (tf2ss, cont2discrete, lti.step) on seeded random transfer functions:
the controllable canonical form, every discretization the simulator offers, and the exact step response."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.exact_steps import exact_step
from synth.sim.discretize import DISCRETIZATIONS, discretize_controller
from synth.statespace import tf_to_ss

SCIPY_METHOD = {"tustin": "bilinear", "zoh": "zoh", "backward_euler": "backward_diff", "forward_euler": "euler"}


def _random_tf(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    n = int(rng.integers(1, 6))
    poles = -rng.uniform(0.1, 50.0, n)
    if n >= 2 and rng.random() < 0.5:  # a lightly damped pair
        wn, zeta = rng.uniform(1.0, 30.0), rng.uniform(0.02, 0.7)
        poles[:2] = -zeta * wn, -zeta * wn
        den = np.polymul(np.poly(poles[2:]), [1.0, 2 * zeta * wn, wn * wn])
    else:
        den = np.poly(poles)
    m = int(rng.integers(0, n + 1))  # biproper when m == n
    num = np.poly(rng.uniform(-20.0, 20.0, m)) * rng.uniform(0.1, 100.0) * rng.choice([-1.0, 1.0])
    return num * rng.uniform(0.5, 3.0), den * rng.uniform(0.5, 3.0)  # unnormalized leading coefficients


@pytest.mark.parametrize("seed", range(3))
def test_canonical_form_and_discretizations_match_scipy(seed: int):
    rng = np.random.default_rng(seed)
    for _ in range(20):
        num, den = _random_tf(rng)
        A, B, C, D = tf_to_ss(num, den)
        As, Bs, Cs, Ds = signal.tf2ss(num, den)
        assert np.allclose(A, As, rtol=1e-12, atol=0) and np.allclose(B, Bs[:, 0]) and np.allclose(C, Cs[0])
        assert D == pytest.approx(float(Ds[0, 0]), rel=1e-12, abs=1e-15)
        h = float(rng.uniform(1e-4, 0.05))
        for method in DISCRETIZATIONS:
            Ad, Bd, Cd, Dd = discretize_controller(num, den, h, method)
            ref = signal.cont2discrete((As, Bs, Cs, Ds), h, method=SCIPY_METHOD[method])
            assert np.allclose(Ad, ref[0], rtol=1e-9, atol=1e-12), method
            assert np.allclose(Bd, ref[1][:, 0], rtol=1e-9, atol=1e-12), method
            assert np.allclose(Cd, ref[2][0], rtol=1e-9, atol=1e-12), method
            assert Dd == pytest.approx(float(ref[3][0, 0]), rel=1e-9, abs=1e-12), method


def test_exact_step_matches_scipy_step():
    rng = np.random.default_rng(11)
    for _ in range(25):
        num, den = _random_tf(rng)
        slowest = float(np.min(np.abs(np.roots(den).real)))
        t = np.linspace(0.0, 8.0 / slowest, int(rng.integers(200, 3000)))
        _, ref = signal.lti(num, den).step(T=t)
        y = exact_step(num, den, t)
        assert np.allclose(y, ref, rtol=1e-7, atol=1e-9 * max(1.0, float(np.max(np.abs(ref)))))


def test_improper_and_zero_denominator_are_refused():
    with pytest.raises(ValueError, match="improper"):
        tf_to_ss(np.array([1.0, 0.0, 0.0]), np.array([1.0, 1.0]))
    with pytest.raises(ValueError, match="zero polynomial"):
        tf_to_ss(np.array([1.0]), np.array([0.0, 0.0]))
