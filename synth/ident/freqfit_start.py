"""A formula structure's start for the frequency-response fit, from the orders fit of the same degrees.

A formula's parameters are started from a few constant vectors (1 and the band's edges and centre): all positive,
so a structure such as ``c*(s+z)/((s+p1)*(s+p2))`` starts minimum-phase. Behind a right-half-plane zero IPOPT then
carries ``z`` away to a local optimum (a black-box test: z = 6.5e6 rad/s, a 0.108 s delay standing in for the zero at
+6.88 rad/s, J = 111, where the orders fit ``1/2`` found the zero at J = 1.13). Matching the formula's coefficients
to the orders fit's (both normalized by the denominator's leading coefficient) gives a start in the right basin
whatever the signs.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["matched_start"]


def _normalized(num: np.ndarray, den: np.ndarray, size: tuple[int, int]) -> np.ndarray | None:
    num, den = np.atleast_1d(np.asarray(num, float)), np.atleast_1d(np.asarray(den, float))
    lead = den[np.flatnonzero(den)[0]] if np.any(den) else 0.0
    if lead == 0.0 or not np.isfinite(lead):
        return None
    num, den = np.r_[np.zeros(max(size[0] - num.size, 0)), num], np.r_[np.zeros(max(size[1] - den.size, 0)), den]
    return np.r_[num[-size[0]:], den[-size[1]:]] / lead


#: the starts are tried with every sign pattern up to this many parameters (2^n each), beyond it as given
SIGNED_UP_TO = 6
#: at most this many Levenberg-Marquardt matches, from the signed starts with the smallest residuals
MATCHED_RUNS = 8
#: a match this close (sum of squared relative coefficient errors) ends the search
EXACT_MATCH = 1e-12


def _signed(starts: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Each start with every pattern of its parameters' signs: a coefficient match from a
    positive start reaches ``c < 0, z < 0`` in ``c*(s+z)`` only across ``c = 0, z -> inf``, where the
    Levenberg-Marquardt steps stop or not by the last digits of the arithmetic (a test's worker ended at c = 0,
    z = 3.9e6 where the same call alone crosses)."""
    out = []
    for x0 in starts:
        x0 = np.asarray(x0, float)
        patterns = itertools.product((1.0, -1.0), repeat=x0.size) if x0.size <= SIGNED_UP_TO else [np.ones(x0.size)]
        out += [x0 * np.asarray(p) for p in patterns]
    return out


def matched_start(structure: Any, orders_num: np.ndarray, orders_den: np.ndarray,
                  starts: Sequence[np.ndarray]) -> np.ndarray | None:
    """The structure's parameters whose coefficients best match the orders fit's (relative least squares, from
    each of ``starts`` with every pattern of signs); None when no start gives finite coefficients.

    Parameters
    ----------
    structure : Structure
        With ``coefficients(theta) -> (num, den)``, highest power first.
    orders_num, orders_den : numpy.ndarray
        The orders fit's polynomials (same degrees as the structure's).
    starts : sequence of numpy.ndarray
        Parameter vectors to start the matching from.

    Returns
    -------
    numpy.ndarray or None

    Examples
    --------
    >>> from synth.ident.structure import parse_structure
    >>> st = parse_structure("c*(s+z)/((s+p1)*(s+p2))")
    >>> theta = matched_start(st, np.array([-12.64, 86.99]), np.array([1.0, 8.407, 17.63]), [np.ones(4)])
    >>> dict(zip(st.parameters, np.round(theta, 3)))["z"]  # the zero at +6.88 rad/s: z < 0
    np.float64(-6.882)
    """
    from scipy.optimize import least_squares

    size = (len(orders_num), len(orders_den))
    target = _normalized(orders_num, orders_den, size)
    if target is None or not np.all(np.isfinite(target)):
        return None
    scale = np.abs(target) + 1e-3 * np.max(np.abs(target))

    def residual(theta: np.ndarray) -> np.ndarray:
        got = _normalized(*structure.coefficients(theta), size)
        if got is None or got.size != target.size or not np.all(np.isfinite(got)):
            return np.full(target.size, 1e6)
        return (got - target) / scale

    def initial(x0: np.ndarray) -> float:
        cost = float(np.sum(residual(x0) ** 2))
        return cost if np.isfinite(cost) else np.inf

    best: tuple[float, np.ndarray] | None = None
    # the closest few sign patterns first (by their residual before any step), until one matches exactly
    for x0 in sorted(_signed(starts), key=initial)[:MATCHED_RUNS]:
        if best is not None and best[0] < EXACT_MATCH:
            break
        try:
            sol = least_squares(residual, np.asarray(x0, float), method="lm", max_nfev=200 * (len(x0) + 1))
        except (ValueError, np.linalg.LinAlgError):
            continue
        cost = float(np.sum(sol.fun ** 2))
        if np.all(np.isfinite(sol.x)) and np.isfinite(cost) and (best is None or cost < best[0]):
            best = (cost, sol.x)
    return None if best is None else best[1]
