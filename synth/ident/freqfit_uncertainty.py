"""Standard errors of a frequency-response fit's parameters, and which of them the band cannot pin down.

The fit (:func:`synth.ident.freqfit.fit_frequency_response`) minimizes a weighted sum of squared log-magnitude
and phase errors, ``sum W_k r_k^2``, over the grid points of its range. Each point's error has the random
error ``eps_k`` of the spectral estimate as its standard deviation, in natural-log magnitude and in radians
alike (:func:`synth.ident.coherence.random_error`). The weights are not ``1 / eps_k^2`` (the NASA cost weights
by coherence), so the covariance is the sandwich of the linearized fit:

    C = A^-1 B A^-1,   A = J' W J,   B = J' W S W J,   S = diag(kappa eps_k^2),

``J`` the derivative of the residuals ``ln(G_model / H)`` (real: magnitude, imaginary: phase) by the
parameters (central differences of ``ln G``).

The grid points are not independent: the log grid is denser than a long window's frequency resolution, and
a point's spectral estimate shares the data of its neighbours (lag-1 correlations of 0.4-0.99 across noise
seeds on a 40-per-decade grid). The factor ``kappa = (1 + rho) / (1 - rho)`` is the variance of a sum of
first-order-autocorrelated errors over that of independent ones, with ``rho`` the lag-1 autocorrelation of the
fit's own residuals ``r_k`` (log magnitude and phase) along the grid (capped at :data:`MAX_RESIDUAL_CORRELATION`).
Where the structure misses the response, the residuals are smooth, ``rho`` is near 1, and the standard errors
grow: the report then says so (a misfit is not noise). On 40 noise seeds of a swept ``10 (s+2)/((s+1)(s+20))``
with output noise, the reported standard errors were 0.99-1.16 times the parameters' scatter over 0.5-20 rad/s
(0.60-0.70 without ``kappa``) and 0.70-0.76 over a 0.2-decade band (``tests/test_freqfit_uncertainty.py``).

What they leave out: the spectral estimate's own bias (window leakage and the sweep's rate near corners and
resonances), which does not shrink with the noise. Its smooth residuals raise ``rho`` too, so ``kappa`` widens the
errors for part of it. On 30 random plants and sweeps (``benchmarks/freqfit_uncertainty.py``) the reported errors
were a median 1.6 times the scatter over noise seeds (0.91 without ``kappa``) and the 95 % intervals held the truth
in 79 % of the fits (54 % without ``kappa``): read them as the noise's share, not a bound on the error.

A parameter whose standard error is a large share of its value, or that is tied to another one, is weakly
identifiable (:func:`synth.ident.identifiability.weak_parameters`): reported with its interval and its
correlation partner, not as a confident number.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.ident.identifiability import WeakParameter, weak_parameters

__all__ = ["MAX_RESIDUAL_CORRELATION", "MISFIT_CORRELATION", "FreqFitUncertainty", "fit_uncertainty"]

MAX_RESIDUAL_CORRELATION = 0.95
"""Cap on the residuals' lag-1 correlation ``rho`` (``kappa`` at most 39)."""

MISFIT_CORRELATION = 0.9
"""A lag-1 correlation of the residuals above this says the structure misses the response (a
smooth error along the band, not the spectral estimate's scatter)."""

_LN_TO_DB = 20.0 / np.log(10.0)
_RAD_TO_DEG = 180.0 / np.pi


