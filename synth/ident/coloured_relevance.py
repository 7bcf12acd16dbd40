"""Does the output respond to the input at all, beyond its own drift? Cross-correlation of prewhitened signals.

The plain F-test of a fit (:func:`synth.ident.fit_failure.fit_failure`) takes the residuals for white noise. An
output that wanders on its own (a random walk, a drifting sensor) is matched in part by any slow model of a busy
input, and that share passes the test: a black-box test's random walk, unrelated to its PRBS input, was identified
as ``0.244/(s + 0.211)`` with a 0.39 s delay, every parameter a few percent certain, exit 0 (eight seeds of eight).
Here the input and the output are each filtered by the inverse of their own autoregressive model (order
:data:`WHITENING_ORDER`, least squares), which leaves two nearly white series; when the output does not respond to
the input they are independent and every lag of their cross-correlation is about normal with variance ``1/N``
(Haugh's test), whatever the output's drift; a response shows as a large correlation at the lags of the plant's
delay and fastest motion. The test looks at lags 0 to a tenth of the record and corrects for their number
(Bonferroni). It asks only whether the output moves with the input, not whether a structure fits. It loses power
where whitening the output leaves little of a slow response among its noise (a first-order step train at 10 %
noise: p = 0.004); so a fit fails for it only when the fit's own F-test, made on residuals whitened by their
autoregressive model (:func:`whitened_f_test`), finds no response either (:func:`no_response_p_value`): that one
keeps its power for the right structure, whose residuals are white, and loses it only where a wrong structure
leaves smooth residuals, where the first test finds the response.
"""

from __future__ import annotations

import math

import numpy as np

from synth.distributions import f_sf

__all__ = ["WHITENING_ORDER", "no_response_p_value", "response_p_value", "whitened_f_test"]

WHITENING_ORDER = 10
"""Order of each signal's autoregressive model."""


def _inverse_ar(x: np.ndarray, order: int) -> np.ndarray:
    """The whitening filter ``1 - a_1 q^-1 - ... - a_p q^-p`` of ``x``'s autoregressive model (least squares)."""
    n = x.size
    lags = np.column_stack([x[order - k - 1:n - k - 1] for k in range(order)])
    return np.r_[1.0, -np.linalg.lstsq(lags, x[order:], rcond=None)[0]]


def _filtered(inverse: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``x`` through the FIR filter ``inverse`` (zero initial state; numpy alone: the design report loads no
    scipy.signal)."""
    return np.convolve(x, inverse)[:x.size]


def _whitened(x: np.ndarray, order: int) -> np.ndarray:
    x = np.asarray(x, float) - np.mean(x)
    e = _filtered(_inverse_ar(x, order), x)[order:]
    return e - e.mean()


def response_p_value(u: np.ndarray, y: np.ndarray, order: int = WHITENING_ORDER) -> float:
    """p-value that the output moves with the input: the largest cross-correlation of the prewhitened signals at
    lags 0 to ``N/10``, Bonferroni-corrected (1: no sign of a response; 0 when the record is too short or the input
    does not move, where the test cannot be made).

    Parameters
    ----------
    u, y : numpy.ndarray
        Input and output samples.
    order : int
        Order of each signal's autoregressive model.

    Returns
    -------
    float

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> u = np.repeat(rng.choice([0.0, 1.0], 150), 20)
    >>> walk = np.cumsum(0.01 * rng.normal(size=u.size))                # an output that ignores the input
    >>> response_p_value(u, walk) > 1e-3
    True
    >>> y = np.convolve(u, np.exp(-np.arange(50) / 10) / 10)[:u.size]
    >>> response_p_value(u, y + walk) < 1e-9                             # a response under the same drift
    True
    """
    u, y = np.asarray(u, float), np.asarray(y, float)
    n = u.size
    if n <= 4 * order + 8 or not np.ptp(u) > 0:
        return 0.0
    eu, ey = _whitened(u, order), _whitened(y, order)
    norm = float(np.sqrt((eu @ eu) * (ey @ ey)))
    if not norm > 0:
        return 0.0
    m = eu.size
    max_lag = max(1, m // 10)
    size = 1 << int(np.ceil(np.log2(2 * m)))
    ccf = np.fft.irfft(np.conj(np.fft.rfft(eu, size)) * np.fft.rfft(ey, size), size)[:max_lag + 1] / norm
    z = float(np.max(np.abs(ccf))) * np.sqrt(m)
    return float(min(1.0, (max_lag + 1) * math.erfc(z / math.sqrt(2.0))))


def whitened_f_test(y: np.ndarray, residuals: np.ndarray, free: int, order: int = WHITENING_ORDER) -> float:
    """p-value of the F-test of the fitted model against the output's mean, both whitened by the residuals'
    autoregressive model (1 when the model does no better; 0 when too few samples leave nothing to test, or the
    residuals are not finite: a fit whose model output is NaN is a failure for :func:`fit_failure`'s reasons).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> y = np.repeat(rng.choice([0.0, 1.0], 150), 20) + 0.01 * rng.normal(size=3000)
    >>> whitened_f_test(y, 0.01 * rng.normal(size=3000), 3) < 1e-9             # white residuals: the plain test
    True
    """
    r = np.asarray(residuals, float)
    n = r.size
    if n <= 4 * order + free + 2 or not np.all(np.isfinite(r)):  # a model whose output is not finite failed anyway
        return 0.0
    r = r - r.mean()
    inverse = _inverse_ar(r, order)
    e1 = _filtered(inverse, r)[order:]
    e0 = _filtered(inverse, np.asarray(y, float) - np.mean(y))[order:]
    ssr1, ssr0 = float(e1 @ e1), float(e0 @ e0)
    if not ssr0 > ssr1:
        return 1.0
    dof = max(e1.size - free - order, 1)
    return float(f_sf(((ssr0 - ssr1) / max(free - 1, 1)) / (max(ssr1, 1e-300) / dof), max(free - 1, 1), dof))


def no_response_p_value(u: np.ndarray, y: np.ndarray, y_fit: np.ndarray, residuals: np.ndarray, free: int,
                        significance: float = 1e-3) -> float:
    """The smaller p-value of :func:`response_p_value` (on the whole input ``u`` and output ``y``) and
    :func:`whitened_f_test` (on the fitted samples ``y_fit`` and their ``residuals``): large only when neither finds a
    response to the input. Where the F-test alone is at most ``significance`` (a response found), its p-value is
    returned and the cross-correlation is not computed: the smaller one is at most that too.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> u = np.repeat(rng.choice([0.0, 1.0], 150), 20)
    >>> walk = np.cumsum(0.01 * rng.normal(size=u.size))
    >>> fake = walk - 0.2 * np.convolve(u, np.full(400, 1 / 400))[:u.size]       # a spurious model's residuals
    >>> no_response_p_value(u, walk, walk, fake, 3) > 1e-3
    True
    """
    p = whitened_f_test(y_fit, residuals, free)
    return p if p <= significance else min(p, response_p_value(u, y))
