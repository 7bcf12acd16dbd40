"""Coherence of a frequency-response estimate: its value, the random error it implies, the coherent band.

*Coherence.* ``gamma^2 = |Gxy|^2 / (Gxx Gyy)`` from the one-sided spectra.

*Random error.* Normalized random error of ``|H|`` (and, in radians, of its phase):
``eps = sqrt(1 - gamma^2) / (|gamma| sqrt(2 n_d))``.

*Coherent band.* Where ``gamma^2 >= threshold`` (0.8, the seed's criterion) and the
coherence does not oscillate: within +/- ``span`` decades of a point, the total
variation of ``gamma^2`` minus its net change (the back-and-forth part) must stay
below ``roughness`` (default 0.15). The band is the widest contiguous run of such
points.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.errors import DataError

__all__ = ["COHERENCE_THRESHOLD", "CoherentBand", "coherence_from_spectra", "coherent_band", "random_error"]

#: the seed's coherence criterion
COHERENCE_THRESHOLD = 0.8


@dataclass(frozen=True)
class CoherentBand:
    """The frequency range where the coherence is high and does not oscillate.

    Attributes
    ----------
    w_min, w_max : float
        Edges [rad/s] (``nan`` if no grid point qualifies).
    threshold : float
        Coherence threshold ``gamma^2``.
    roughness : float
        Largest back-and-forth coherence variation allowed within +/- ``span`` decades.
    span : float
        Half width of the oscillation test neighbourhood [decades].
    mask : numpy.ndarray
        Grid points that pass both tests (the band may be a sub-range of them).

    Examples
    --------
    >>> w = np.geomspace(0.1, 100, 61)
    >>> b = coherent_band(w, np.where((w > 1) & (w < 20), 0.95, 0.3))
    >>> round(b.w_min, 3), round(b.w_max, 3), b.width_decades > 1
    (1.122, 19.953, True)
    """

    w_min: float
    w_max: float
    threshold: float
    roughness: float
    span: float
    mask: np.ndarray = field(repr=False)

    @property
    def found(self) -> bool:
        """Whether any grid point is coherent."""
        return bool(np.isfinite(self.w_min))

    @property
    def width_decades(self) -> float:
        """Width of the band in decades (0 if none)."""
        return float(np.log10(self.w_max / self.w_min)) if self.found else 0.0

    def contains(self, w: Any) -> np.ndarray:
        """Which of ``w`` lie inside the band."""
        w = np.asarray(w, float)
        return (w >= self.w_min) & (w <= self.w_max) if self.found else np.zeros(w.shape, bool)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {"w_min": self.w_min if self.found else None, "w_max": self.w_max if self.found else None,
                "threshold": self.threshold, "roughness": self.roughness, "span_decades": self.span}


def _oscillation(coherence: np.ndarray, logw: np.ndarray, span: float) -> np.ndarray:
    """Back-and-forth variation of ``coherence`` within +/- ``span`` decades of each point."""
    steps = np.abs(np.diff(coherence))
    cum = np.r_[0.0, np.cumsum(steps)]
    lo = np.searchsorted(logw, logw - span, side="left")
    hi = np.searchsorted(logw, logw + span, side="right") - 1
    total = cum[hi] - cum[lo]
    net = np.abs(coherence[hi] - coherence[lo])
    return total - net


def coherent_band(w: Any, coherence: Any, threshold: float = COHERENCE_THRESHOLD, roughness: float = 0.15,
                  span: float = 0.1) -> CoherentBand:
    """The widest contiguous frequency range with ``gamma^2 >= threshold`` and no oscillation.

    Parameters
    ----------
    w : array_like
        Increasing frequencies [rad/s].
    coherence : array_like
        ``gamma^2`` at ``w``.
    threshold : float
        Coherence threshold (the seed: 0.8).
    roughness : float
        A point oscillates when, within +/- ``span`` decades, the total variation
        of ``gamma^2`` exceeds its net change by more than ``roughness``.
    span : float
        Half width of that neighbourhood [decades].

    Returns
    -------
    CoherentBand

    Examples
    --------
    >>> w = np.geomspace(1, 100, 81)
    >>> g = np.where(w < 30, 0.97, 0.97 - 0.15 * (np.arange(81) % 2))  # oscillates above 30 rad/s
    >>> round(coherent_band(w, g).w_max, 1) < 30
    True
    """
    w = np.asarray(w, float)
    g = np.asarray(coherence, float)
    if w.shape != g.shape or w.ndim != 1 or w.size < 2:
        raise DataError("coherent_band: w and coherence must be 1-D arrays of the same length")
    if not 0 < threshold < 1:
        raise DataError(f"coherence threshold must be between 0 and 1, got {threshold:g}")
    finite = np.isfinite(g)
    gg = np.where(finite, g, 0.0)
    ok = finite & (gg >= threshold) & (_oscillation(gg, np.log10(w), span) <= roughness)
    best, start, run = (0, 0), None, []
    for i, flag in enumerate(np.r_[ok, False]):
        if flag and start is None:
            start = i
        elif not flag and start is not None:
            run.append((start, i))
            start = None
    if run:
        best = max(run, key=lambda ab: (np.log10(w[ab[1] - 1] / w[ab[0]]), ab[1] - ab[0]))
        return CoherentBand(float(w[best[0]]), float(w[best[1] - 1]), threshold, roughness, span, ok)
    return CoherentBand(float("nan"), float("nan"), threshold, roughness, span, ok)


def coherence_from_spectra(gxx: np.ndarray, gyy: np.ndarray, gxy: np.ndarray) -> np.ndarray:
    """``gamma^2 = |Gxy|^2 / (Gxx Gyy)``, clipped to [0, 1] (0/0 gives nan).

    Examples
    --------
    >>> coherence_from_spectra(np.array([1.0, 2.0]), np.array([4.0, 2.0]), np.array([1.0, 2.0 + 0j])).tolist()
    [0.25, 1.0]
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.clip(np.abs(gxy) ** 2 / (gxx * gyy), 0.0, 1.0)


def random_error(coherence: Any, n_averages: Any) -> np.ndarray:
    """Normalized random error of ``|H|``: ``sqrt(1 - gamma^2) / (|gamma| sqrt(2 n_d))``.

    Examples
    --------
    >>> round(float(random_error(0.8, 10)), 4)
    0.1118
    """
    g2 = np.clip(np.asarray(coherence, float), 0.0, 1.0)
    with np.errstate(divide="ignore"):
        return np.sqrt(1.0 - g2) / (np.sqrt(g2) * np.sqrt(2.0 * np.asarray(n_averages, float)))
