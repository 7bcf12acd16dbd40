"""Exact unit steps of closed loops without a delay, one or many at once, on grids whose step grows with the time.

A step is held constant, so the zero-order-hold discretization of a loop at evenly spaced samples has no error:
the response at the samples is exact to rounding. :func:`doubling_grid` gives the samples a step limit needs (the
start resolved, the step doubling with each doubling of the horizon); :func:`exact_steps` computes many loops'
responses on it together (one matrix exponential call and one stacked recursion for all loops and all spans).
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import pairwise

import numpy as np

from synth.statespace import step_from_rest, tf_to_ss, zoh

__all__ = ["doubling_grid", "exact_step", "exact_steps"]


def doubling_grid(first: float, doublings: int, intervals: int = 4000) -> np.ndarray:
    """Sample times of a step over ``first * 2**doublings`` seconds that keep the start's resolution: ``intervals``
    even steps over ``[0, first]`` and over each doubling ``[first 2^(k-1), first 2^k]``, the step growing with the
    time (the first two spans share ``first / intervals``, each later one doubles it): ``intervals (doublings + 1)
    + 1`` samples where an even grid at the start's step takes ``intervals 2^doublings + 1``. Every sample is
    within ``1 / intervals`` of its own time of the next. The times are ``first`` times those of ``first = 1``.

    Examples
    --------
    >>> t = doubling_grid(1.0, 3, intervals=4)
    >>> t.tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0]
    """
    parts = [np.linspace(0.0, 1.0, intervals + 1)]
    for k in range(1, doublings + 1):
        lo = 2.0 ** (k - 1)
        parts.append(np.linspace(lo, 2.0 * lo, intervals + 1)[1:])
    return first * np.concatenate(parts)


def exact_step(num: np.ndarray, den: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Unit step response of ``num/den`` (proper, no delay) at the times ``t`` (increasing, from 0), exact (see
    :func:`exact_steps`, of which this is one loop).

    Examples
    --------
    >>> exact_step(np.array([1.0]), np.array([1.0, 1.0]), np.array([0.0, np.log(2.0)])).round(12).tolist()
    [0.0, 0.5]
    >>> exact_step(np.array([1.0]), np.array([1.0, 1.0]), np.log([1.0, 2.0, 4.0, 16.0])).round(12).tolist()
    [0.0, 0.5, 0.75, 0.9375]
    """
    return exact_steps([num], [den], np.ones(1), np.asarray(t, float))[0]


def exact_steps(nums: Sequence[np.ndarray], dens: Sequence[np.ndarray], scales: np.ndarray,
                unit: np.ndarray) -> np.ndarray:
    """Unit step responses of the loops ``nums[i] / dens[i]`` (proper, no delay), loop ``i`` at the times
    ``scales[i] * unit`` (``unit`` increasing from 0): ``(len(nums), unit.size)``.

    ``unit`` is taken as runs of even spacing (as :func:`doubling_grid` makes), cut into pieces of the shortest
    run's length. Each piece starts from the exact state at its first time (the step from rest over that time:
    the zero-order hold's own matrix exponential, :func:`synth.statespace.zoh`), so no error is carried from one
    piece to the next; the pieces of every loop of one order are stepped together
    (:func:`synth.statespace.step_from_rest` on stacked systems), their matrix exponentials in one call.

    Examples
    --------
    ``1/(s+1)`` at ``t = ln 2`` and ``2/(s+2)`` at twice that time:

    >>> y = exact_steps([np.array([1.0]), np.array([2.0])], [np.array([1.0, 1.0]), np.array([1.0, 2.0])],
    ...                 np.array([1.0, 2.0]), np.array([0.0, np.log(2.0)]))
    >>> y.round(12).tolist()
    [[0.0, 0.5], [0.0, 0.9375]]
    """
    unit = np.asarray(unit, float)
    scales = np.asarray(scales, float)
    out = np.empty((len(nums), unit.size))
    systems = [tf_to_ss(num, den) for num, den in zip(nums, dens)]
    pieces = _even_pieces(unit) if unit.size > 1 else []
    for order in sorted({A.shape[0] for A, *_ in systems}):
        rows = [i for i, (A, *_) in enumerate(systems) if A.shape[0] == order]
        D = np.array([float(systems[i][3]) for i in rows])
        if order == 0 or unit.size < 2:  # a static gain, or only t = 0 (the state starts at rest)
            out[rows] = D[:, None]
            continue
        A = np.array([systems[i][0] for i in rows])
        B = np.array([systems[i][1] for i in rows])
        C = np.array([systems[i][2] for i in rows], dtype=float)
        for size in sorted({b - a + 1 for a, b in pieces}):
            group = [(a, b) for a, b in pieces if b - a + 1 == size]
            first = np.array([a for a, _ in group])
            span = scales[rows, None]
            F, G = zoh(A[:, None], B[:, None, :, None], span * (unit[first + 1] - unit[first]))  # (loops, pieces, ...)
            start = zoh(A[:, None], B[:, None, :, None], span * unit[first])[1]  # each piece's first state, from rest
            k, m = len(rows), len(group)
            runs = step_from_rest(F.reshape(k * m, order, order), G.reshape(k * m, order),
                                  np.repeat(C, m, axis=0), np.repeat(D, m), size,
                                  start.reshape(k * m, order)).reshape(k, m, size)
            for j, (a, b) in enumerate(group):
                out[rows, a:b + 1] = runs[:, j]
    return out


def _even_pieces(t: np.ndarray) -> list[tuple[int, int]]:
    """``(first, last)`` sample indices of pieces of ``t`` evenly spaced within, consecutive pieces sharing a
    sample: the runs of even spacing, each cut into pieces of the shortest run's number of steps."""
    d = np.diff(t)
    change = np.flatnonzero(np.abs(np.diff(d)) > 1e-9 * np.maximum(d[1:], d[:-1])) + 1  # d[i] != d[i - 1]
    edges = [0, *change.tolist(), d.size]
    length = min(b - a for a, b in pairwise(edges))
    return [(i, min(i + length, b)) for a, b in pairwise(edges) for i in range(a, b, length)]
