"""Golden-section search in the log of a grid parameter, between the best grid point's neighbours.

The effect searches (:mod:`synth.gap.attribution.screen`, :mod:`synth.gap.attribution.refit`) first evaluate a deterministic
grid, then refine the best point's parameter by a golden-section search in its logarithm (rates,
limits, widths and time constants are scale parameters).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["GOLDEN", "golden_section", "log_bracket", "parabolic_section"]

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


def parabolic_section(f: Callable[[float], float], a: float, m: float, b: float, fa: float, fm: float, fb: float,
                      iterations: int, tol: float) -> tuple[float, float]:
    """Minimize ``f`` on ``[a, b]`` from a bracketing triple already evaluated (``f(m)`` not above ``f(a), f(b)``).

    Successive parabolic interpolation through the best point and its two neighbours (Brent's method
    without its first golden points): a golden step into the larger side whenever the parabola's vertex
    falls outside the bracket or does not halve the move before last, and a probe ``tol / 2`` from the
    best point into the larger side when the vertex is closer than that to it. Stops after
    ``iterations`` evaluations or when the bracket is narrower than ``tol``: a smooth minimum takes
    3-5 evaluations where :func:`golden_section` takes ``log(tol / (b - a)) / log(GOLDEN)``.

    Returns
    -------
    (float, float)
        The best point and its value.

    Examples
    --------
    >>> calls = []
    >>> def f(x): calls.append(x); return (x - 0.3) ** 2 + 1.0
    >>> x, fx = parabolic_section(f, 0.0, 0.5, 1.0, f(0.0), f(0.5), f(1.0), 10, 1e-3)
    >>> round(x, 4), len(calls) - 3
    (0.3, 3)
    """
    if not (a < m < b and fm <= fa and fm <= fb):
        raise ValueError("parabolic_section needs a < m < b with f(m) <= f(a), f(b)")
    move_prev, move_last = np.inf, np.inf
    for _ in range(iterations):
        if b - a <= 1.001 * tol:  # (two probes leave exactly tol)
            break
        num = (m - a) ** 2 * (fm - fb) - (m - b) ** 2 * (fm - fa)
        den = (m - a) * (fm - fb) - (m - b) * (fm - fa)
        v = m - 0.5 * num / den if den != 0.0 else np.nan
        right = b - m > m - a
        if not (np.isfinite(v) and a < v < b and abs(v - m) < 0.5 * move_prev):
            v = m + (1.0 - GOLDEN) * (b - m) if right else m - (1.0 - GOLDEN) * (m - a)
        elif abs(v - m) < 0.5 * tol:
            v = m + 0.5 * tol if right else m - 0.5 * tol
        move_prev, move_last = move_last, abs(v - m)
        fv = f(v)
        if fv < fm:
            if v > m:
                a, fa = m, fm
            else:
                b, fb = m, fm
            m, fm = v, fv
        elif v > m:
            b, fb = v, fv
        else:
            a, fa = v, fv
    return m, fm
