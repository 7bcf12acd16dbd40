"""When a restart of the convex stage's phase 1 may stop: it is heading to the infeasible total an earlier start
converged to (every start of an infeasible structure, 7 of them, took 30-40 convex solves to creep to the same
limit)."""

from __future__ import annotations

import numpy as np

__all__ = ["heading_above"]


def heading_above(totals: list[float], level: float) -> bool:
    """Whether the last three totals of phase 1 shrink geometrically (the last two decreases in a ratio below 0.9)
    towards a limit at or above ``level`` (the last total less the rest of the geometric series).

    Examples
    --------
    >>> heading_above([1.0, 0.6, 0.44, 0.376], 0.3), heading_above([1.0, 0.6, 0.44, 0.376], 0.4)
    (True, False)
    >>> heading_above([1.0, 0.9, 0.5], 0.1)  # a decrease that grew: no geometric tail yet
    False
    """
    if len(totals) < 3 or not np.isfinite(level) or level <= 0.0:
        return False
    d1, d2 = totals[-3] - totals[-2], totals[-2] - totals[-1]
    if d1 <= 0.0 or d2 < 0.0:
        return False
    ratio = d2 / d1
    return ratio < 0.9 and totals[-1] - d2 * ratio / (1.0 - ratio) >= level
