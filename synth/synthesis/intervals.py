"""Sets of a real parameter as sorted lists of closed intervals ``[(lo, hi), ...]``: intersection, union and
removal, for the exact one-parameter feasible sets of :mod:`synth.synthesis.gainset`."""

from __future__ import annotations

import numpy as np

__all__ = ["intersect", "interval_middle", "remove", "union"]

Intervals = list[tuple[float, float]]


def intersect(a: Intervals, b: Intervals) -> Intervals:
    """The values in both ``a`` and ``b``.

    Examples
    --------
    >>> intersect([(0.0, 2.0), (3.0, 5.0)], [(1.0, 4.0)])
    [(1.0, 2.0), (3.0, 4.0)]
    """
    out = []
    for lo1, hi1 in a:
        for lo2, hi2 in b:
            lo, hi = max(lo1, lo2), min(hi1, hi2)
            if lo <= hi:
                out.append((lo, hi))
    return sorted(out)


def union(a: Intervals, b: Intervals) -> Intervals:
    """The values in ``a`` or ``b``, overlapping and touching intervals merged.

    Examples
    --------
    >>> union([(0.0, 1.0), (4.0, 5.0)], [(1.0, 2.0)])
    [(0.0, 2.0), (4.0, 5.0)]
    """
    out: Intervals = []
    for lo, hi in sorted([*a, *b]):
        if out and lo <= np.nextafter(out[-1][1], np.inf):  # one float apart: the pieces :func:`remove` leaves
            out[-1] = (out[-1][0], max(out[-1][1], hi))
        else:
            out.append((lo, hi))
    return out


def remove(a: Intervals, lo: float, hi: float) -> Intervals:
    """``a`` without the closed interval ``[lo, hi]``: the pieces left end one float short of it.

    Examples
    --------
    >>> [(float(x), float(y)) for x, y in remove([(0.0, 10.0)], 2.0, 3.0)] == [
    ...     (0.0, float(np.nextafter(2.0, -np.inf))), (float(np.nextafter(3.0, np.inf)), 10.0)]
    True
    >>> union(remove([(0.0, 10.0)], 2.0, 3.0), [(2.0, 3.0)])
    [(0.0, 10.0)]
    """
    below, above = float(np.nextafter(lo, -np.inf)), float(np.nextafter(hi, np.inf))
    out = []
    for a_lo, a_hi in a:
        if a_hi < lo or a_lo > hi:
            out.append((a_lo, a_hi))
            continue
        if a_lo <= below:
            out.append((a_lo, below))
        if a_hi >= above:
            out.append((above, a_hi))
    return out


def interval_middle(lo: float, hi: float) -> float:
    """A point well inside ``[lo, hi]``: the geometric middle of an interval of one sign spanning more than a
    factor 10, else the arithmetic middle.

    Examples
    --------
    >>> interval_middle(-2.0, -1.5), interval_middle(1e-4, 1.0)
    (-1.75, 0.01)
    """
    if lo * hi > 0 and max(abs(lo), abs(hi)) > 10 * min(abs(lo), abs(hi)):
        return float(np.sign(lo) * np.sqrt(lo * hi))
    return 0.5 * (lo + hi)
