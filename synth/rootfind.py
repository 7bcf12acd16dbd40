"""Vectorized root refinement: many sign-change brackets of one function at once."""

from __future__ import annotations

import numpy as np

__all__ = ["bisect_roots"]


def bisect_roots(f, lo: np.ndarray, hi: np.ndarray, iterations: int = 200, *, indexed: bool = False) -> np.ndarray:
    """Refine many sign-change brackets ``[lo, hi]`` of a vectorized ``f`` at once, each to a width of
    ``1e-14 max(1, |hi|)`` (its midpoint is returned).

    Every bracket stays a bracket: each step takes the Illinois (modified regula falsi) point, and every
    third step the midpoint, so a bracket shrinks at least as fast as one bisection in three and usually
    superlinearly (about 10 evaluations instead of 50).

    With ``indexed=True``, ``f(x, index)`` is called with the points of the brackets still open only,
    ``index`` being their flat positions in ``lo``: a batch's median bracket closes in about 8 steps and its
    slowest in about 50, so evaluating only the open ones saves most of the work. ``f`` must then give each
    bracket's value from its own point alone (row ``index[j]`` at ``x[j]``); the roots are the same, bit for
    bit, as with every bracket evaluated at every step. Otherwise ``f(x)`` gets arrays of ``lo``'s shape.

    Examples
    --------
    >>> float(bisect_roots(lambda x: x**2 - 2.0, np.array([1.0]), np.array([2.0]))[0])
    1.414213562373095
    >>> bisect_roots(lambda x, i: x**2 - np.array([2.0, 3.0])[i], np.ones(2), np.full(2, 2.0),
    ...              indexed=True).round(12).tolist()
    [1.414213562373, 1.732050807569]
    """
    lo = np.array(lo, dtype=float)
    hi = np.array(hi, dtype=float)
    if lo.size == 0:
        return lo
    if indexed:
        return _bisect_open(f, lo, hi, iterations)
    f_lo = np.asarray(f(lo), dtype=float)
    f_hi = np.asarray(f(hi), dtype=float)
    lo, hi = _ends_at_roots(lo, hi, f_lo, f_hi)
    side = np.zeros(lo.shape, int)  # which end was kept last time (-1 lo, +1 hi): Illinois halves its value
    done = _narrow(lo, hi) | (f_lo == 0) | (f_hi == 0)
    for k in range(iterations):
        if np.all(done):
            break
        x = np.where(done, lo, _next_point(lo, hi, f_lo, f_hi, k))
        fx = np.asarray(f(x), dtype=float)
        lo, hi, f_lo, f_hi, side, closed = _step(lo, hi, f_lo, f_hi, side, x, fx, ~done)
        done |= closed
    return 0.5 * (lo + hi)


def _bisect_open(f, lo: np.ndarray, hi: np.ndarray, iterations: int) -> np.ndarray:
    """:func:`bisect_roots` with ``f(x, index)`` evaluated at the open brackets only."""
    shape = lo.shape
    lo, hi = lo.ravel(), hi.ravel()
    every = np.arange(lo.size)
    f_lo = np.asarray(f(lo, every), dtype=float).ravel()
    f_hi = np.asarray(f(hi, every), dtype=float).ravel()
    lo, hi = _ends_at_roots(lo, hi, f_lo, f_hi)
    side = np.zeros(lo.shape, int)
    open_ = np.flatnonzero(~(_narrow(lo, hi) | (f_lo == 0) | (f_hi == 0)))
    for k in range(iterations):
        if open_.size == 0:
            break
        a, b, fa, fb, sd = lo[open_], hi[open_], f_lo[open_], f_hi[open_], side[open_]
        x = _next_point(a, b, fa, fb, k)
        fx = np.asarray(f(x, open_), dtype=float).ravel()
        a, b, fa, fb, sd, closed = _step(a, b, fa, fb, sd, x, fx, np.ones(open_.size, bool))
        lo[open_], hi[open_], f_lo[open_], f_hi[open_], side[open_] = a, b, fa, fb, sd
        open_ = open_[~closed]
    return (0.5 * (lo + hi)).reshape(shape)


def _ends_at_roots(lo: np.ndarray, hi: np.ndarray, f_lo: np.ndarray, f_hi: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """A bracket with ``f = 0`` at an end closed onto that end (its midpoint is then the root)."""
    return np.where(f_hi == 0, hi, lo), np.where((f_lo == 0) & (f_hi != 0), lo, hi)


def _narrow(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Brackets narrower than the tolerance, ``1e-14 max(1, |hi|)``."""
    return hi - lo <= 1e-14 * np.maximum(1.0, np.abs(hi))


def _next_point(lo: np.ndarray, hi: np.ndarray, f_lo: np.ndarray, f_hi: np.ndarray, k: int) -> np.ndarray:
    """Step ``k``'s point in each bracket: the (Illinois) regula falsi point, the midpoint every third step and
    wherever that point is not strictly inside."""
    with np.errstate(divide="ignore", invalid="ignore"):
        x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
    mid = 0.5 * (lo + hi)
    bad = ~np.isfinite(x) | (x <= lo) | (x >= hi) | (k % 3 == 2)
    return np.where(bad, mid, x)


def _step(lo, hi, f_lo, f_hi, side, x, fx, live):
    """Each live bracket narrowed to the side of ``x`` where ``f`` still changes sign; which brackets closed."""
    left = (np.sign(fx) == np.sign(f_lo)) & live  # root in [x, hi]: x replaces lo
    right = ~left & live
    hit = (fx == 0) & live
    f_hi = np.where(left & (side == 1), 0.5 * f_hi, f_hi)
    f_lo = np.where(right & (side == -1), 0.5 * f_lo, f_lo)
    lo, f_lo = np.where(left, x, lo), np.where(left, fx, f_lo)
    hi, f_hi = np.where(right, x, hi), np.where(right, fx, f_hi)
    side = np.where(left, 1, np.where(right, -1, side))
    lo = np.where(hit, x, lo)
    hi = np.where(hit, x, hi)
    return lo, hi, f_lo, f_hi, side, hit | _narrow(lo, hi)
