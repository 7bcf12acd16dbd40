"""The output moved back by the response's delay before windowing, the delay put back in the phase afterwards.

A window of the input and the same window of the output see the same excitation only when the output answers at
once. Behind a delay ``D`` the output's answer to what a window's input holds lies ``D`` later, further down the
window's taper or past its end: the estimate at the frequencies a sweep reaches last (or first) is biased (session
62's black-box test: ``e^(-2 s)/(s + 1)`` behind a 0.1-5 rad/s sweep, the band's top 2-4 dB low and 7-47 deg off,
a fitted delay 10 std short). Moving the output ``k`` samples earlier (``y[k:]`` against ``u[:-k]``) and
multiplying the estimate by ``exp(-j w k dt)`` afterwards is exact for the delay and leaves the windows aligned with
what they excite. ``k`` is the lower quartile of the response's group delay over the upper half of the coherent band
of a first estimate, in samples: the pure delay, to which a plant's lags add (a shift by a lag's group delay as well
took a moving run's lowest frequencies further from the truth); the realignment is made only where that is a
material share of the shortest window.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from synth.data import Record
from synth.ident.coherence import CoherentBand
from synth.ident.excitation_edge import SLOPE_DB

__all__ = ["ALIGN_SHARE", "EXCITED_DB", "alignment_samples", "band_after_alignment", "shifted_runs"]

ALIGN_SHARE = 0.05
"""Share of the shortest window the group delay must reach for the output to be realigned."""

EXCITED_DB = 3.0
"""Past an end of the estimate's band before the move, the realigned band is kept where the input autospectrum lies
at most this many dB (plus :data:`~synth.ident.excitation_edge.SLOPE_DB` per decade) below its level at that end."""


def alignment_samples(w: np.ndarray, H: np.ndarray, band: CoherentBand, fs: float, shortest_window: float,
                      shortest_run: int) -> int:
    """Samples by which to move the output earlier: the lower quartile of the group delay ``-d(phase)/dw`` over
    the upper half (in log frequency) of the coherent band, rounded to samples; 0 where there is no band, where that delay is
    negative or below :data:`ALIGN_SHARE` of ``shortest_window`` [s], or where it would leave less than half the
    shortest run.

    Examples
    --------
    >>> from synth.ident.coherence import coherent_band
    >>> w = np.geomspace(0.1, 5, 60); H = np.exp(-2j * w) / (1j * w + 1)
    >>> alignment_samples(w, H, coherent_band(w, np.full(60, 0.99)), 50.0, 15.0, 15000)  # 2 s and a little lag
    105
    >>> alignment_samples(w, 1 / (1j * w + 1), coherent_band(w, np.full(60, 0.99)), 50.0, 15.0, 15000)
    0
    """
    if not band.found:
        return 0
    inside = band.contains(w) & np.isfinite(H) & (np.abs(H) > 0)
    if np.count_nonzero(inside) < 4:
        return 0
    wb, phase = w[inside], np.unwrap(np.angle(H[inside]))
    upper = np.log(wb) >= 0.5 * (np.log(wb[0]) + np.log(wb[-1]))
    slopes = -np.diff(phase) / np.diff(wb)
    delays = slopes[upper[1:]]
    if delays.size == 0:
        return 0
    delay = float(np.quantile(delays, 0.25))
    if not delay >= ALIGN_SHARE * shortest_window:
        return 0
    k = round(delay * fs)
    return k if 0 < k <= shortest_run // 2 else 0


def shifted_runs(runs: list[Record], k: int) -> list[Record]:
    """Each run with its output moved ``k`` samples earlier (``y[k:]`` against ``u[:-k]``, the time of ``u``).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> r = record_from_arrays(np.arange(6.0), [0, 1, 1, 1, 1, 1], [0, 0, 0, 1, 1, 1])
    >>> s = shifted_runs([r], 2)[0]
    >>> s.u.tolist(), s.y.tolist()
    ([0.0, 1.0, 1.0, 1.0], [0.0, 1.0, 1.0, 1.0])
    """
    return [replace(r, t=r.t[:-k], u=r.u[:-k], y=r.y[k:], aux={}, gaps=()) for r in runs]


def band_after_alignment(before: CoherentBand, after: CoherentBand, w: np.ndarray, gxx: np.ndarray) -> CoherentBand:
    """The realigned estimate's coherent band ``after``, kept past the ends of the band ``before`` the move only
    where the input excites as strongly as at that end (within :data:`EXCITED_DB` plus the slope an input's
    autospectrum may have, :data:`~synth.ident.excitation_edge.SLOPE_DB` per decade).

    Realigned, the leakage past a sweep's end answers coherently too, and its estimate is biased: there the input
    autospectrum falls away from the band's end. A noise input behind a delay excites past the end, which only the
    delay's bias on the windows' coherence had set (white noise behind 0.1 s, windows down to 1.5 s: 252 rad/s
    before the move, coherence 0.999 and the truth within 0.05 dB up to 628 rad/s after it).

    Parameters
    ----------
    before, after : CoherentBand
        The bands before and after the move (on the same grid ``w``).
    w, gxx : numpy.ndarray
        Frequencies [rad/s] and the input's power on them (:func:`synth.ident.excitation_edge.run_input_level`:
        a window's leakage past a sweep's end would look like excitation).

    Returns
    -------
    CoherentBand

    Examples
    --------
    >>> from synth.ident.coherence import coherent_band
    >>> w = np.geomspace(1, 100, 41)
    >>> before, after = coherent_band(w, np.where(w < 20, 0.99, 0.5)), coherent_band(w, np.full(41, 0.99))
    >>> round(band_after_alignment(before, after, w, np.ones(41)).w_max, 1)  # white noise: the band widens
    100.0
    >>> round(band_after_alignment(before, after, w, np.where(w < 20, 1.0, 1e-3)).w_max, 1)  # a sweep's end: not
    20.0
    >>> apart = coherent_band(w, np.where(w > 50, 0.99, 0.5))  # no overlap with ``before``: ``apart`` as it is
    >>> band_after_alignment(before, apart, w, np.ones(41)).w_min == apart.w_min
    True
    """
    if not (before.found and after.found):
        return after
    with np.errstate(divide="ignore"):
        level = 10 * np.log10(np.maximum(np.asarray(gxx, float), 1e-300))
    logw = np.log10(w)
    keep = after.mask & before.mask
    inside = np.flatnonzero(before.mask)
    for end, beyond in ((inside[0], np.arange(inside[0] - 1, -1, -1)), (inside[-1], np.arange(inside[-1] + 1, w.size))):
        for i in beyond:
            if not after.mask[i] or level[i] < level[end] - EXCITED_DB - SLOPE_DB * abs(logw[i] - logw[end]):
                break
            keep[i] = True
    found = np.flatnonzero(keep)
    if found.size == 0:  # the two bands do not overlap: the realigned one as it is
        return after
    return replace(after, w_min=float(w[found[0]]), w_max=float(w[found[-1]]), mask=keep)
