"""Crossings of boundary curves sampled as short chords (the D-decomposition of a plane of two gains,
:mod:`synth.synthesis.stabilizing_plane`): where two curves, a curve and itself, or a curve and a line cross, in
coordinates scaled to the box (both axes 0 to 1).

A chord is a row ``[w0, u0, v0, w1, u1, v1]``: the curve's parameter (a frequency) and its point at both ends.
Crossings are found between chords and refined on the curves themselves, through a curve's ``at(w)`` (its points
``(u, v, ...)`` at the frequencies ``w``).
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

__all__ = ["CHORD", "Curve", "chord_crossings", "chords_intersect", "line_crossings"]

CHORD = 2e-3
"""Longest chord of a boundary curve near the box, as a share of the box (both axes scaled to 1): crossings are
looked for only between chords whose middles are at most two cells of twice this size apart."""


class Curve(Protocol):
    """A curve of the plane: its scaled points at frequencies ``w`` (``at(w)[0]`` is ``u``, ``[1]`` is ``v``)."""

    def at(self, w: np.ndarray) -> tuple[Any, ...]: ...


def line_crossings(lines: list[np.ndarray], segments: list[np.ndarray]) -> np.ndarray:
    """The scaled ``x`` where the lines ``a u + b v + c = 0`` (rows ``[a, b, c]``) cross the box's lower and upper
    edges, each other and the chords.

    Examples
    --------
    >>> line_crossings([np.array([1.0, -1.0, 0.0])], []).tolist()  # u = v meets v = 0 and v = 1 at u = 0 and 1
    [0.0, 1.0]
    """
    out: list[float] = []
    for i, (a, b, c) in enumerate(lines):
        if abs(b) < 1e-15:
            out.append(-c / a)
        else:
            out += [(-c - b * edge) / a for edge in (0.0, 1.0) if abs(a) > 1e-15]
        for a2, b2, c2 in lines[i + 1:]:
            det = a * b2 - a2 * b
            if abs(det) > 1e-12:
                out.append((b * c2 - b2 * c) / det)
        for seg in segments:
            f0 = a * seg[:, 1] + b * seg[:, 2] + c
            f1 = a * seg[:, 4] + b * seg[:, 5] + c
            k = np.flatnonzero(f0 * f1 <= 0)
            t = f0[k] / np.where(f0[k] == f1[k], 1.0, f0[k] - f1[k])
            out += (seg[k, 1] + t * (seg[k, 4] - seg[k, 1])).tolist()
    return np.array(out, float)


def chord_crossings(segments: list[np.ndarray], curves: list[Curve]) -> np.ndarray:
    """The scaled ``x`` of every crossing between chords (of one curve or of two; ``curves[i]`` is the curve of
    ``segments[i]``), each refined on the curves themselves. Chords are short (:data:`CHORD`): only chords whose
    midpoints share a cell of a grid of twice that size, or neighbouring cells, are tested."""
    if not segments:
        return np.zeros(0)
    rows = np.concatenate(segments)
    owner = np.concatenate([np.full(len(s), i) for i, s in enumerate(segments)])
    order = np.concatenate([np.arange(len(s)) for s in segments])
    cell = 2.0 * CHORD
    mid = 0.5 * (rows[:, [1, 2]] + rows[:, [4, 5]])
    keys = np.floor(mid / cell).astype(np.int64)
    long = np.hypot(rows[:, 4] - rows[:, 1], rows[:, 5] - rows[:, 2]) > cell
    buckets: dict[tuple[int, int], list[int]] = {}
    for i, (kx, ky) in enumerate(keys):
        buckets.setdefault((int(kx), int(ky)), []).append(i)
    pairs: set[tuple[int, int]] = set()
    for (kx, ky), members in buckets.items():
        near = [j for dx in (-1, 0, 1) for dy in (-1, 0, 1) for j in buckets.get((kx + dx, ky + dy), [])]
        near_arr = np.array(near)
        for i in members:
            others = near_arr[near_arr > i]
            hits = others[chords_intersect(rows[i], rows[others])]
            pairs.update((i, int(j)) for j in hits)
    for i in np.flatnonzero(long):  # chords the refinement could not shorten: against every other
        others = np.delete(np.arange(len(rows)), i)
        pairs.update((min(i, int(j)), max(i, int(j))) for j in others[chords_intersect(rows[i], rows[others])])
    out = []
    for i, j in pairs:
        if owner[i] == owner[j] and abs(int(order[i]) - int(order[j])) <= 1:
            continue  # neighbouring chords of one piece share an end
        out.append(_refined_crossing(curves[owner[i]], rows[i], curves[owner[j]], rows[j]))
    return np.array(out, float)


def chords_intersect(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Whether chord ``p`` (a row ``[w0, u0, v0, w1, u1, v1]``) crosses each chord of ``q`` (rows).

    Examples
    --------
    >>> p = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    >>> chords_intersect(p, np.array([[0.0, 0.0, 1.0, 1.0, 1.0, 0.0], [0.0, 0.0, 0.5, 1.0, 0.2, 0.9]])).tolist()
    [True, False]
    """
    def orient(ax, ay, bx, by, cx, cy):
        return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)

    o1 = orient(p[1], p[2], p[4], p[5], q[:, 1], q[:, 2])
    o2 = orient(p[1], p[2], p[4], p[5], q[:, 4], q[:, 5])
    o3 = orient(q[:, 1], q[:, 2], q[:, 4], q[:, 5], p[1], p[2])
    o4 = orient(q[:, 1], q[:, 2], q[:, 4], q[:, 5], p[4], p[5])
    return (o1 * o2 <= 0) & (o3 * o4 <= 0) & ~((o1 == 0) & (o2 == 0))


def _refined_crossing(ca: Curve, a: np.ndarray, cb: Curve, b: np.ndarray) -> float:
    """The scaled ``x`` of the crossing of two chords, refined on their curves: each chord's frequency interval
    cut in 8, the crossing sub-chords kept, five times."""
    wa, wb = (a[0], a[3]), (b[0], b[3])
    x = _crossing_x(a, b)
    for _ in range(5):
        sa, sb = _subchords(ca, *wa), _subchords(cb, *wb)
        found = False
        for ra in sa:
            hit = chords_intersect(ra, sb)
            if np.any(hit):
                rb = sb[int(np.flatnonzero(hit)[0])]
                wa, wb, x, found = (ra[0], ra[3]), (rb[0], rb[3]), _crossing_x(ra, rb), True
                break
        if not found:
            break
    return x


def _subchords(curve: Curve, w0: float, w1: float) -> np.ndarray:
    w = np.linspace(w0, w1, 9)
    u, v, _ = curve.at(w)
    return np.column_stack([w[:-1], u[:-1], v[:-1], w[1:], u[1:], v[1:]])


def _crossing_x(p: np.ndarray, q: np.ndarray) -> float:
    """The scaled ``x`` where the lines through two chords meet (an end's when they are parallel)."""
    r = np.array([p[4] - p[1], p[5] - p[2]])
    s = np.array([q[4] - q[1], q[5] - q[2]])
    den = r[0] * s[1] - r[1] * s[0]
    if den == 0.0:
        return float(p[1])
    t = ((q[1] - p[1]) * s[1] - (q[2] - p[2]) * s[0]) / den
    return float(p[1] + min(max(t, 0.0), 1.0) * r[0])
