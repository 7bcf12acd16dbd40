"""Coherence of a frequency-response estimate: its value, the random error it implies, the coherent band.

*Coherence.* ``gamma^2 = |Gxy|^2 / (Gxx Gyy)`` from the one-sided spectra.

*Random error.* Normalized random error of ``|H|`` (and, in radians, of its phase):
``eps = sqrt(1 - gamma^2) / (|gamma| sqrt(2 n_d))``.

*Coherent band.* Where ``gamma^2 >= threshold`` (0.8, the seed's criterion) and the
coherence does not oscillate: within +/- ``span`` decades of a point, inside the contiguous
run of points at or above the threshold that holds it, the total variation of
``min(gamma^2, threshold + ceiling)`` minus its net change (the back-and-forth part) must
stay below ``roughness`` (default 0.15). The band is the widest contiguous run of such points.

Two things the test deliberately ignores. A drop below the threshold ends a run, and is not
counted as an oscillation of the points beside it: a notch next to a mode ends the band at the
notch instead of excluding the mode 0.1 decade around it. And the scatter of a high coherence
(above ``threshold + ceiling`` = 0.9) is the random error of a good estimate, not an
oscillation: its total variation grows with the grid density (at 400 points per decade a
coherence scattering within 0.93-0.99 sums to more than 1 over 0.2 decade), so without the
ceiling a denser grid would find no band at all.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.errors import DataError

__all__ = [
    "COHERENCE_THRESHOLD", "CoherentBand", "back_and_forth", "coherence_from_spectra", "coherent_band", "random_error",
]

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
    ceiling : float
        Variation above ``threshold + ceiling`` is not counted as oscillation.
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
    ceiling: float = 0.1
    note: str = ""

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
        out = {"w_min": self.w_min if self.found else None, "w_max": self.w_max if self.found else None,
               "threshold": self.threshold, "roughness": self.roughness, "span_decades": self.span,
               "ceiling": self.ceiling}
        return out | ({"note": self.note} if self.note else {})


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """``(start, stop)`` of each contiguous run of True in ``flags``."""
    edges = np.flatnonzero(np.diff(np.r_[0, flags.astype(int), 0]))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def back_and_forth(coherence: Any, logw: Any, span: float, runs: list[tuple[int, int]]) -> np.ndarray:
    """Back-and-forth variation of ``coherence`` within +/- ``span`` decades of each point, inside its run.

    Total variation minus net change over the neighbourhood, the neighbourhood cut
    at the edges of the ``(start, stop)`` run that holds the point; ``nan`` outside
    every run.

    Examples
    --------
    >>> g = np.array([0.9, 0.8, 0.9, 0.8, 0.9]); lw = np.log10([1.0, 1.1, 1.2, 1.3, 1.4])
    >>> back_and_forth(g, lw, 0.1, [(0, 5)]).round(2).tolist()
    [0.2, 0.2, 0.4, 0.2, 0.2]
    >>> back_and_forth(g, lw, 0.1, [(0, 2)]).round(2).tolist()[:2]
    [0.0, 0.0]
    """
    g = np.asarray(coherence, float)
    logw = np.asarray(logw, float)
    out = np.full(g.shape, np.nan)
    cum = np.r_[0.0, np.cumsum(np.abs(np.diff(g)))]
    lo_all = np.searchsorted(logw, logw - span, side="left")
    hi_all = np.searchsorted(logw, logw + span, side="right") - 1
    for a, b in runs:
        lo = np.clip(lo_all[a:b], a, b - 1)
        hi = np.clip(hi_all[a:b], a, b - 1)
        out[a:b] = (cum[hi] - cum[lo]) - np.abs(g[hi] - g[lo])
    return out


def coherent_band(w: Any, coherence: Any, threshold: float = COHERENCE_THRESHOLD, roughness: float = 0.15,
                  span: float = 0.1, ceiling: float = 0.1) -> CoherentBand:
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
        A point oscillates when, within +/- ``span`` decades and inside its run of
        points at or above the threshold, the total variation of
        ``min(gamma^2, threshold + ceiling)`` exceeds its net change by more than ``roughness``.
    span : float
        Half width of that neighbourhood [decades].
    ceiling : float
        Scatter above ``threshold + ceiling`` is random error, not oscillation (module text).

    Returns
    -------
    CoherentBand

    Examples
    --------
    >>> w = np.geomspace(1, 100, 81)
    >>> g = np.where(w < 30, 0.97, 0.97 - 0.15 * (np.arange(81) % 2))  # oscillates above 30 rad/s
    >>> round(coherent_band(w, g).w_max, 1) < 30
    True
    >>> notch = np.where(np.abs(w - 40) < 2, 0.3, 0.97)          # a notch ends the band, nothing more
    >>> round(coherent_band(w, notch).w_max, 2)
    37.58
    """
    w = np.asarray(w, float)
    g = np.asarray(coherence, float)
    if w.shape != g.shape or w.ndim != 1 or w.size < 2:
        raise DataError("coherent_band: w and coherence must be 1-D arrays of the same length")
    if not 0 < threshold < 1:
        raise DataError(f"coherence threshold must be between 0 and 1, got {threshold:g}")
    above = np.isfinite(g) & (np.where(np.isfinite(g), g, 0.0) >= threshold)
    capped = np.minimum(np.where(above, g, threshold), threshold + ceiling)
    osc = back_and_forth(capped, np.log10(w), span, _runs(above))
    ok = above & (np.where(above, osc, np.inf) <= roughness)
    runs = _runs(ok)
    if runs:
        a, b = max(runs, key=lambda ab: (np.log10(w[ab[1] - 1] / w[ab[0]]), ab[1] - ab[0]))
        return CoherentBand(float(w[a]), float(w[b - 1]), threshold, roughness, span, ok, ceiling)
    return CoherentBand(float("nan"), float("nan"), threshold, roughness, span, ok, ceiling)


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
