"""Vectorized root refinement: many sign-change brackets of one function at once."""

from __future__ import annotations

import numpy as np

__all__ = ["bisect_roots"]


def bisect_roots(f, lo: np.ndarray, hi: np.ndarray, iterations: int = 200) -> np.ndarray:
    """Refine many sign-change brackets ``[lo, hi]`` of a vectorized ``f`` at once, each to a width of
    ``1e-14 max(1, |hi|)`` (its midpoint is returned).

    Every bracket stays a bracket: each step takes the Illinois (modified regula falsi) point, and every
    third step the midpoint, so a bracket shrinks at least as fast as one bisection in three and usually
    superlinearly (about 10 evaluations instead of 50).

    Examples
    --------
    >>> float(bisect_roots(lambda x: x**2 - 2.0, np.array([1.0]), np.array([2.0]))[0])
    1.414213562373095
    """
    lo = np.array(lo, dtype=float)
    hi = np.array(hi, dtype=float)
    if lo.size == 0:
        return lo
    f_lo = np.asarray(f(lo), dtype=float)
    f_hi = np.asarray(f(hi), dtype=float)
    side = np.zeros(lo.shape, int)  # which end was kept last time (-1 lo, +1 hi): Illinois halves its value
    done = (hi - lo <= 1e-14 * np.maximum(1.0, np.abs(hi))) | (f_lo == 0) | (f_hi == 0)
    for k in range(iterations):
        if np.all(done):
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        mid = 0.5 * (lo + hi)
        bad = ~np.isfinite(x) | (x <= lo) | (x >= hi) | (k % 3 == 2)
        x = np.where(bad, mid, x)
        x = np.where(done, lo, x)
        fx = np.asarray(f(x), dtype=float)
        left = (np.sign(fx) == np.sign(f_lo)) & ~done  # root in [x, hi]: x replaces lo
        right = ~left & ~done
        hit = (fx == 0) & ~done
        f_hi = np.where(left & (side == 1), 0.5 * f_hi, f_hi)
        f_lo = np.where(right & (side == -1), 0.5 * f_lo, f_lo)
        lo, f_lo = np.where(left, x, lo), np.where(left, fx, f_lo)
        hi, f_hi = np.where(right, x, hi), np.where(right, fx, f_hi)
        side = np.where(left, 1, np.where(right, -1, side))
        lo = np.where(hit, x, lo)
        hi = np.where(hit, x, hi)
        done |= hit | (hi - lo <= 1e-14 * np.maximum(1.0, np.abs(hi)))
    return 0.5 * (lo + hi)
