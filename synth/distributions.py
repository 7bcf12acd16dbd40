"""Quantiles and tail probabilities of the distributions synth's tests use (chi-square, F, Student t, normal,
Kolmogorov), from :mod:`scipy.special`: the same functions :mod:`scipy.stats` evaluates, without its import
(about 0.3 s, paid by every command that reports a confidence interval).
"""

from __future__ import annotations

import numpy as np
from scipy import special

__all__ = ["chi2_isf", "chi2_median", "chi2_ppf", "chi2_sf", "f_cdf", "f_sf", "kolmogorov_ppf", "norm_ppf",
           "norm_sf", "t_ppf"]


def chi2_ppf(q: float | np.ndarray, df: float | np.ndarray) -> np.ndarray:
    """Quantile ``q`` of the chi-square distribution with ``df`` degrees of freedom.

    Examples
    --------
    >>> round(float(chi2_ppf(0.95, 2)), 6)
    5.991465
    """
    return special.chdtri(df, 1.0 - np.asarray(q, float))


def chi2_isf(p: float | np.ndarray, df: float | np.ndarray) -> np.ndarray:
    """The value whose upper tail probability is ``p`` (chi-square, ``df`` degrees of freedom).

    Examples
    --------
    >>> round(float(chi2_isf(0.05, 2)), 6)
    5.991465
    """
    return special.chdtri(df, p)


def chi2_sf(x: float | np.ndarray, df: float | np.ndarray) -> np.ndarray:
    """Upper tail probability ``P(X > x)``, chi-square with ``df`` degrees of freedom.

    Examples
    --------
    >>> round(float(chi2_sf(5.991465, 2)), 6)
    0.05
    """
    return special.chdtrc(df, x)


def chi2_median(df: float | np.ndarray) -> np.ndarray:
    """Median of the chi-square distribution with ``df`` degrees of freedom.

    Examples
    --------
    >>> round(float(chi2_median(2)), 6)
    1.386294
    """
    return chi2_ppf(0.5, df)


def f_sf(x: float | np.ndarray, d1: float, d2: float) -> np.ndarray:
    """Upper tail probability of the F distribution with ``(d1, d2)`` degrees of freedom.

    Examples
    --------
    >>> round(float(f_sf(3.0, 2, 10)), 6)
    0.095367
    """
    return special.fdtrc(d1, d2, x)


def f_cdf(x: float | np.ndarray, d1: float, d2: float) -> np.ndarray:
    """Lower tail probability of the F distribution with ``(d1, d2)`` degrees of freedom.

    Examples
    --------
    >>> round(float(f_cdf(3.0, 2, 10)), 6)
    0.904633
    """
    return special.fdtr(d1, d2, x)


def t_ppf(q: float | np.ndarray, df: float | np.ndarray) -> np.ndarray:
    """Quantile ``q`` of Student's t distribution with ``df`` degrees of freedom.

    Examples
    --------
    >>> round(float(t_ppf(0.975, 10)), 6)
    2.228139
    """
    return special.stdtrit(df, q)


def norm_ppf(q: float | np.ndarray) -> np.ndarray:
    """Quantile ``q`` of the standard normal distribution.

    Examples
    --------
    >>> round(float(norm_ppf(0.975)), 6)
    1.959964
    """
    return special.ndtri(q)


def norm_sf(x: float | np.ndarray) -> np.ndarray:
    """Upper tail probability of the standard normal distribution.

    Examples
    --------
    >>> round(float(norm_sf(1.959964)), 6)
    0.025
    """
    return special.ndtr(-np.asarray(x, float))


def kolmogorov_ppf(q: float | np.ndarray) -> np.ndarray:
    """Quantile ``q`` of the Kolmogorov distribution (the limit of ``sqrt(n) D_n``).

    Examples
    --------
    >>> round(float(kolmogorov_ppf(0.95)), 6)
    1.358099
    """
    return special.kolmogi(1.0 - np.asarray(q, float))
