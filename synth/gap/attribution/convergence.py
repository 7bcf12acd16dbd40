"""Where a linearly converging descent is heading: Aitken's extrapolation of its last three values.

Block-coordinate descent (the re-fit's alternation of the casadi fit and the basis least squares)
decreases the cost by about the same ratio each round near its limit. Three successive costs
``s0 > s1 > s2`` with ratio ``r = (s1 - s2)/(s0 - s1) < 1`` extrapolate to
``s2 - (s1 - s2) r/(1 - r)``. :func:`cannot_reach` uses it to stop a second start that will end
where (or above where) the first one did.
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["aitken_limit", "cannot_reach"]

_MAX_RATIO = 0.8  # a slower descent is not trusted to be geometric: no extrapolation


def aitken_limit(costs: Sequence[float]) -> float | None:
    """The limit of a geometrically decreasing sequence from its last three values, or ``None``.

    ``None`` when there are fewer than three values, the last two steps are not both decreases, or the
    steps shrink by a ratio above 0.8 (too slow to extrapolate safely).

    Examples
    --------
    >>> aitken_limit([10.0 + 4.0 * 0.5**k for k in range(4)])  # 14, 12, 11, 10.5 -> 10
    10.0
    >>> aitken_limit([3.0, 2.0]) is None, aitken_limit([3.0, 2.0, 2.5]) is None
    (True, True)
    """
    if len(costs) < 3:
        return None
    s0, s1, s2 = (float(c) for c in costs[-3:])
    d0, d1 = s0 - s1, s1 - s2
    if not (d0 > 0.0 and d1 > 0.0) or d1 > _MAX_RATIO * d0:
        return None
    ratio = d1 / d0
    return s2 - d1 * ratio / (1.0 - ratio)


def cannot_reach(costs: Sequence[float], target: float) -> bool:
    """True when a descent with these costs so far is heading to a limit at or above ``target``.

    Examples
    --------
    >>> costs = [10.0 + 4.0 * 0.5**k for k in range(4)]  # limit 10
    >>> cannot_reach(costs, 9.5), cannot_reach(costs, 10.5), cannot_reach(costs[:2], 10.5)
    (True, False, False)
    """
    limit = aitken_limit(costs)
    return limit is not None and limit >= target
