"""bisect_roots: every bracket refined to its root; evaluating only the open brackets (``indexed=True``) gives the
same roots, bit for bit, as evaluating every bracket at every step, with far fewer evaluations."""

from __future__ import annotations

import numpy as np
import pytest

from synth.rootfind import bisect_roots


def _random_brackets(seed: int, n: int = 400):
    """Cubics ``(x - r)(x^2 + b x + c)`` with one real root ``r`` inside a bracket of random width; the slopes
    at the root span six decades, so brackets close after very different numbers of steps."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(-50.0, 50.0, n)
    b, c = rng.uniform(-1.0, 1.0, n), rng.uniform(1.0, 1e6, n)
    lo = r - rng.uniform(1e-6, 10.0, n)
    hi = r + rng.uniform(1e-6, 10.0, n)
    return r, b, c, lo, hi


@pytest.mark.parametrize("seed", range(5))
def test_indexed_brackets_give_the_same_roots_bit_for_bit_with_fewer_evaluations(seed):
    r, b, c, lo, hi = _random_brackets(seed)
    calls = {"all": 0, "open": 0}

    def every(x):
        calls["all"] += x.size
        return (x - r) * (x * x + b * x + c)

    def some(x, i):
        calls["open"] += x.size
        return (x - r[i]) * (x * x + b[i] * x + c[i])

    full = bisect_roots(every, lo, hi)
    part = bisect_roots(some, lo, hi, indexed=True)
    assert np.array_equal(full, part)
    assert np.all(np.abs(full - r) <= 1e-12 * np.maximum(1.0, np.abs(r)))
    assert calls["open"] < 0.6 * calls["all"]


def test_indexed_keeps_the_shape_of_two_dimensional_brackets():
    lo = np.array([[1.0, 2.0], [0.5, 3.0]])
    roots = bisect_roots(lambda x, i: x * x - np.array([2.0, 5.0, 1.0, 10.0])[i], lo, lo + 1.5, indexed=True)
    assert roots.shape == (2, 2)
    assert np.allclose(roots, np.sqrt([[2.0, 5.0], [1.0, 10.0]]), rtol=1e-14)


def test_a_root_at_a_bracket_end_is_returned_exactly():
    roots = bisect_roots(lambda x, i: x - np.array([1.0, 2.5])[i], np.array([1.0, 0.0]), np.array([3.0, 2.5]),
                         indexed=True)
    assert roots.tolist() == [1.0, 2.5]
