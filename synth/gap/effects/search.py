"""A local search of several nonnegative scale parameters at once (time constants, latencies).

:func:`pattern_search` is Hooke and Jeeves' pattern search (:func:`synth.search.hooke_jeeves`) in
``z = log(p + floor)``: a parameter at 0 sits at the lower end of its coordinate and is switched on by the
same steps that scale a nonzero one. Its pattern moves walk along the ridges two parameters that trade off
(a latency and a time constant) make, where moves of one coordinate at a time would crawl.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from synth.search import hooke_jeeves

__all__ = ["pattern_search"]

Params = dict[str, float]


def pattern_search(cost: Callable[[Params], float], start: Params, names: tuple[str, ...], floor: float,
                   upper: dict[str, float], step: float = 4.0, tol: float = 1.03, budget: int = 150) -> Params:
    """Hooke-Jeeves pattern search of the parameters ``names`` (each >= 0) in ``log(p + floor)``.

    Parameters
    ----------
    cost : callable
        Cost of a parameter point (``start`` with the searched parameters replaced).
    start : dict
        Starting point (every name of ``names`` in it, values >= 0).
    names : tuple of str
        The parameters searched.
    floor : float
        Scale below which a parameter is as good as 0 (> 0): the log's offset.
    upper : dict
        Largest value of each parameter (missing: unbounded).
    step : float
        First step, a factor on ``p + floor`` (> 1); halved in the log when no move helps.
    tol : float
        Smallest step factor: the search stops below it.
    budget : int
        Most cost evaluations.

    Returns
    -------
    dict
        The best point found (``start`` if none is better).

    Examples
    --------
    >>> f = lambda p: (np.log(p["a"] + 0.01) - np.log(0.31)) ** 2 + (p["b"] - 0.05) ** 2 * 100
    >>> best = pattern_search(f, {"a": 0.0, "b": 0.0, "c": 7.0}, ("a", "b"), 0.01, {})
    >>> round(best["a"], 2), round(best["b"], 3), best["c"]
    (0.3, 0.05, 7.0)
    """
    if floor <= 0 or step <= 1 or tol <= 1:
        raise ValueError("need floor > 0, step > 1 and tol > 1")
    lo = np.full(len(names), float(np.log(floor)))
    hi = np.array([np.log(upper.get(k, np.inf) + floor) for k in names])

    def point(z: np.ndarray) -> Params:
        return {**start, **{k: float(max(np.exp(zi) - floor, 0.0)) for k, zi in zip(names, z)}}

    z0 = np.array([np.log(max(start[k], 0.0) + floor) for k in names])
    found = hooke_jeeves(lambda z: float(cost(point(z))), z0, lo, hi,
                         lambda a, b: a < b - 1e-9 * abs(b),  # beyond round-off: log and exp are not exact
                         float(np.log(step)), float(np.log(tol)), budget)
    return point(found.z)
