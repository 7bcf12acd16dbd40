"""A local search of an effect's grid parameters together (both limits of a saturation, ...).

The grid and the section search along one parameter (:mod:`synth.gap.attribution.refit`) move one limit at a time;
with a PI's wound-up integrator the command passes both limits far and unevenly, and one limit moved alone
trades against the other (a one-sided clip plus a bias fitted 250 times the noise, the true pair at the
noise). From the best point with two or more of these parameters finite, Nelder-Mead over them, each
evaluation a warm-started re-fit of the nominal coefficients.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.optimize import minimize

__all__ = ["fewest_limits", "ranges_within", "search_from_points", "search_jointly"]


def search_jointly(fit: Callable[[dict[str, float]], Any], best_params: dict[str, float], names: list[str],
                   steps: list[float], noise_ssr: float, max_fits: int = 40) -> list[Any]:
    """Nelder-Mead over ``names`` from ``best_params``; every point fitted, in order.

    Parameters
    ----------
    fit : callable
        ``fit(params) -> point`` with a training ``ssr`` attribute (``inf`` where the fit failed).
    best_params : dict
        The start (the best grid or section point's parameters).
    names : list of str
        The parameters searched together.
    steps : list of float
        The initial simplex's step in each.
    noise_ssr : float
        One noise variance of training SSR: the search stops when the simplex's SSRs agree to it.
    max_fits : int
        Budget of fits.

    Returns
    -------
    list
        The fitted points.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> bowl = lambda p: SimpleNamespace(params=p, ssr=(p["lower"] + 0.9) ** 2 + (p["upper"] - 0.9) ** 2)
    >>> pts = search_jointly(bowl, {"lower": -0.5, "upper": 1.3}, ["lower", "upper"], [0.1, 0.1], 1e-8)
    >>> best = min(pts, key=lambda p: p.ssr).params
    >>> round(best["lower"], 2), round(best["upper"], 2)
    (-0.9, 0.9)
    """
    points: list[Any] = []

    def cost(x: np.ndarray) -> float:
        if len(points) >= max_fits:
            return float("inf")
        point = fit({**best_params, **{k: float(v) for k, v in zip(names, x)}})
        points.append(point)
        return float(point.ssr) if np.isfinite(point.ssr) else 1e300

    x0 = np.array([best_params[k] for k in names], float)
    simplex = np.vstack([x0] + [x0 + np.eye(len(names))[i] * steps[i] for i in range(len(names))])
    minimize(cost, x0, method="Nelder-Mead",
             options={"initial_simplex": simplex, "maxfev": max_fits, "xatol": 0.02 * min(steps),
                      "fatol": noise_ssr})
    return points


def _finite(params: dict[str, float], names: list[str]) -> bool:
    return all(np.isfinite(params.get(k, np.nan)) for k in names)


def search_from_points(fit: Callable[[dict[str, float], dict[str, float]], Any], names: list[str], points: list[Any],
                       start: dict[str, float], step: float, n: int) -> list[Any]:
    """:func:`search_jointly` over ``names`` from the best point with all of them finite (the best point when it
    has none switched off: a one-sided limit).

    Parameters
    ----------
    fit : callable
        ``fit(params, warm_nominal) -> point`` (``params``, ``ssr`` and ``nominal`` attributes).
    names : list of str
        The parameters searched together (an effect's grid parameters).
    points : list
        The fitted points so far (grid and section search).
    start : dict
        The nominal coefficients' names (and start values) of the fit.
    step : float
        The initial simplex's step in each parameter.
    n : int
        Fitted samples (the noise variance of SSR is ``ssr / n``).

    Returns
    -------
    list
        The points fitted.

    Examples
    --------
    >>> from types import SimpleNamespace as P
    >>> bowl = lambda p, w: P(params=p, nominal={}, ssr=(p["lower"] + 0.9) ** 2 + (p["upper"] - 0.9) ** 2 + 1e-6)
    >>> one_sided = P(params={"lower": -np.inf, "upper": 1.4}, nominal={}, ssr=0.3)
    >>> pts = [one_sided, bowl({"lower": -0.4, "upper": 1.4}, {})]
    >>> found = min(search_from_points(bowl, ["lower", "upper"], pts, {}, 0.1, 1000), key=lambda p: p.ssr)
    >>> round(found.params["lower"], 2), round(found.params["upper"], 2)
    (-0.9, 0.9)
    """
    whole = [p for p in points if _finite(p.params, names)]
    if not whole:
        return []
    origin = min(whole, key=lambda p: p.ssr)  # ``best`` itself unless it has a parameter switched off
    warm = {k: v for k, v in origin.nominal.items() if k in start}
    return search_jointly(lambda prm: fit(prm, warm), dict(origin.params), names, [step] * len(names),
                          origin.ssr / max(n, 1))


def ranges_within(names: list[str], points: list[Any], best: Any, level: float) -> dict[str, tuple[float, float]]:
    """Each parameter's range over the fitted points with all ``names`` finite and SSR within ``level``.

    The points of a joint search are no profile along one parameter; the values they reached inside the 95 %
    level bound its interval from inside. Empty when ``best`` has a parameter switched off.

    Examples
    --------
    >>> from types import SimpleNamespace as P
    >>> pts = [P(params={"a": a, "b": 1.0}, ssr=abs(a)) for a in (-2.0, -1.0, 0.0, 1.0, 3.0)]
    >>> ranges_within(["a", "b"], pts, pts[2], 1.5)
    {'a': (-1.0, 1.0), 'b': (1.0, 1.0)}
    """
    if not _finite(best.params, names):
        return {}
    inside = [p.params for p in points if p.ssr <= level and _finite(p.params, names)]
    return {k: (min(q[k] for q in inside), max(q[k] for q in inside)) for k in names}


def fewest_limits(points: list[Any], names: list[str], n: int, critical: float = 3.84) -> Any:
    """The best point, or the best with a parameter switched off (a one-sided limit) unless the best beats it by
    ``critical`` noise variances of SSR (the 95 % point of chi-square with one degree of freedom).

    A limit the record never reaches leaves the SSR flat, and the search ends wherever it stopped: such a limit is
    not claimed.

    Examples
    --------
    >>> from types import SimpleNamespace as P
    >>> one = P(params={"lower": -np.inf, "upper": 2.0}, ssr=100.0)
    >>> two = P(params={"lower": -7.0, "upper": 2.0}, ssr=99.9)
    >>> fewest_limits([one, two], ["lower", "upper"], 1000) is one
    True
    >>> fewest_limits([one, P(params={"lower": -1.0, "upper": 2.0}, ssr=90.0)], ["lower", "upper"], 1000) is one
    False
    """
    best = min(points, key=lambda p: p.ssr)
    fewer = [p for p in points if not _finite(p.params, names) and np.isfinite(p.ssr)]
    if not _finite(best.params, names) or not fewer:
        return best
    simpler = min(fewer, key=lambda p: p.ssr)
    return best if best.ssr < simpler.ssr - critical * simpler.ssr / max(n, 1) else simpler