@dataclass(frozen=True)
class FreqFitUncertainty:
    """Standard errors of a frequency-response fit (module text).

    Attributes
    ----------
    names : tuple of str
        The fitted parameters (the delay last when it was fitted).
    std : dict
        1-sigma standard error by name (the delay in s).
    intervals : dict
        95 % intervals (``value +- 1.96 std``) by name.
    correlation : numpy.ndarray
        Correlation matrix of the parameters (rows and columns in ``names`` order).
    residual_correlation : float
        ``rho``: lag-1 autocorrelation of the residuals along the grid.
    inflation : float
        ``kappa = (1 + rho) / (1 - rho)``, the variance factor for neighbouring points' shared data.
    points : int
        Grid points the fit used.
    weak : tuple of WeakParameter
        The parameters the band cannot pin down.
    at_bound : tuple of str
        Parameters the fit ended at a bound of (a delay of 0 s): held there for the others' standard
        errors, without one of their own.

    Examples
    --------
    >>> from synth.plant import Plant
    >>> from synth.ident.freqfit import _Orders
    >>> w = np.geomspace(0.5, 20, 60); G = Plant.from_string("4/(s+2)")
    >>> H = G.freqresp(w) * np.exp(0.02 * np.random.default_rng(0).normal(size=60))
    >>> u = fit_uncertainty(_Orders(0, 1), np.array([4.0, 2.0]), 0.0, False, w, H, np.ones(60), np.full(60, 0.02))
    >>> sorted(u.std), u.weak
    (['a0', 'b0'], ())
    """

    names: tuple[str, ...]
    std: dict[str, float]
    intervals: dict[str, tuple[float, float]]
    correlation: np.ndarray
    residual_correlation: float
    inflation: float
    points: int
    weak: tuple[WeakParameter, ...]
    at_bound: tuple[str, ...] = ()

    @property
    def misfit(self) -> bool:
        """Whether the residuals are smooth along the band (:data:`MISFIT_CORRELATION`)."""
        return self.residual_correlation > MISFIT_CORRELATION

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields.

        Examples
        --------
        >>> u = FreqFitUncertainty(("k",), {"k": 0.1}, {"k": (0.8, 1.2)}, np.eye(1), 0.5, 3.0, 40, ())
        >>> u.to_dict()["std"], u.to_dict()["inflation"]
        ({'k': 0.1}, 3.0)
        """
        return {"std": dict(self.std), "intervals": {k: list(v) for k, v in self.intervals.items()},
                "correlation": {"names": list(self.names), "matrix": np.round(self.correlation, 6).tolist()},
                "residual_correlation": self.residual_correlation, "inflation": self.inflation,
                "points": self.points, "weak": [p.to_dict() for p in self.weak], "at_bound": list(self.at_bound),
                "basis": "linearized sandwich covariance of the weighted fit; each point's error the spectral "
                         "random error from its coherence and averages, its variance times "
                         "(1 + rho) / (1 - rho) for the residuals' lag-1 correlation rho along the grid"}

    def lines(self) -> list[str]:
        """Lines for a report: what the standard errors rest on, a misfit warning, each weak parameter.

        Examples
        --------
        >>> u = FreqFitUncertainty(("k",), {"k": 0.1}, {"k": (0.8, 1.2)}, np.eye(1), 0.95, 39.0, 40, ())
        >>> u.lines()[1][:60]
        'warning: the residuals are smooth along the band (lag-1 corr'
        """
        out = [f"standard errors (1 sigma) from the spectral random error over {self.points} points, variance "
               f"x {self.inflation:.3g} for the residuals' correlation along the band (lag-1 "
               f"{self.residual_correlation:.2f}: neighbouring points share data); the spectral estimate's own bias "
               "(leakage, sweep rate) is not fully in them"]
        out.extend(f"{name} ended at its bound (held there for the others' standard errors; the band gives it "
                   "no interval of its own)" for name in self.at_bound)
        if self.misfit:
            out.append(f"warning: the residuals are smooth along the band (lag-1 correlation "
                       f"{self.residual_correlation:.2f} > {MISFIT_CORRELATION:g}): the structure misses the "
                       "response there; the standard errors are widened for it, but a misfit is not noise "
                       "(try another structure or a shorter --fit-range)")
        out.extend("warning: " + p.text() for p in self.weak)
        return out


def _log_model(structure: Any, theta: np.ndarray, w: np.ndarray, fit_delay: bool, tau: float) -> np.ndarray:
    """``ln G(jw)`` up to multiples of ``2 pi j`` (compared only as ratios of nearby values)."""
    params = theta[:-1] if fit_delay else theta
    delay = float(theta[-1]) if fit_delay else tau
    num, den = structure.coefficients(params)
    s = 1j * w
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return np.log(np.polyval(num, s) / np.polyval(den, s)) - s * delay


ROUNDING_RESIDUAL = 1e-10
"""Residual (relative magnitude in nepers, phase in radians) below which a fit is exact to rounding."""


def _lag1(z: np.ndarray) -> float:
    """Lag-1 autocorrelation of ``z`` about zero (the residuals of a fit, in nepers and radians), 0 when undefined
    or when every residual is below :data:`ROUNDING_RESIDUAL` (an exact fit: the correlation of rounding errors
    varies with the machine's arithmetic, 0.0 on one and 0.113 on another)."""
    z = z[np.isfinite(z)]
    if z.size < 3 or not np.any(np.abs(z) > ROUNDING_RESIDUAL):
        return 0.0
    return float(np.sum(z[:-1] * z[1:]) / np.sum(z * z))


def fit_uncertainty(structure: Any, theta: np.ndarray, tau: float, fit_delay: bool, w: np.ndarray, H: np.ndarray,
                    coherence_weights: np.ndarray, random_error: np.ndarray,
                    weights: tuple[float, float] = (1.0, 0.01745), delay_name: str = "delay") -> FreqFitUncertainty:
    """The standard errors of a frequency-response fit's parameters (module text).

    Parameters
    ----------
    structure : object
        The fitted structure (``parameters`` and ``coefficients(theta)``, as in :mod:`synth.ident.freqfit`).
    theta : numpy.ndarray
        The fitted parameters in ``structure.parameters`` order.
    tau : float
        The fitted or fixed delay [s].
    fit_delay : bool
        Whether the delay was fitted (then it is a parameter, named ``delay_name``).
    w, H, coherence_weights, random_error : numpy.ndarray
        The grid points of the fitted range: frequency [rad/s], measured response, the cost's coherence weight
        ``W_gamma`` (:func:`synth.ident.freqfit.coherence_weight`), normalized random error.
    weights : (float, float)
        The cost's ``W_g`` (per dB^2) and ``W_p`` (per deg^2).
    delay_name : str
        Name of the delay parameter.

    Returns
    -------
    FreqFitUncertainty

    Examples
    --------
    >>> from synth.plant import Plant
    >>> from synth.ident.freqfit import _Orders
    >>> w = np.geomspace(0.5, 20, 60); H = Plant.from_string("4/(s+2)").freqresp(w)
    >>> u = fit_uncertainty(_Orders(0, 1), np.array([4.0, 2.0]), 0.0, False, w, H, np.ones(60), np.full(60, 0.01))
    >>> round(u.std["b0"] / 4.0, 4) < 0.01, u.residual_correlation
    (True, 0.0)
    """
    at_bound = (delay_name,) if fit_delay and tau <= 1e-9 else ()  # IPOPT's delay at its lower bound 0
    fit_delay = fit_delay and not at_bound
    names = tuple(structure.parameters) + ((delay_name,) if fit_delay else ())
    x = np.r_[np.asarray(theta, float), [tau] if fit_delay else []]
    base = _log_model(structure, x, w, fit_delay, tau)
    columns = []
    for i in range(x.size):
        h = 1e-6 * max(abs(x[i]), 1e-6)
        up, down = x.copy(), x.copy()
        up[i] += h
        down[i] -= h
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            d = np.log(np.exp(_log_model(structure, up, w, fit_delay, tau) - _log_model(structure, down, w,
                                                                                        fit_delay, tau))) / (2 * h)
        columns.append(np.r_[d.real, d.imag])
    J = np.column_stack(columns)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        r = np.log(np.exp(base) / H)
    wg = np.asarray(coherence_weights, float)
    W = np.r_[wg * weights[0] * _LN_TO_DB ** 2, wg * weights[1] * _RAD_TO_DEG ** 2]
    eps = np.asarray(random_error, float)
    rho = min(max(0.5 * (_lag1(r.real) + _lag1(r.imag)), 0.0), MAX_RESIDUAL_CORRELATION)
    kappa = (1.0 + rho) / (1.0 - rho)
    S = np.r_[eps, eps] ** 2 * kappa
    S = np.where(W > 0, S, 0.0)  # a point of zero coherence weighs nothing, whatever its error
    A = J.T @ (W[:, None] * J)
    B = J.T @ ((W ** 2 * S)[:, None] * J)
    # the rank and the inverse on the columns scaled to unit curvature: a delay's column (about w) beside a gain's
    # (about 1/b0) put A's diagonal 17 decades apart on the Silverbox record, below numpy's rank tolerance
    diag = np.diag(A)
    scale = 1.0 / np.sqrt(np.where(np.isfinite(diag) & (diag > 0), diag, 1.0))
    As = A * np.outer(scale, scale)
    if np.all(np.isfinite(A)) and np.all(np.isfinite(B)) and np.linalg.matrix_rank(As) == x.size:
        Ai = np.linalg.inv(As) * np.outer(scale, scale)
        cov = Ai @ B @ Ai
    else:  # the band cannot tell some parameters apart at all
        cov = np.full((x.size, x.size), np.inf)
    sd = np.sqrt(np.abs(np.diag(cov)))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = cov / np.outer(sd, sd)
    std = {n: float(s) for n, s in zip(names, sd)}
    intervals = {n: (float(v - 1.96 * s), float(v + 1.96 * s)) for n, v, s in zip(names, x, sd)}
    values = dict(zip(names, map(float, x)))
    dt = float(np.pi / w[-1]) if w.size else 0.0  # a delay is judged against the finest time the band resolves
    weak = weak_parameters(list(names), values, cov, intervals, delay_name if fit_delay else None, dt)
    return FreqFitUncertainty(names, std, intervals, corr, float(rho), float(kappa), int(w.size), tuple(weak),
                              at_bound)
