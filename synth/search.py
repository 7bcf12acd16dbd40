"""Hooke and Jeeves' pattern search in a box: a local search that needs only comparisons of values.

Exploratory moves try each coordinate in turn, up then down by the step; after a sweep that helped, the
search jumps on along the sweep's net move (the pattern), which walks along ridges where two coordinates
trade off and moves of one coordinate at a time would crawl. When no move helps the step is halved.
Used where the function is a check or a simulation rather than a smooth expression: the direction effect's
time parameters (:func:`synth.gap.effects.search.pattern_search`) and a design no converged stage produced
(:func:`synth.synthesis.pattern.pattern_search`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

__all__ = ["SearchResult", "hooke_jeeves"]

V = TypeVar("V")


@dataclass(frozen=True)
class SearchResult(Generic[V]):
    """Outcome of :func:`hooke_jeeves`: the best point, its value, evaluations made, the last step."""

    z: np.ndarray
    value: V
    evaluations: int
    step: float


def hooke_jeeves(f: Callable[[np.ndarray], V], z0: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                 better: Callable[[V, V], bool], step: float, min_step: float, budget: int,
                 start_value: V | None = None, ahead: Callable[[np.ndarray], None] | None = None,
                 ) -> SearchResult[V]:
    """Search ``f`` from ``z0`` within ``[lo, hi]`` for a point ``better`` than the others found.

    Parameters
    ----------
    f : callable
        Value of a point (any type ``better`` compares: a cost, or a tuple for a lexicographic order).
    z0 : ndarray
        Start (clipped into the box).
    lo, hi : ndarray
        The box (``-inf`` / ``inf`` allowed).
    better : callable
        ``better(a, b)``: value ``a`` is strictly better than ``b`` (beyond round-off, or the search may spin).
    step, min_step : float
        First and smallest step in every coordinate; the search stops when the step is no longer above
        ``min_step``.
    budget : int
        Most evaluations of ``f``.
    start_value : optional
        ``f(z0)`` when the caller has it already (``z0`` inside the box): not evaluated again.
    ahead : callable, optional
        Told the point the search will likely evaluate after the one it evaluates now (the move down when it
        tries a move up, which fails more often than not; the first move around a pattern move's point), so
        that it can be computed meanwhile (:class:`synth.speculation.Speculator`). It changes nothing else.

    Returns
    -------
    SearchResult

    Examples
    --------
    >>> f = lambda z: float((z[0] - 1.0) ** 2 + 10 * (z[1] - z[0]) ** 2)  # a ridge along z1 = z0
    >>> r = hooke_jeeves(f, np.zeros(2), np.full(2, -5.0), np.full(2, 5.0), lambda a, b: a < b - 1e-12, 0.5, 1e-6,
    ...                  500)
    >>> np.round(r.z, 4).tolist()
    [1.0, 1.0]
    """
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    used = 0

    def value(z: np.ndarray) -> V:
        nonlocal used
        used += 1
        return f(z)

    def moved(z: np.ndarray, i: int, s: float) -> np.ndarray:
        y = z.copy()
        y[i] = min(max(y[i] + s, lo[i]), hi[i])
        return y

    def explore(base: np.ndarray, v_base: V, h: float) -> tuple[np.ndarray, V]:
        z, vz = base.copy(), v_base
        for i in range(z.size):
            for s in (h, -h):
                if used >= budget:
                    return z, vz
                y = moved(z, i, s)
                if y[i] == z[i]:
                    continue
                if ahead is not None and s > 0 and used + 1 < budget:
                    down = moved(z, i, -h)
                    if down[i] != z[i]:
                        ahead(down)
                vy = value(y)
                if better(vy, vz):
                    z, vz = y, vy
                    break
        return z, vz

    z = np.minimum(np.maximum(np.asarray(z0, float), lo), hi)
    vz = value(z) if start_value is None else start_value
    h = float(step)
    while h > min_step and used < budget:
        zn, vn = explore(z, vz, h)
        if not better(vn, vz):
            h /= 2.0
            continue
        while used < budget:  # pattern moves: on along the net move while exploring around it helps
            zp = np.minimum(np.maximum(zn + (zn - z), lo), hi)
            z, vz = zn, vn
            if ahead is not None and zp.size and used + 1 < budget:
                ahead(moved(zp, 0, h))  # explore's first move from zp
            zq, vq = explore(zp, value(zp), h)
            if not better(vq, vz):
                break
            zn, vn = zq, vq
    return SearchResult(z, vz, used, h)
