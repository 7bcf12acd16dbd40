"""SRIVC's filter bank ``s^k / den(s)`` of held, delayed samples against an exact propagation written here.

The reference propagates the companion form of ``1/den`` from sample to sample with ``scipy.linalg.expm`` of the
held input's segments (a fractional delay splits each sample period in two), so its states are ``s^k/den x``
exactly up to rounding. Random denominators of order 1-4 (real poles 0.03-200 rad/s, a few unstable ones,
pairs of damping 0.02-0.9), sample periods 1-20 ms, delays none, whole samples or fractional.

Before session 74 each state's numerator was the difference of two polynomials from eigenvalues,
``poly(Ad - B C) - poly(Ad)``, which cancels where the discrete poles crowd near 1 (slow poles at a fast rate):
errors up to 3e-3 of the response (cases 3, 156 and 173: 2.4e-3, 9.4e-4, 3.1e-3; the median over 300 cases
1.6e-10). The numerators now come from one recursion (Faddeev-LeVerrier) without that difference.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from synth.ident.filter_bank import filter_bank


def _case(seed: int) -> tuple[int, float, np.ndarray, float, np.ndarray]:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 5))
    dt = float(rng.choice([1e-3, 5e-3, 0.01, 0.02]))
    poles: list[complex] = []
    while len(poles) < n:
        if n - len(poles) >= 2 and rng.random() < 0.4:
            w, z = 10 ** rng.uniform(-1, 2), rng.uniform(0.02, 0.9)
            poles += [complex(-z * w, w * np.sqrt(1 - z * z)), complex(-z * w, -w * np.sqrt(1 - z * z))]
        else:
            poles.append(-10 ** rng.uniform(-1.5, 2.3) * (1 if rng.random() < 0.9 else -0.3))
    den = np.real(np.poly(poles)) * rng.uniform(0.5, 3)
    delay = float(rng.choice([0.0, dt * int(rng.integers(1, 20)), rng.uniform(0, 0.2)]))
    samples = int(rng.integers(200, 3000))
    x = np.repeat(rng.standard_normal(samples // 50 + 1), 50)[:samples] + 0.1 * rng.standard_normal(samples)
    return n, dt, den, delay, x


def _exact_states(n: int, dt: float, den: np.ndarray, delay: float, x: np.ndarray) -> np.ndarray:
    den = den / den[0]
    a = np.zeros((n, n))
    a[:-1, 1:] = np.eye(n - 1)
    a[-1, :] = -den[1:][::-1]

    def over(h: float) -> tuple[np.ndarray, np.ndarray]:
        m = np.zeros((n + 1, n + 1))
        m[:n, :n], m[n - 1, n] = a * h, h
        e = expm(m)
        return e[:n, :n], e[:n, n]

    whole = int(np.floor(delay / dt + 1e-9))
    fraction = delay - whole * dt

    def held(i: int) -> float:
        return float(x[i - whole]) if 0 <= i - whole < x.size else 0.0

    first, rest = (over(fraction), over(dt - fraction)) if fraction > 1e-12 * dt else (None, over(dt))
    states, s = np.zeros((x.size, n)), np.zeros(n)
    for i in range(x.size):
        states[i] = s
        if first is not None:  # the sample before is still held for `fraction` of this period
            s = first[0] @ s + first[1] * held(i - 1)
        s = rest[0] @ s + rest[1] * held(i)
    return states


def _error(seed: int) -> float:
    n, dt, den, delay, x = _case(seed)
    exact = _exact_states(n, dt, den, delay, x)
    bank = filter_bank(den, dt, x, n, delay)
    return max(float(np.max(np.abs(bank[k] - exact[:, k])) / np.max(np.abs(exact[:, k]))) for k in range(n))


@pytest.mark.parametrize("seed", [3, 156, 173])
def test_slow_and_fast_poles_at_a_fast_rate_are_filtered_to_the_exact_states(seed: int) -> None:
    assert _error(seed) < 1e-5


def test_a_random_sample_is_exact_to_rounding() -> None:
    errors = np.array([_error(seed) for seed in range(40)])
    assert np.all(np.isfinite(errors))
    assert np.median(errors) < 1e-11
    assert np.mean(errors > 1e-6) <= 0.05
