"""Frequency grids, peak search and crossing search on frequency-response curves.

Peaks are found on a log grid and refined by bounded Brent search in
``log w`` around every local maximum close to the top, so the reported value
and frequency do not depend on the grid spacing. Crossings are bracketed on
the grid (curves need not be monotonic) and refined by bisection in ``log w``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import minimize_scalar

from synth.stability import bisect_roots

__all__ = ["DEFAULT_PER_DECADE", "Curve", "band_grid", "characteristic_range", "crossings", "log_grid", "peak"]

Curve = Callable[[np.ndarray], np.ndarray]

DEFAULT_PER_DECADE = 80


def characteristic_range(*polys: np.ndarray, delay: float = 0.0) -> tuple[float, float]:
    """A frequency range (rad/s) two decades beyond every corner frequency and ``1/delay``.

    Examples
    --------
    >>> characteristic_range(np.array([1.0, 10.0]), np.array([1.0, 1.0]))
    (0.01, 1000.0)
    """
    mags: list[float] = []
    for p in polys:
        p = np.asarray(p, dtype=float)
        if p.size > 1:
            r = np.abs(np.roots(p))
            mags.extend(r[r > 1e-12].tolist())
    if delay > 0:
        mags.append(1.0 / delay)
    if not mags:
        return 1e-2, 1e2
    return float(min(mags)) / 100.0, float(max(mags)) * 100.0


def log_grid(w_lo: float, w_hi: float, per_decade: int = DEFAULT_PER_DECADE) -> np.ndarray:
    """Logarithmic grid from ``w_lo`` to ``w_hi`` (both > 0).

    Examples
    --------
    >>> log_grid(1.0, 100.0, 2)
    array([  1.        ,   3.16227766,  10.        ,  31.6227766 , 100.        ])
    """
    n = max(2, int(np.ceil(per_decade * np.log10(w_hi / w_lo))) + 1)
    return np.geomspace(w_lo, w_hi, n)


def band_grid(band: tuple[float, float], auto: tuple[float, float],
              per_decade: int = DEFAULT_PER_DECADE) -> np.ndarray:
    """Grid covering ``band``; a band starting at 0 gets ``w = 0`` plus a log grid from far below.

    Examples
    --------
    >>> g = band_grid((0.0, 30.0), (0.005, 960.0), 10)
    >>> float(g[0]), float(g[1]), float(g[-1])
    (0.0, 0.003, 30.0)
    """
    lo, hi = float(band[0]), float(band[1])
    if lo > 0:
        return log_grid(lo, hi, per_decade)
    start = min(auto[0], hi * 1e-4)
    return np.concatenate([[0.0], log_grid(start, hi, per_decade)])


def peak(curve: Curve, grid: np.ndarray, tol_db: float = 3.0) -> tuple[float, float]:
    """Maximum of a real ``curve(w)`` over ``[grid[0], grid[-1]]``: ``(value, w)``.

    Every local maximum on the grid within ``tol_db`` (as 20 log10 ratio) of
    the largest is refined by bounded Brent search on ``log w``.

    Examples
    --------
    >>> f = lambda w: 1.0 / np.abs(1.0 - w**2 + 0.2j * w)  # resonance at ~0.99 rad/s
    >>> v, w = peak(f, log_grid(0.01, 100.0, 5))
    >>> round(v, 4), round(w, 4)
    (5.0252, 0.9899)
    """
    grid = np.asarray(grid, dtype=float)
    values = np.asarray(curve(grid), dtype=float)
    i_best = int(np.nanargmax(values))
    best_v, best_w = float(values[i_best]), float(grid[i_best])
    if not np.isfinite(best_v):
        return best_v, best_w
    interior = np.flatnonzero(
        (values[1:-1] >= values[:-2]) & (values[1:-1] >= values[2:])
    ) + 1
    candidates = [int(i) for i in interior if values[i] >= best_v * 10 ** (-tol_db / 20)]
    for i in candidates[:20]:
        a, b = grid[i - 1], grid[i + 1]
        if a <= 0:
            res = minimize_scalar(lambda x: -float(curve(np.array([x]))[0]), bounds=(a, b),
                                  method="bounded", options={"xatol": 1e-10 * b})
            w_opt = float(res.x)
        else:
            res = minimize_scalar(lambda x: -float(curve(np.array([np.exp(x)]))[0]),
                                  bounds=(np.log(a), np.log(b)), method="bounded",
                                  options={"xatol": 1e-10})
            w_opt = float(np.exp(res.x))
        v = float(curve(np.array([w_opt]))[0])
        if v > best_v:
            best_v, best_w = v, w_opt
    return best_v, best_w


def crossings(curve: Curve, level: float, grid: np.ndarray) -> np.ndarray:
    """Every frequency in the grid's span where ``curve(w) - level`` changes sign.

    Examples
    --------
    >>> crossings(lambda w: 1.0 / np.abs(1j * w + 1.0), 1 / np.sqrt(2), log_grid(0.01, 100.0)).round(8)
    array([1.])
    """
    grid = np.asarray(grid, dtype=float)
    g = np.asarray(curve(grid), dtype=float) - level
    sign = np.sign(g)
    idx = np.flatnonzero(sign[:-1] * sign[1:] < 0)
    exact = grid[1:-1][sign[1:-1] == 0]
    if idx.size == 0:
        return np.sort(exact)
    lo, hi = grid[idx], grid[idx + 1]
    positive = lo > 0
    roots = np.empty(idx.size)
    if np.any(positive):
        roots[positive] = np.exp(bisect_roots(
            lambda x: np.asarray(curve(np.exp(x)), dtype=float) - level,
            np.log(lo[positive]), np.log(hi[positive]),
        ))
    if np.any(~positive):
        roots[~positive] = bisect_roots(
            lambda x: np.asarray(curve(x), dtype=float) - level, lo[~positive], hi[~positive]
        )
    return np.sort(np.concatenate([roots, exact]))
