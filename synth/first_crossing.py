"""The first fall of many frequency-response curves below a level, one curve per row: the first sign change
on each row's grid, or an earlier dip narrower than the grid's spacing (every local minimum before it refined by
golden section, the way down found by bisection)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from synth.rootfind import bisect_roots

__all__ = ["batch_first_crossing"]

Curve = Callable[[np.ndarray], np.ndarray]

_GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0


def _bracketed_min(curve: Callable[[np.ndarray], np.ndarray], a: np.ndarray, x: np.ndarray, b: np.ndarray,
                   iterations: int = 80) -> tuple[np.ndarray, np.ndarray]:
    """Minimize ``curve`` on ``[a, b]`` from a bracket ``a < x < b`` with ``curve(x)`` below both ends (all
    positive, any shape; golden section on ``log w`` that always keeps the best point found, so it ends at a
    local minimum no higher than ``curve(x)`` even where the interval holds several)."""
    a, x, b = np.log(a), np.log(x), np.log(b)

    def f(v: np.ndarray) -> np.ndarray:
        return np.asarray(curve(np.exp(v)), dtype=float)

    fx = f(x)
    for _ in range(iterations):
        right = (b - x) > (x - a)
        u = np.where(right, x + (1 - _GOLDEN) * (b - x), x - (1 - _GOLDEN) * (x - a))
        fu = f(u)
        better = fu < fx
        a = np.where(better, np.where(right, x, a), np.where(right, a, u))
        b = np.where(better, np.where(right, b, x), np.where(right, u, b))
        x, fx = np.where(better, u, x), np.where(better, fu, fx)
        if np.all(b - a <= 1e-12 * np.maximum(1.0, np.abs(b))):
            break
    return fx, np.exp(x)


def batch_first_crossing(curve: Curve, level: np.ndarray, grid: np.ndarray,
                         lengths: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Lowest frequency of each row where ``curve(w)`` falls below ``level`` on a positive ``grid`` ``(n, m)``:
    the first sign change of ``curve(w) - level``, or an earlier dip below ``level`` between grid points;
    ``nan`` where none. Also returns whether each row starts below ``level``.
    ``lengths`` (optional) is each row's count of grid points, the rest repeating its last one (as
    :func:`synth.freqgrid.log_grids` pads): each row's answer is then that of its own points alone.

    Examples
    --------
    >>> from synth.freqgrid import log_grid
    >>> f = lambda w: 1.0 / np.abs(1j * w / np.array([[1.0], [10.0]]) + 1.0)
    >>> w, below = batch_first_crossing(f, np.full(2, 1 / np.sqrt(2)), np.tile(log_grid(0.01, 100.0), (2, 1)))
    >>> w.round(8), below
    (array([ 1., 10.]), array([False, False]))
    """
    grid = np.asarray(grid, dtype=float)
    level = np.asarray(level, dtype=float)
    g = np.asarray(curve(grid), dtype=float) - level[:, None]
    sign = np.sign(g)
    n, m = g.shape
    rows = np.arange(n)
    change = sign[:, :-1] * sign[:, 1:] < 0
    has = change.any(axis=1)
    idx = np.argmax(change, axis=1)
    zero = np.zeros((n, m), bool)
    zero[:, 1:-1] = sign[:, 1:-1] == 0
    valid = np.full(n, m) if lengths is None else np.asarray(lengths, int)
    zero &= np.arange(m)[None, :] < (valid - 1)[:, None]  # a row's last point is its end, not a zero
    first_zero = np.where(zero.any(axis=1), grid[rows, np.argmax(zero, axis=1)], np.inf)
    lo = np.where(has, np.log(grid[rows, idx]), 0.0)
    hi = np.where(has, np.log(grid[rows, idx + 1]), 1.0)
    root = np.exp(bisect_roots(lambda x: np.asarray(curve(np.exp(x)[:, None]), float)[:, 0] - level, lo, hi))
    root = np.minimum(np.where(has, root, np.inf), first_zero)
    root = np.minimum(root, _batch_dips(curve, level, grid, g, np.where(has, idx, valid - 2)))
    return np.where(np.isfinite(root), root, np.nan), g[:, 0] < 0


def _batch_dips(curve: Curve, level: np.ndarray, grid: np.ndarray, g: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Per row, where ``curve`` first goes below ``level`` inside a dip narrower than the grid before column
    ``end`` (at most; every local minimum of ``g = curve - level`` above zero is refined by :func:`_bracketed_min`);
    ``inf`` where none does."""
    n, m = g.shape
    is_min = np.zeros((n, m), bool)
    is_min[:, 1:-1] = (g[:, 1:-1] <= g[:, :-2]) & (g[:, 1:-1] <= g[:, 2:]) & (g[:, 1:-1] > 0)
    is_min &= np.arange(m)[None, :] <= end[:, None]
    if not is_min.any():
        return np.full(n, np.inf)
    score = np.where(is_min, g, np.inf)
    order = np.argsort(score, axis=1, kind="stable")[:, :int(is_min.sum(axis=1).max())]
    valid = np.isfinite(np.take_along_axis(score, order, axis=1))
    j = np.where(valid, order, 1)
    rows = np.arange(n)[:, None]
    a, b = grid[rows, j - 1], grid[rows, j + 1]
    low, at = _bracketed_min(lambda x: np.asarray(curve(x), dtype=float), a, grid[rows, j], b)
    dips = valid & (low < level[:, None])
    if not dips.any():
        return np.full(n, np.inf)
    down = np.exp(bisect_roots(lambda x: np.asarray(curve(np.exp(x)), float) - level[:, None],
                               np.log(np.where(dips, a, 1.0)), np.log(np.where(dips, at, 2.0))))
    return np.min(np.where(dips, down, np.inf), axis=1)
