"""A lightly damped mode that rings longer than the composite's windows: leakage, not noise, at its peak.

Every window of the composite (:mod:`synth.ident.spectral_windows`) sees a sweep's resonance for a while only;
a mode whose ring-down outlasts the window leaks its output into the windows after the input has moved on. The
coherence then dips at the peak, where the output's signal to noise is highest, and it falls with the window's
length: a black-box test's noise-free 120 s sweep through ``25/(s^2 + 0.5 s + 25)`` (damping 0.05, 4 s to decay)
had a coherence of 0.90 in the 63.5 s window at the peak and 0.35 in the 6.35 s one, a composite of 0.76, and a
coherent band that ended below the mode, its last points 1.9 dB low. Noise lowers every window's coherence alike
(the shortest ones, with the most averages, are the least biased upward). :func:`leakage_points` finds the
signature; for runs from rest to rest (:func:`synth.ident.whole_run.at_rest`) the whole-run ratio, which has no
window, replaces the composite there (exact to 0.001 dB on that record), with the longest window's coherence.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np

from synth.ident.coherence import coherence_from_spectra
from synth.ident.spectral_windows import PERIODS_PER_WINDOW, USE_PERIODS, WindowSpectra

__all__ = ["LEAK_RISE", "PEAK_SPAN", "PROMINENCE", "TIE", "leakage_points"]

LEAK_RISE = 0.1
"""Least excess of the longest window's coherence over the mean of the shorter usable windows' at a point of
leakage."""

PROMINENCE = 2.0
"""A resonance's peak stands at least this factor (6 dB) above ``|H|`` at both ends of its :data:`PEAK_SPAN`
(a mode of damping 0.1 or less: 13 dB or more; a ripple of noise on a falling response: none)."""

TIE = 0.01
"""A shorter window's coherence may exceed the longest's by this much at a point of leakage (the segments fall
differently on the sweep's passage: not strictly monotone)."""

PEAK_SPAN = 0.1
"""Half width [decades] around a local maximum of the whole-run magnitude within which a point may leak."""


def leakage_points(results: Sequence[WindowSpectra], grid: np.ndarray, magnitude: np.ndarray,
                   threshold: float) -> np.ndarray:
    """Grid points with the leakage signature: within :data:`PEAK_SPAN` decades of a resonance's peak
    (:data:`PROMINENCE`) of ``magnitude`` (``|H|``: the composite flattens a peak, it does not move it), the
    longest window and at least one shorter one usable there, the longest window's coherence at least
    ``threshold``, at least the shorter ones' (to :data:`TIE`) and :data:`LEAK_RISE` above their mean.

    Examples
    --------
    >>> grid = np.geomspace(1.0, 10.0, 11)
    >>> mag = 1.0 / np.abs(5.0 - grid + 0.3j)  # a peak at 5 rad/s
    >>> def window(length, coh):
    ...     return WindowSpectra(length, np.ones(11), np.ones(11), np.sqrt(coh) * np.ones(11, complex), np.ones(11))
    >>> dip = np.where(np.abs(grid - 5.0) < 0.6, 0.5, 0.99)
    >>> leakage_points([window(60.0, np.full(11, 0.95)), window(20.0, dip)], grid, mag, 0.8).nonzero()[0].tolist()
    [7]
    """
    by_length = sorted(results, key=lambda r: -r.length)
    coh = np.array([coherence_from_spectra(r.gxx, r.gyy, r.gxy) for r in by_length])
    usable = np.array([grid >= (PERIODS_PER_WINDOW if i == 0 else USE_PERIODS) * 2.0 * np.pi / r.length
                       for i, r in enumerate(by_length)]) & np.isfinite(coh)
    shorter = np.where(usable[1:], coh[1:], np.nan)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # no shorter window usable: nan, not a leak
        highest, mean = np.nanmax(shorter, axis=0), np.nanmean(shorter, axis=0)
    signature = usable[0] & (usable[1:].sum(axis=0) >= 1) & (coh[0] >= threshold) \
        & (coh[0] >= highest - TIE) & (coh[0] - mean >= LEAK_RISE)
    mag = np.where(np.isfinite(magnitude), magnitude, 0.0)
    peaks = np.flatnonzero((mag[1:-1] > mag[:-2]) & (mag[1:-1] >= mag[2:])) + 1
    near = np.zeros(grid.size, bool)
    logw = np.log10(grid)
    for p in peaks:
        span = np.abs(logw - logw[p]) <= PEAK_SPAN
        ends = np.flatnonzero(span)[[0, -1]]
        if ends[0] > 0 and ends[1] < grid.size - 1 and mag[p] >= PROMINENCE * max(mag[ends[0]], mag[ends[1]]):
            near |= span  # a resonance: the peak stands above both ends of its span (not a ripple of noise)
    return signature & near
