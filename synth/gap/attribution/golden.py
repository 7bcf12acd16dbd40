"""Golden-section search in the log of a grid parameter, between the best grid point's neighbours.

The effect searches (:mod:`synth.gap.attribution.screen`, :mod:`synth.gap.attribution.refit`) first evaluate a deterministic
grid, then refine the best point's parameter by a golden-section search in its logarithm (rates,
limits, widths and time constants are scale parameters).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["GOLDEN", "golden_section", "log_bracket"]

GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0


def log_bracket(values: list[float], x0: float) -> tuple[float, float] | None:
    """The logs of ``x0``'s neighbours among the sorted positive ``values`` (one grid step beyond at the ends).

    Returns ``None`` when there are fewer than two values or ``x0`` is not one of them.

    Examples
    --------
    >>> a, b = log_bracket([1.0, 10.0, 100.0], 10.0)
    >>> round(float(np.exp(a)), 6), round(float(np.exp(b)), 6)
    (1.0, 100.0)
    >>> round(float(np.exp(log_bracket([1.0, 10.0, 100.0], 100.0)[1])), 6)  # one step beyond the last
    1000.0
    """
    if len(values) < 2 or not (np.isfinite(x0) and x0 > 0) or x0 not in values:
        return None
    i = values.index(x0)
    lx = np.log(values)
    a = lx[i - 1] if i > 0 else lx[0] - (lx[1] - lx[0])
    b = lx[i + 1] if i + 1 < len(values) else lx[-1] + (lx[-1] - lx[-2])
    return float(a), float(b)


def golden_section(f: Callable[[float], float], a: float, b: float, iterations: int,
                   tol: float = 0.0) -> tuple[float, float]:
    """Golden-section minimization of ``f`` on ``[a, b]``; the last two interior points.

    ``2 + iterations`` evaluations at most; stops early once the bracket is narrower than ``tol``.

    Examples
    --------
    >>> c, d = golden_section(lambda x: (x - 0.3) ** 2, 0.0, 1.0, 30)
    >>> round(float(c), 4), round(float(d), 4)
    (0.3, 0.3)
    """
    c, d = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iterations):
        if b - a < tol:
            break
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - GOLDEN * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + GOLDEN * (b - a)
            fd = f(d)
    return c, d
