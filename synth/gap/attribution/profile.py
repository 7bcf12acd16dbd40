"""Profile interval of a grid parameter: the values whose training SSR is within ``chi2_1(0.95) s^2`` of the best.

``s^2 = SSR_min/N``; the interval's ends are interpolated in the log of the parameter between the
fitted points. It assumes white residuals and is too narrow otherwise; where the fitted points never
rise above the level the end is the last point fitted (the record does not bound the parameter there).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from synth.distributions import chi2_ppf

__all__ = ["CHI2_1_95", "profile_interval", "profile_level"]

CHI2_1_95 = float(chi2_ppf(0.95, 1))  # 95 % quantile of chi-square with one degree of freedom


def profile_level(best_ssr: float, n: int) -> float:
    """The SSR at the edge of the 95 % profile interval: ``SSR_min (1 + chi2_1(0.95)/N)``.

    Examples
    --------
    >>> round(profile_level(100.0, 1000), 4)
    100.3841
    """
    return float(best_ssr) * (1.0 + CHI2_1_95 / n)


def profile_interval(points: Sequence[tuple[float, float]], best: tuple[float, float], n: int) -> tuple[float, float]:
    """95 % profile interval of a parameter of one sign from ``(value, SSR)`` points fitted at fixed values.

    A negative parameter (a saturation's lower limit) is profiled in the log of its magnitude, as a positive
    one in its log; points of the other sign are ignored.

    Parameters
    ----------
    points : sequence of (float, float)
        Parameter values and their training SSR (non-finite values and those not of the best's sign are ignored).
    best : (float, float)
        The best value and its SSR.
    n : int
        Number of fitted samples.

    Returns
    -------
    (float, float)
        Lower and upper end; ``(x, x)`` when nothing can be said (no usable points, a best value of 0).

    Examples
    --------
    >>> pts = [(x, 100.0 + 400.0 * np.log(x) ** 2) for x in (0.5, 0.8, 1.0, 1.25, 2.0)]
    >>> lo, hi = profile_interval(pts, (1.0, 100.0), 1000)
    >>> round(lo, 4), round(hi, 4)  # the level lies between 0.8 and 1.0, and 1.0 and 1.25: interpolated in log
    (0.9957, 1.0043)
    >>> lo, hi = profile_interval([(-x, s) for x, s in pts], (-1.0, 100.0), 1000)
    >>> round(lo, 4), round(hi, 4)
    (-1.0043, -0.9957)
    """
    x0 = float(best[0])
    if not (np.isfinite(x0) and x0 != 0.0):
        return (x0, x0)
    if x0 < 0:
        lo, hi = profile_interval([(-float(x), s) for x, s in points], (-x0, best[1]), n)
        return (-hi, -lo)
    lowest: dict[float, float] = {}  # the profile: at a value fitted more than once, the lowest SSR
    for x, s in points:
        if np.isfinite(s) and np.isfinite(x) and x > 0:
            lowest[float(x)] = min(float(s), lowest.get(float(x), np.inf))
    pts = sorted(lowest.items())
    level = profile_level(best[1], n)
    if not pts:
        return (x0, x0)
    xs = np.log([p[0] for p in pts])
    ss = np.array([p[1] for p in pts])
    i0 = int(np.argmin(np.abs(xs - np.log(x0))))

    def walk(step: int) -> float:
        i = i0
        while 0 <= i + step < xs.size and ss[i + step] <= level:
            i += step
        j = i + step
        if not 0 <= j < xs.size:
            return float(np.exp(xs[i]))
        frac = (level - ss[i]) / (ss[j] - ss[i]) if ss[j] != ss[i] else 0.0
        return float(np.exp(xs[i] + frac * (xs[j] - xs[i])))

    return walk(-1), walk(1)
