"""Are a fit's residuals white? The std column of a fit assumes they are.

``cov = s^2 (J^T J)^-1`` is the covariance of the estimates when the residuals are white. With coloured noise,
drift or a model error they are correlated and the stds can be several times too small (an AR(1) noise with
coefficient 0.95 on a first-order step train: the estimates scatter 5.6-9.3 times more than their reported std). The
Ljung-Box statistic over the first lags tests whiteness; a note is given when the correlation is both
significant and large enough to matter. An output interpolated from uneven time stamps is correlated by the
interpolation itself (about 0.25 at lag 1 for jittered stamps; :attr:`synth.data.Record.noise_correlation`), which
the std column already allows for (:attr:`synth.data.Record.noise_factor`): the test is on the correlation beyond it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from synth.distributions import chi2_sf

__all__ = ["correlated_residuals_note"]

#: significance below which the residuals are called correlated
P_VALUE = 1e-6
#: and the largest autocorrelation over the tested lags at least this
MIN_CORRELATION = 0.2


def correlated_residuals_note(residuals: np.ndarray, lags: int = 20, expected: Sequence[float] = ()) -> str:
    """A note when the residuals are correlated, else ``""``.

    Parameters
    ----------
    residuals : numpy.ndarray
        The residuals of the fit, in time order.
    lags : int
        Autocorrelation lags tested (at most a fifth of the samples).
    expected : sequence of float
        The autocorrelation at lags 1, 2, ... that white noise has in these residuals (the record's
        interpolation); what is tested is the excess over it. Default: none (white).

    Returns
    -------
    str
        The largest autocorrelation, its lag, the Ljung-Box p-value and what it means for the std column;
        ``""`` when the residuals are white within the test (or fewer than 50 samples).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> correlated_residuals_note(rng.normal(size=2000))
    ''
    >>> drift = np.cumsum(rng.normal(size=2000)) * 0.1 + rng.normal(size=2000)
    >>> correlated_residuals_note(drift)[:50]
    'the residuals are correlated (autocorrelation 0.69'
    >>> n = rng.normal(size=2001)
    >>> midpoints = 0.5 * (n[1:] + n[:-1])  # white noise interpolated half-way: 0.5 at lag 1
    >>> correlated_residuals_note(midpoints)[:50]
    'the residuals are correlated (autocorrelation 0.52'
    >>> correlated_residuals_note(midpoints, expected=[0.5])
    ''
    """
    e = np.asarray(residuals, float)
    e = e[np.isfinite(e)]
    n = e.size
    m = min(int(lags), n // 5)
    if n < 50 or m < 1:
        return ""
    e = e - np.mean(e)
    energy = float(e @ e)
    if energy <= 0.0:
        return ""
    rho = np.array([float(e[k:] @ e[:-k]) / energy for k in range(1, m + 1)])
    known = np.zeros(m)
    known[:min(m, len(expected))] = np.asarray(expected, float)[:m]
    rho = rho - known  # what the interpolation of white noise does not explain
    q = n * (n + 2) * float(np.sum(rho**2 / (n - np.arange(1, m + 1))))
    p = float(chi2_sf(q, m))
    worst = int(np.argmax(np.abs(rho)))
    if p >= P_VALUE or abs(rho[worst]) < MIN_CORRELATION:
        return ""
    shown = f"= {p:.1g}" if p > 1e-300 else "< 1e-300"
    share = f", {known[worst]:.2f} of it from the resampling of uneven stamps" if known[worst] else ""
    return (f"the residuals are correlated (autocorrelation {rho[worst] + known[worst]:.2f} at lag {worst + 1} "
            f"sample{'s' if worst else ''}{share}; Ljung-Box p {shown} over {m} lags): coloured noise, drift or a model "
            f"error; the stds assume white residuals and may be several times too small (the split check, "
            f"synth.ident.split_check or --split-check 5, measures the real scatter)")
