"""Where in frequency the residual lies: bands where the model-error model is significant.

A band is a run of neighbouring grid frequencies where the error model's
confidence region excludes zero (see :mod:`synth.gap.where.error_model`) and,
when the model is given, the error is also relevant: ``|E| >= relevance |G|``
(default 10 % of the model's own response; with little noise a 0.2 % error
is significant too, but it is not where the gap is); runs
separated by a gap narrower than a factor ``merge_ratio`` in frequency are
merged. Each band is reported as ``[w0, w1, share]`` [rad/s] with ``share``
the fraction of the residual's power (Welch PSD, same segments as the
coherence, integrated over ``w``) that lies inside the band, and, in the
details, the fraction of the residual power the error model itself
explains there (``|E|^2`` times the input PSD, relative to the residual power).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.gap.where.coherence import Coherence, input_residual_coherence
from synth.gap.where.error_model import ErrorModel, fit_error_model
from synth.gap.where.residual import ModelResidual
from synth.gap.where.xcorr import CrossCorrelation, prewhitened_xcorr
from synth.ident.welch import welch_density
from synth.plant import Plant

__all__ = ["FrequencyBand", "FrequencyLocalization", "localize_frequency", "significant_bands"]


@dataclass(frozen=True)
class FrequencyBand:
    """A band where the model error is significant.

    Examples
    --------
    >>> FrequencyBand(20.0, 80.0, 0.6, 0.4).to_list()
    [20.0, 80.0, 0.6]
    """

    w0: float
    w1: float
    share: float
    explained: float

    def to_list(self) -> list[float]:
        """``[w0, w1, share]`` as in the JSON contract."""
        return [self.w0, self.w1, self.share]


def _power_share(w: np.ndarray, psd: np.ndarray, w0: float, w1: float) -> float:
    cum = np.r_[0.0, np.cumsum(np.diff(w) * (psd[1:] + psd[:-1]) / 2.0)]  # scipy's cumulative_trapezoid, not imported
    if cum[-1] <= 0:
        return 0.0
    return float((np.interp(w1, w, cum) - np.interp(w0, w, cum)) / cum[-1])


def significant_bands(model: ErrorModel, w_psd: np.ndarray, e_psd: np.ndarray, u_psd: np.ndarray,
                      merge_ratio: float = 1.1, relevant: np.ndarray | None = None) -> list[FrequencyBand]:
    """Bands of the error model's significant frequencies with their power shares, largest share first.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> u = rng.normal(size=4000)
    >>> m = fit_error_model(u, 0.3 * u + rng.normal(size=4000), 0.01, na=0, nb=2)
    >>> w = np.linspace(0, np.pi / 0.01, 50)
    >>> b = significant_bands(m, w, np.ones(50), np.ones(50))
    >>> len(b), round(b[0].w1 / b[0].w0) > 100
    (1, True)
    """
    sig = model.significant if relevant is None else model.significant & relevant
    w = model.w
    runs: list[list[int]] = []
    for i in np.flatnonzero(sig):
        if runs and (i == runs[-1][1] + 1 or w[i] <= w[runs[-1][1]] * merge_ratio):
            runs[-1][1] = int(i)
        else:
            runs.append([int(i), int(i)])
    total = float(np.trapezoid(e_psd, w_psd)) if w_psd.size > 1 else 0.0
    explained_psd = np.interp(w_psd, w, np.abs(model.response) ** 2) * u_psd
    bands = []
    for i0, i1 in runs:
        w0, w1 = float(w[i0]), float(w[i1])
        share = _power_share(w_psd, e_psd, w0, w1)
        inside = (w_psd >= w0) & (w_psd <= w1)
        expl = float(np.trapezoid(explained_psd[inside], w_psd[inside]) / total) if total > 0 and inside.sum() > 1 else 0.0
        bands.append(FrequencyBand(w0, w1, share, expl))
    bands.sort(key=lambda b: -b.share)
    return bands


@dataclass(frozen=True)
class FrequencyLocalization:
    """The frequency part of the diagnosis.

    Attributes
    ----------
    bands : list of FrequencyBand
    xcorr : CrossCorrelation
    coherence : Coherence
    error_model : ErrorModel
    w_psd, e_psd : numpy.ndarray
        Residual power spectral density (one-sided, per rad/s) on its grid [rad/s].

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.where.residual import model_residual
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 40, 0.01)
    >>> rng = np.random.default_rng(0)
    >>> u = rng.normal(size=t.size)
    >>> y = simulate_plant(Plant.from_string("1/(0.05*s+1)", delay=0.03), t, u) + 0.05 * rng.normal(size=t.size)
    >>> f = localize_frequency(model_residual(Plant.from_string("1/(0.05*s+1)"), record_from_arrays(t, u, y)))
    >>> f.error_model.significant_overall, f.bands[0].w0 < 20 < f.bands[0].w1
    (True, True)
    """

    bands: list[FrequencyBand]
    xcorr: CrossCorrelation
    coherence: Coherence
    error_model: ErrorModel
    w_psd: np.ndarray
    e_psd: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        return {"frequency_bands": [b.to_list() for b in self.bands],
                "bands": [{"w0": b.w0, "w1": b.w1, "share": b.share, "explained": b.explained} for b in self.bands],
                "cross_correlation": self.xcorr.to_dict(), "coherence": self.coherence.to_dict(),
                "error_model": self.error_model.to_dict()}


def localize_frequency(residual: ModelResidual, max_lag: int = 50, n_segments: int = 16, na: int = 4, nb: int = 10,
                       level: float = 0.95, plant: Plant | None = None, relevance: float = 0.1) -> FrequencyLocalization:
    """Cross-correlation, coherence, error model and significant bands of a model's residual.

    Parameters
    ----------
    residual : ModelResidual
    max_lag : int
        Largest cross-correlation lag [samples].
    n_segments : int
        Welch segments for the coherence and the PSDs (fewer on a record too short for them to hold 8 samples each).
    na, nb : int
        Error-model orders.
    level : float
        Confidence level of every test (``alpha = 1 - level``).
    plant : Plant, optional
        The model; with it, bands also need ``|E| >= relevance |G|``.
    relevance : float
        Smallest relative error a band must show.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.where.residual import model_residual
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 20, 0.01)
    >>> rng = np.random.default_rng(0)
    >>> u = rng.normal(size=t.size)
    >>> G = Plant.from_string("1/(0.05*s+1)")
    >>> from synth.ident.simulate import simulate_plant
    >>> rec = record_from_arrays(t, u, simulate_plant(G, t, u) + 0.1 * rng.normal(size=t.size))
    >>> localize_frequency(model_residual(G, rec)).bands
    []
    """
    u, e, dt = residual.u, residual.e, residual.dt
    alpha = 1.0 - level
    xc = prewhitened_xcorr(u, e, dt, max_lag=max_lag, alpha=alpha)
    n_segments = max(2, min(n_segments, u.size // 8))  # a short record: fewer segments of 8 samples, not a refusal
    coh = input_residual_coherence(u, e, dt, n_segments=n_segments, alpha=alpha)
    model = fit_error_model(u, e, dt, na=na, nb=nb, level=level)
    nper = max(8, u.size // n_segments)
    f, pe = welch_density(e - e.mean(), dt, nper, nper - nper // 2)
    _, pu = welch_density(u - u.mean(), dt, nper, nper - nper // 2)
    w = 2.0 * np.pi * f
    pe, pu = pe / (2.0 * np.pi), pu / (2.0 * np.pi)
    relevant = None
    if plant is not None:
        relevant = np.abs(model.response) >= relevance * np.abs(plant.freqresp(model.w))
    bands = significant_bands(model, w, pe, pu, relevant=relevant)
    return FrequencyLocalization(bands, xc, coh, model, w, pe)
