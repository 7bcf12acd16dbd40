"""The composite's evident bias at a sweep's low end, measured against the local rational method.

Below 20 periods of the longest window a run that does not start and end at rest gets its response from the local
rational method (:mod:`synth.ident.local_rational`), except where that method's random error is several times the
composite's. The composite's random error there counts noise only: its windows' taper and the run's transient bias
it by an amount that does not shrink with the noise (an integrating plant's sweep, 5 % noise: 40 % low at 0.17-0.33
rad/s with random errors of 0.3-7 %). Where the method is used, the two differ by that bias plus their random errors;
the bias is smooth in frequency, so at a point between such points the composite is taken to carry the bias its
neighbours show. This module estimates it, so that the choice between the two compares honest errors.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BIAS_NEIGHBOURS", "BIAS_SIGMAS", "PRECISE", "composite_bias"]

BIAS_SIGMAS = 2.0
"""The part of the two estimates' difference within this many of their combined random errors is noise, not bias."""

BIAS_NEIGHBOURS = 4
"""Points on each side of a frequency whose measured bias is looked at (0.1 decade on the default grid)."""

PRECISE = 0.1
"""Only where the method's own random error is at most this is its difference from the composite evidence of bias: at
a sweep's first frequencies the method can be many times off (18 times at 0.36 rad/s, its error 0.3)."""


def composite_bias(H_composite: np.ndarray, err_composite: np.ndarray, H_method: np.ndarray,
                   err_method: np.ndarray, used: np.ndarray) -> np.ndarray:
    """The composite's bias (relative to ``|H|``) at each point: the median, over the points within
    :data:`BIAS_NEIGHBOURS` on either side where the method is ``used`` with a random error of at most
    :data:`PRECISE`, of how far the two estimates differ beyond
    :data:`BIAS_SIGMAS` combined random errors; 0 where no such point is near.

    The median asks for most of the neighbours to agree, so one point where the method itself is off (little input
    at that frequency) does not make the composite look biased.

    Parameters
    ----------
    H_composite, err_composite : numpy.ndarray
        The composite's response and normalized random error at consecutive grid points.
    H_method, err_method : numpy.ndarray
        The local rational method's, at the same points.
    used : numpy.ndarray of bool
        Where the method's response is taken.

    Returns
    -------
    numpy.ndarray
        The bias estimate at every point (0 or more).

    Examples
    --------
    >>> import numpy as np
    >>> Hc = np.full(5, 0.6 + 0j); Hm = np.ones(5, complex)
    >>> used = np.array([True, True, False, True, True])
    >>> np.round(composite_bias(Hc, np.full(5, 0.01), Hm, np.full(5, 0.02), used), 3)
    array([0.622, 0.622, 0.622, 0.622, 0.622])
    """
    Hc, Hm = np.asarray(H_composite, complex), np.asarray(H_method, complex)
    noise = BIAS_SIGMAS * np.hypot(np.asarray(err_composite, float), np.asarray(err_method, float))
    with np.errstate(divide="ignore", invalid="ignore"):
        excess = np.abs(Hc - Hm) / np.abs(Hc) - noise
    measured = np.asarray(used, bool) & np.isfinite(excess) & (np.asarray(err_method, float) <= PRECISE)
    bias = np.zeros(Hc.size)
    for i in range(Hc.size):
        near = slice(max(0, i - BIAS_NEIGHBOURS), i + BIAS_NEIGHBOURS + 1)
        values = excess[near][measured[near]]
        if values.size:
            bias[i] = max(0.0, float(np.median(values)))
    return bias
