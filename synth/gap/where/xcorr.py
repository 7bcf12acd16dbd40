"""Input-residual cross-correlation with bounds valid for coloured signals (prewhitening).

The usual bound ``+-1.96/sqrt(N)`` on the normalized cross-correlation holds
only if at least one of the two signals is white; a step train or a
low-passed input is far from white, and with it the naive bound raises false
alarms at most lags. So the input is prewhitened: an AR model ``A(q)`` is
fitted to the (mean-removed) input (Yule-Walker equations solved by the
Levinson-Durbin recursion), its order chosen by
Akaike's criterion up to ``max_order``; the input and the residual are both
filtered by ``A(q)``. The filtered input is white, the filtered residual is
still independent of it when the model is right, and a linear filter applied
to both keeps every linear input-to-residual relation, so
``r(tau) = sum_k a_k b_{k+tau} / sqrt(sum a^2 sum b^2)`` has standard deviation
``1/sqrt(N)`` under a correct model (Box and Jenkins' prewhitening). Lags
``tau >= 0`` (residual after input) point to unmodelled dynamics; lags
``tau < 0`` to feedback in the data.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.distributions import norm_ppf
from synth.errors import DataError

__all__ = ["CrossCorrelation", "fit_ar", "prewhitened_xcorr"]


def fit_ar(x: np.ndarray, max_order: int = 20) -> np.ndarray:
    """Whitening filter ``[1, a_1, ..., a_p]`` of ``x`` (Yule-Walker by Levinson-Durbin, order by AIC).

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> x = lfilter([1.0], [1.0, -0.8], np.random.default_rng(0).normal(size=20000))
    >>> a = fit_ar(x, 5)
    >>> a.size, round(float(a[1]), 1)
    (2, -0.8)
    """
    x = np.asarray(x, float) - np.mean(x)
    n = x.size
    if n < 20:
        raise DataError(f"need at least 20 samples to fit a whitening filter, got {n}", where="input")
    p_max = int(min(max_order, max(1, n // 10)))
    spec = np.fft.rfft(x, 2 * n)
    r = np.fft.irfft(np.abs(spec) ** 2)[: p_max + 1] / n
    if r[0] <= 0.0:
        return np.array([1.0])
    a = np.array([1.0])
    err = float(r[0])
    best = (n * np.log(err), a)
    for p in range(1, p_max + 1):
        k = -float(np.dot(a, r[p:0:-1])) / err
        a = np.r_[a, 0.0] + k * np.r_[a, 0.0][::-1]
        err *= 1.0 - k * k
        if err <= 1e-15 * r[0]:
            return a
        aic = n * np.log(err) + 2 * p
        if aic < best[0]:
            best = (aic, a)
    return best[1]


@dataclass(frozen=True)
class CrossCorrelation:
    """Prewhitened input-residual cross-correlation.

    Attributes
    ----------
    lags : numpy.ndarray
        Lags in samples (``r[i]`` correlates ``u_k`` with ``e_{k+lags[i]}``).
    r : numpy.ndarray
        Normalized cross-correlation.
    bound : float
        Two-sided bound ``z_{1-alpha/2}/sqrt(N)``.
    dt : float
        Sample interval [s].
    whitening : numpy.ndarray
        The filter ``A(q)`` coefficients.

    Examples
    --------
    >>> import numpy as np
    >>> c = CrossCorrelation(np.arange(-2, 3), np.array([0.0, 0.01, 0.5, 0.0, 0.0]), 0.1, 0.01, np.ones(1), 0.05)
    >>> c.significant_lags.tolist(), c.false_alarm_fraction
    ([0], 0.2)
    """

    lags: np.ndarray
    r: np.ndarray
    bound: float
    dt: float
    whitening: np.ndarray = field(repr=False)
    alpha: float = 0.05

    @property
    def exceed(self) -> np.ndarray:
        """Lags where ``|r|`` exceeds the bound (boolean mask)."""
        return np.abs(self.r) > self.bound

    @property
    def significant_lags(self) -> np.ndarray:
        """Lags [samples] where the bound is exceeded."""
        return self.lags[self.exceed]

    @property
    def false_alarm_fraction(self) -> float:
        """Fraction of lags outside the bound (about ``alpha`` under a correct model)."""
        return float(np.mean(self.exceed))

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        causal = self.exceed & (self.lags >= 0)
        return {"bound": self.bound, "alpha": self.alpha, "max_lag": int(self.lags.max()),
                "whitening_order": int(self.whitening.size - 1),
                "significant_lags_s": [float(k * self.dt) for k in self.significant_lags],
                "fraction_outside": self.false_alarm_fraction,
                "peak_lag_s": float(self.lags[np.argmax(np.abs(self.r))] * self.dt),
                "peak": float(self.r[np.argmax(np.abs(self.r))]),
                "causal_significant": bool(np.any(causal)),
                "method": "AR (Yule-Walker) prewhitening of the input, order by AIC; both signals filtered"}


def prewhitened_xcorr(u: np.ndarray, e: np.ndarray, dt: float, max_lag: int = 50, max_order: int = 20,
                      alpha: float = 0.05, prewhiten: bool = True) -> CrossCorrelation:
    """Cross-correlation of input and residual with a bound valid for coloured signals.

    Parameters
    ----------
    u, e : numpy.ndarray
        Input and residual.
    dt : float
        Sample interval [s].
    max_lag : int
        Largest lag [samples], both signs.
    max_order : int
        Largest order of the whitening AR model.
    alpha : float
        Level of the two-sided bound.
    prewhiten : bool
        ``False`` computes the naive correlation (for comparison only: its bound is wrong for coloured signals).

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(3)
    >>> u = rng.normal(size=4000)
    >>> e = 0.5 * np.r_[0.0, 0.0, u[:-2]] + rng.normal(size=4000)
    >>> c = prewhitened_xcorr(u, e, 0.01, max_lag=10)
    >>> int(c.lags[np.argmax(np.abs(c.r))]), bool(c.exceed[c.lags == 2][0])
    (2, True)
    """
    u = np.asarray(u, float)
    e = np.asarray(e, float)
    if u.shape != e.shape:
        raise DataError("input and residual must have the same length", where="residual")
    if not 0.0 < alpha < 1.0:
        raise DataError(f"must be in (0, 1), got {alpha!r}", where="alpha")
    a = fit_ar(u, max_order) if prewhiten else np.array([1.0])
    p = a.size - 1
    fu = np.convolve(u - u.mean(), a)[p:u.size]  # the whitening filter (FIR), from the p-th sample on
    fe = np.convolve(e - e.mean(), a)[p:e.size]
    n = fu.size
    max_lag = int(min(max_lag, n // 4))
    if max_lag < 1:
        raise DataError(f"record too short for a cross-correlation ({u.size} samples)", where="residual")
    scale = np.sqrt(np.sum(fu**2) * np.sum(fe**2))
    if scale == 0.0:
        raise DataError("the input or the residual is constant; no correlation to test", where="residual")
    lags = np.arange(-max_lag, max_lag + 1)
    r = np.empty(lags.size)
    for i, tau in enumerate(lags):
        r[i] = np.dot(fu[: n - tau], fe[tau:]) if tau >= 0 else np.dot(fu[-tau:], fe[: n + tau])
    bound = float(norm_ppf(1.0 - alpha / 2.0) / np.sqrt(n))
    return CrossCorrelation(lags, r / scale, bound, float(dt), a, alpha)
