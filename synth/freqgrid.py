"""Frequency grids, peak search and crossing search on frequency-response curves.

Peaks are found on a log grid and refined by bounded Brent search in
``log w`` around every local maximum close to the top, so the reported value
and frequency do not depend on the grid spacing. Crossings are bracketed on
the grid (curves need not be monotonic) and refined by bisection in ``log w``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from synth.errors import ModelError
from synth.first_crossing import batch_first_crossing
from synth.rootfind import bisect_roots

__all__ = [
    "DEFAULT_PER_DECADE",
    "Curve",
    "band_grid",
    "band_grids",
    "batch_first_crossing",
    "batch_peak",
    "bracketed_maxima",
    "characteristic_range",
    "corner_frequencies",
    "crossings",
    "first_fall",
    "grid_decades",
    "log_grid",
    "log_grid_sizes",
    "log_grids",
    "neighbour_brackets",
    "peak",
    "refine_maxima",
    "resolving_grid",
]

Curve = Callable[[np.ndarray], np.ndarray]

DEFAULT_PER_DECADE = 80


def characteristic_range(*polys: np.ndarray, delay: float = 0.0) -> tuple[float, float]:
    """A frequency range (rad/s) two decades beyond every corner frequency and ``1/delay``.

    Examples
    --------
    >>> characteristic_range(np.array([1.0, 10.0]), np.array([1.0, 1.0]))
    (0.01, 1000.0)
    """
    lo, hi = corner_frequencies(*polys)
    if delay > 0:
        lo, hi = (1.0 / delay, 1.0 / delay) if np.isnan(lo) else (min(lo, 1.0 / delay), max(hi, 1.0 / delay))
    if np.isnan(lo):
        return 1e-2, 1e2
    return float(lo) / 100.0, float(hi) * 100.0


def corner_frequencies(*polys: np.ndarray) -> tuple[float, float]:
    """Smallest and largest root magnitude above 1e-12 of the polynomials (``nan, nan`` if none).

    Examples
    --------
    >>> corner_frequencies(np.array([1.0, 10.0]), np.array([1.0, 1.0]))
    (1.0, 10.0)
    """
    mags: list[float] = []
    for p in polys:
        p = np.asarray(p, dtype=float)
        if p.size > 1:
            r = np.abs(np.roots(p))
            mags.extend(r[r > 1e-12].tolist())
    return (float(min(mags)), float(max(mags))) if mags else (np.nan, np.nan)


def grid_decades(w_lo: float, w_hi: float) -> float:
    """Decades from ``w_lo`` to ``w_hi``; a :class:`~synth.errors.ModelError` when they are not finite (one line).

    Examples
    --------
    >>> grid_decades(1.0, 100.0)
    2.0
    """
    decades = float(np.log10(w_hi / w_lo)) if w_lo > 0 else np.inf
    if not np.isfinite(decades):  # e.g. 1 / delay underflowed: a plant delay of 1e308 s
        raise ModelError(f"cannot grid the frequencies from {w_lo:g} to {w_hi:g} rad/s (a delay, pole or zero at an "
                         "extreme scale?)")
    return decades


def log_grid(w_lo: float, w_hi: float, per_decade: int = DEFAULT_PER_DECADE) -> np.ndarray:
    """Logarithmic grid from ``w_lo`` to ``w_hi`` (both > 0).

    Examples
    --------
    >>> log_grid(1.0, 100.0, 2)
    array([  1.        ,   3.16227766,  10.        ,  31.6227766 , 100.        ])
    >>> log_grid(1e-310, 1e3)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    synth.errors.ModelError: cannot grid the frequencies from 1e-310 to 1000 rad/s (a delay, pole or zero at an ...
    """
    decades = grid_decades(w_lo, w_hi)
    n = max(2, int(np.ceil(per_decade * decades)) + 1)
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
    the largest (at most 20) is refined by golden-section search on ``log w`` between its
    neighbours, all at once.

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
    candidates = np.array([int(i) for i in interior if values[i] >= best_v * 10 ** (-tol_db / 20)][:20], dtype=int)
    if candidates.size == 0:
        return best_v, best_w
    v, w = refine_maxima(curve, grid, candidates)
    v = np.where(np.isnan(v), -np.inf, v)
    j = int(np.argmax(v))
    if v[j] > best_v:
        best_v, best_w = float(v[j]), float(w[j])
    return best_v, best_w


def resolving_grid(w_lo: float, w_hi: float, per_decade: int, max_step: float | None = None,
                   max_points: int = 20_000, even_until: float | None = None) -> np.ndarray:
    """A log grid on ``[w_lo, w_hi]`` with evenly spaced points added wherever its spacing exceeds ``max_step``
    (rad/s), up to ``even_until`` (default ``w_hi``) and at most ``max_points`` of them: a curve that ripples in
    ``w`` (a delay ``tau`` turns the phase by ``w tau``) is resolved at every frequency, not only where the log
    grid is fine enough.

    Examples
    --------
    >>> g = resolving_grid(0.1, 100.0, 10, max_step=1.0)
    >>> bool(np.all(np.diff(g) <= 1.0 + 1e-12)), g.size > 100, log_grid(0.1, 100.0, 10).size
    (True, True, 31)
    """
    grid = log_grid(w_lo, w_hi, per_decade)
    if max_step is None or not np.isfinite(max_step) or max_step <= 0:
        return grid
    coarse = np.flatnonzero(np.diff(grid) > max_step)
    if coarse.size == 0:
        return grid
    top = float(grid[-1]) if even_until is None else min(float(even_until), float(grid[-1]))
    start = float(grid[coarse[0]])  # the cap before the points are made: a delay of 1e8 s asked for 1e10 of them
    even = np.arange(start + max_step, min(top, start + max_step * (max_points + 0.5)), max_step)
    return np.union1d(grid, even)


def neighbour_brackets(grid: np.ndarray, values: np.ndarray, index: np.ndarray, refined: np.ndarray,
                       band: tuple[float, float], factor: float) -> tuple[np.ndarray, np.ndarray]:
    """For each local maximum ``values[index]`` (refined to ``refined``), the interval up to the grid's
    neighbouring local minima on either side, within ``factor`` of the maximum and inside ``band``: where the
    curve has that one maximum, so a stationary point held in it is that maximum (pass ``-values`` for
    minima). Returns ``(lo, hi)``.

    Examples
    --------
    >>> w = np.linspace(1.0, 10.0, 901)
    >>> v = np.cos(2 * np.pi * w)  # maxima at integers, minima half-way
    >>> lo, hi = neighbour_brackets(w, v, np.array([400]), np.array([5.0]), (1.0, 10.0), 1.5)
    >>> float(lo[0]), float(hi[0])
    (4.5, 5.5)
    """
    grid, values = np.asarray(grid, float), np.asarray(values, float)
    refined = np.asarray(refined, float)
    troughs = np.flatnonzero((values[1:-1] < values[:-2]) & (values[1:-1] <= values[2:])) + 1
    edges = np.concatenate([[band[0]], grid[troughs], [band[1]]])  # the band's ends stand for missing minima
    k = np.searchsorted(troughs, np.asarray(index, int))
    lo = np.maximum(np.maximum(edges[k], refined / factor), band[0])
    hi = np.minimum(np.minimum(edges[k + 1], refined * factor), band[1])
    return lo, hi


def bracketed_maxima(curve: Curve, grid: np.ndarray, keep: Callable[[np.ndarray], np.ndarray],
                     band: tuple[float, float], factor: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The local maxima of a real ``curve`` on ``grid`` whose values pass ``keep``, refined by golden section
    (:func:`refine_maxima`), each with its interval up to the neighbouring minima (:func:`neighbour_brackets`):
    ``(w, lo, hi)``, empty when none passes.

    Examples
    --------
    >>> w = np.linspace(1.0, 10.0, 901)
    >>> f = lambda x: np.cos(2 * np.pi * x) * x  # maxima near the integers, growing
    >>> peaks, lo, hi = bracketed_maxima(f, w, lambda v: v > 7.5, (1.0, 10.0), 1.5)
    >>> peaks.round(3).tolist(), lo.round(2).tolist(), hi.round(2).tolist()
    ([8.003, 9.003], [7.5, 8.5], [8.5, 9.5])
    """
    with np.errstate(all="ignore"):
        values = np.asarray(curve(grid), dtype=float)
        inner = np.flatnonzero((values[1:-1] > values[:-2]) & (values[1:-1] >= values[2:])) + 1
        inner = inner[np.isfinite(values[inner]) & keep(values[inner])]
        if inner.size == 0:
            return np.array([]), np.array([]), np.array([])
        _, refined = refine_maxima(curve, grid, inner)
    lo, hi = neighbour_brackets(grid, values, inner, refined, band, factor)
    return refined, lo, hi


def refine_maxima(curve: Curve, grid: np.ndarray, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima ``grid[index]`` of a real ``curve(w)`` refined by golden-section search between their
    neighbours (on ``log w`` where the interval is positive), all at once: ``(values, w)``.

    Examples
    --------
    >>> f = lambda w: -np.abs(w - 2.0)
    >>> v, w = refine_maxima(f, np.array([1.0, 1.5, 2.2, 3.0]), np.array([2]))
    >>> round(float(w[0]), 6)
    2.0
    """
    grid = np.asarray(grid, dtype=float)
    index = np.asarray(index, dtype=int)
    a, b = grid[index - 1], grid[index + 1]
    return _zoom_max(lambda x: np.asarray(curve(x.ravel()), dtype=float).reshape(x.shape), a, b, a > 0)


def _zoom_max(curve: Callable[[np.ndarray], np.ndarray], a: np.ndarray, b: np.ndarray, log: np.ndarray,
              points: int = 16, iterations: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Maximize ``curve`` on each bracket ``[a, b]`` (1-D arrays; in ``log w`` where ``log``) by zooming grids:
    ``points`` interior points per bracket, then the bracket shrinks to the best point found so far +- one
    spacing (a factor ``(points + 1) / 2`` per round), all brackets in one evaluation per round, until each is
    narrower than 1e-12 relative. Keeps the best point seen, so it ends at a maximum no lower than any sample
    even where a bracket holds several; ``-inf`` where no sample was a number. For a few brackets this is far
    fewer calls than golden section (12 against 50), each on a short array, which is what costs."""
    with np.errstate(divide="ignore"):
        lo = np.where(log, np.log(np.where(log, a, 1.0)), a)
        hi = np.where(log, np.log(np.where(log, b, 1.0)), b)
    logc = log[:, None]

    def f(x: np.ndarray) -> np.ndarray:
        with np.errstate(over="ignore"):
            v = np.asarray(curve(np.where(logc, np.exp(x), x)), dtype=float)
        return np.where(np.isnan(v), -np.inf, v)

    steps = np.arange(1, points + 1) / (points + 1)
    best_x = 0.5 * (lo + hi)
    best_v = f(best_x[:, None])[:, 0]
    rows = np.arange(lo.size)
    for _ in range(iterations):
        x = lo[:, None] + (hi - lo)[:, None] * steps
        v = f(x)
        j = np.argmax(v, axis=1)
        better = v[rows, j] > best_v
        best_x, best_v = np.where(better, x[rows, j], best_x), np.where(better, v[rows, j], best_v)
        h = (hi - lo) / (points + 1)
        lo, hi = np.maximum(lo, best_x - h), np.minimum(hi, best_x + h)
        if np.all(hi - lo <= 1e-12 * np.maximum(1.0, np.abs(hi))):
            break
    return best_v, np.where(log, np.exp(best_x), best_x)


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



def first_fall(curve: Curve, level: float, grid: np.ndarray) -> float:
    """Lowest frequency in the grid's span where ``curve(w)`` falls below ``level``, a dip narrower than the
    grid's spacing included (:func:`batch_first_crossing` on one row: every local minimum on the grid before the
    first sampled crossing is refined between its neighbours, and where it goes below ``level`` the crossing on
    its way down is found by bisection). ``inf`` when the curve never falls below ``level``; ``grid[0]`` when
    it starts below; ``grid`` positive.

    Examples
    --------
    A notch 0.5 % wide at 2.05 rad/s, between the points of a 10-per-decade grid (1.995 and 2.512):

    >>> f = lambda w: np.abs((4.2025 - w**2 + 1e-4j * w) / (4.2025 - w**2 + 0.02j * w))
    >>> g = log_grid(0.01, 100.0, 10)
    >>> bool(np.all(f(g) > 0.5)), round(first_fall(f, 0.5, g), 4)
    (True, 2.0442)
    """
    grid = np.asarray(grid, dtype=float)
    cross, below = batch_first_crossing(lambda w: np.asarray(curve(w.ravel()), dtype=float).reshape(w.shape),
                                        np.array([float(level)]), grid[None, :])
    if below[0]:
        return float(grid[0])
    return float(cross[0]) if np.isfinite(cross[0]) else np.inf

# ------------------------------------------------------------------ vectorized: one curve per row

_GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0


def log_grids(w_lo: np.ndarray, w_hi: np.ndarray, per_decade: int = DEFAULT_PER_DECADE) -> np.ndarray:
    """One :func:`log_grid` per row, ``(n, m)``: row ``i`` is exactly ``log_grid(w_lo[i], w_hi[i])``,
    its last point repeated up to the longest row's length ``m``.

    Examples
    --------
    >>> log_grids(np.array([1.0, 10.0]), np.array([100.0, 100.0]), 1)
    array([[  1.,  10., 100.],
           [ 10., 100., 100.]])
    """
    w_lo, w_hi = np.asarray(w_lo, float), np.asarray(w_hi, float)
    pairs, inverse = np.unique(np.column_stack([w_lo, w_hi]), axis=0, return_inverse=True)
    lo, hi = pairs[:, 0], pairs[:, 1]
    sizes = log_grid_sizes(lo, hi, per_decade)
    # np.geomspace's own arithmetic, all rows at once: 10 ** (log10 lo + k step), the ends set exactly
    log_lo, log_hi = np.log10(lo), np.log10(hi)
    k = np.arange(int(sizes.max()), dtype=float)
    padded = 10.0 ** (k[None, :] * ((log_hi - log_lo) / (sizes - 1))[:, None] + log_lo[:, None])
    padded[:, 0] = lo
    padded[k[None, :] >= (sizes - 1)[:, None]] = np.repeat(hi, sizes.max() - sizes + 1)
    return padded[np.ravel(inverse)]


def log_grid_sizes(w_lo: np.ndarray, w_hi: np.ndarray, per_decade: int = DEFAULT_PER_DECADE) -> np.ndarray:
    """The number of points of each :func:`log_grid` from ``w_lo[i]`` to ``w_hi[i]`` (the rows of
    :func:`log_grids` before its padding).

    Examples
    --------
    >>> log_grid_sizes(np.array([1.0, 10.0]), np.array([100.0, 100.0]), 1), log_grid(1.0, 100.0, 1).size
    (array([3, 2]), 3)
    """
    return np.maximum(2, np.ceil(per_decade * np.log10(np.asarray(w_hi, float) / w_lo)).astype(int) + 1)


def band_grids(band: tuple[float, float], auto: np.ndarray, per_decade: int = DEFAULT_PER_DECADE) -> np.ndarray:
    """:func:`band_grid` for many rows at once: ``auto`` is ``(n, 2)`` (each row's frequency range).

    Examples
    --------
    >>> band_grids((0.0, 30.0), np.array([[0.005, 960.0]]), 10)[0, :2]
    array([0.   , 0.003])
    """
    lo, hi = float(band[0]), float(band[1])
    auto = np.asarray(auto, float)
    if lo > 0:
        return np.broadcast_to(log_grid(lo, hi, per_decade), (auto.shape[0], log_grid(lo, hi, per_decade).size))
    start = np.minimum(auto[:, 0], hi * 1e-4)
    grid = log_grids(start, np.full(start.shape, hi), per_decade)
    return np.concatenate([np.zeros((grid.shape[0], 1)), grid], axis=1)


def _golden_max(curve: Callable[[np.ndarray], np.ndarray], a: np.ndarray, b: np.ndarray, log: np.ndarray,
                iterations: int = 80) -> tuple[np.ndarray, np.ndarray]:
    """Maximize ``curve`` on ``[a, b]`` (shape ``(n, k)``; in ``log w`` where ``log``), golden section."""
    with np.errstate(divide="ignore"):
        a = np.where(log, np.log(np.where(log, a, 1.0)), a)
        b = np.where(log, np.log(np.where(log, b, 1.0)), b)

    def f(x: np.ndarray) -> np.ndarray:
        return np.asarray(curve(np.where(log, np.exp(x), x)), dtype=float)

    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iterations):
        left = fc >= fd
        a, b = np.where(left, a, c), np.where(left, d, b)
        c_new = np.where(left, b - _GOLDEN * (b - a), d)
        d_new = np.where(left, c, a + _GOLDEN * (b - a))
        c, d = c_new, d_new
        fc_known, fd_known = np.where(left, np.nan, fd), np.where(left, fc, np.nan)
        fresh = f(np.where(left, c, d))
        fc, fd = np.where(left, fresh, fc_known), np.where(left, fd_known, fresh)
        if np.all(np.abs(b - a) <= 1e-12 * np.maximum(1.0, np.abs(b))):
            break
    x = 0.5 * (a + b)
    return f(x), np.where(log, np.exp(x), x)


def batch_peak(curve: Curve, grid: np.ndarray, tol_db: float = 3.0, top: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """:func:`peak` for one curve per row: ``curve`` maps frequencies ``(n, k)`` to values ``(n, k)``,
    ``grid`` is ``(n, m)``. The ``top`` highest local maxima of each row within ``tol_db`` of its largest
    grid value are refined at once by golden-section search in ``log w``. Returns ``(values, w)``.

    Examples
    --------
    >>> f = lambda w: 1.0 / np.abs(1.0 - w**2 + np.array([[0.2], [0.4]]) * 1j * w)
    >>> v, w = batch_peak(f, np.tile(log_grid(0.01, 100.0, 5), (2, 1)))
    >>> v.round(4), w.round(4)
    (array([5.0252, 2.5516]), array([0.9899, 0.9592]))
    """
    grid = np.asarray(grid, dtype=float)
    values = np.asarray(curve(grid), dtype=float)
    n, m = values.shape
    rows = np.arange(n)
    clean = np.where(np.isnan(values), -np.inf, values)
    i_best = np.argmax(clean, axis=1)
    best_v, best_w = values[rows, i_best], grid[rows, i_best]
    if m < 3:
        return best_v, best_w
    inner = (clean[:, 1:-1] >= clean[:, :-2]) & (clean[:, 1:-1] >= clean[:, 2:])
    with np.errstate(invalid="ignore", over="ignore"):
        inner &= clean[:, 1:-1] >= (best_v * 10 ** (-tol_db / 20))[:, None]
    inner &= np.isfinite(best_v)[:, None]
    score = np.where(inner, clean[:, 1:-1], -np.inf)
    k = min(top, m - 2)
    cand = np.argsort(-score, axis=1, kind="stable")[:, :k] + 1
    ok = np.isfinite(score[rows[:, None], cand - 1])
    if not np.any(ok):
        return best_v, best_w
    a, b = grid[rows[:, None], cand - 1], grid[rows[:, None], cand + 1]
    v, w = _golden_max(curve, a, b, a > 0)
    v = np.where(ok & ~np.isnan(v), v, -np.inf)
    j = np.argmax(v, axis=1)
    better = v[rows, j] > best_v
    return np.where(better, v[rows, j], best_v), np.where(better, w[rows, j], best_w)
