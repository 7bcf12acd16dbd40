"""The coherent band cut to where the input excites: coherence alone does not show an input's band edge.

Below a sweep's lowest frequency (or above its highest) the input's autospectrum is leakage from the band, yet
with little output noise the coherence stays near 1 there while ``H = Gxy / Gxx`` is off by many dB (a sweep
from 0.3 rad/s, estimated down to 0.21 rad/s: 7.7 dB too high at coherence 0.98). At each end of the coherent
band, a point is outside the excitation, and cut from the band, when its input autospectrum ``Gxx`` lies more than
``EDGE_DB + SLOPE_DB * d`` below ``Gxx`` at a point of the band ``d`` decades inward. Inputs change their
``Gxx`` by at most :data:`SLOPE_DB` per decade (a sweep with equal time per decade: ``Gxx ~ 1/w``, 10 dB per
decade; white noise: flat; integrated noise ``1/w^2``: 20 dB per decade); at an input's band edge it falls tens of
dB within a fraction of a decade.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from synth.ident.coherence import CoherentBand

if TYPE_CHECKING:
    from synth.data.record import Record

__all__ = ["EDGE_DB", "FINE_BINS", "SLOPE_DB", "excitation_level", "run_input_level", "trim_to_excitation"]

#: dB, beyond the allowed slope, by which a band end's input autospectrum may lie below a point inward
EDGE_DB = 10.0
#: dB per decade an input autospectrum may fall inside its excitation
SLOPE_DB = 20.0
#: the longest window's input autospectrum tests the band's ends where a cell holds at least this many of its bins
FINE_BINS = 8


def trim_to_excitation(band: CoherentBand, w: np.ndarray, gxx: np.ndarray) -> CoherentBand:
    """``band`` with each end moved inward past the points outside the input's excitation (module text); the
    band's ``note`` says where and why when an end moved.

    Parameters
    ----------
    band : CoherentBand
    w : numpy.ndarray
        The estimate's frequencies [rad/s], increasing.
    gxx : numpy.ndarray
        Input autospectrum at ``w``.

    Returns
    -------
    CoherentBand

    Examples
    --------
    A flat input spectrum from 1 rad/s up, leakage 40 dB lower below it; coherence 0.99 throughout:

    >>> from synth.ident.coherence import coherent_band
    >>> w = np.geomspace(0.1, 10, 41); gxx = np.where(w < 0.99, 1e-4, 1.0)
    >>> b = trim_to_excitation(coherent_band(w, np.full(41, 0.99)), w, gxx)
    >>> round(b.w_min, 3), round(b.w_max, 3), b.note[:40]
    (1.0, 10.0, 'the input excites 1-10 rad/s only: the c')
    """
    if not band.found:
        return band
    w, gxx = np.asarray(w, float), np.asarray(gxx, float)
    inside = np.flatnonzero(band.contains(w))
    a, b = int(inside[0]), int(inside[-1])
    with np.errstate(divide="ignore", invalid="ignore"):
        level = 10 * np.log10(np.where(gxx > 0, gxx, np.nan))
    logw = np.log10(w)

    def outside(i: int, lo: int, hi: int) -> bool:
        if not np.isfinite(level[i]):
            return True
        allowed = level[lo:hi + 1] - EDGE_DB - SLOPE_DB * np.abs(logw[lo:hi + 1] - logw[i])
        return bool(np.any(level[i] < allowed[np.isfinite(allowed)]))

    lo, hi = a, b
    while lo < hi and outside(lo, lo, hi):
        lo += 1
    while hi > lo and outside(hi, lo, hi):
        hi -= 1
    if (lo, hi) == (a, b):
        return band
    mask = band.mask.copy()
    mask[:lo] = False
    mask[hi + 1:] = False
    cut = []
    if lo > a:
        cut.append(f"below {w[lo]:.4g} rad/s")
    if hi < b:
        cut.append(f"above {w[hi]:.4g} rad/s")
    note = (f"the input excites {w[lo]:.4g}-{w[hi]:.4g} rad/s only: the coherent band {band.w_min:.4g}-"
            f"{band.w_max:.4g} rad/s was cut {' and '.join(cut)}, where the input autospectrum lies more than "
            f"{EDGE_DB:g} dB plus {SLOPE_DB:g} dB per decade below its level inward (leakage: the estimate there "
            f"is biased whatever its coherence)")
    return replace(band, w_min=float(w[lo]), w_max=float(w[hi]), mask=mask, note=note)


def excitation_level(results: list[Any], grid: np.ndarray, gxx: np.ndarray, runs: list[Any] | None = None
                     ) -> np.ndarray:
    """The input autospectrum the band's ends are tested on (:func:`trim_to_excitation`): the composite's, or the
    longest window's where that is lower and its cell holds at least :data:`FINE_BINS` of its bins; with ``runs``,
    the whole runs' transforms likewise (:func:`run_input_level`: a 0.11-4.37 rad/s
    sweep of 200 s cut at full amplitude kept 4.37-4.85 rad/s in the band on its 100 s window's leakage, +3.4 dB and
    +12 deg off at coherence 0.98).

    A short window's main lobe spreads a sweep's power past its end: a 0.5-10 rad/s sweep's 2.5 s window put the
    input at 12.5 rad/s 13 dB below its level in the band, the 45 s window 50 dB, and the composite there was 23 %
    off at coherence 0.93 (leakage answers coherently). Where its cells hold several bins the longest window's
    estimate is smooth enough to tell an edge from the scatter of a noise input.

    Examples
    --------
    >>> from synth.ident.spectral_windows import WindowSpectra
    >>> grid = np.array([1.0, 10.0, 12.5]); composite = np.array([1.0, 1.0, 0.05])
    >>> fine = WindowSpectra(100.0, np.array([1.0, 1.0, 1e-5]), np.ones(3), np.ones(3, complex), np.ones(3))
    >>> excitation_level([fine], grid, composite).tolist()  # the 12.5 rad/s cell holds 8 or more of its bins
    [1.0, 1.0, 1e-05]
    """
    from synth.ident.spectral_windows import cell_edges

    fine = max(results, key=lambda r: r.length)
    width = np.diff(cell_edges(grid))
    level = np.where(width * fine.length / (2.0 * np.pi) >= FINE_BINS, np.fmin(gxx, fine.gxx), gxx)
    if not runs:
        return level
    shortest = min(r.n * r.dt for r in runs)  # the whole runs' transforms, as a density like the windows' spectra
    whole = run_input_level(runs, grid) / len(runs) * 2.0 * runs[0].dt / (2.0 * np.pi)
    return np.where(width * shortest / (2.0 * np.pi) >= FINE_BINS, np.fmin(level, whole), level)


def run_input_level(runs: list[Record], w: np.ndarray) -> np.ndarray:
    """The runs' input power in each cell of the grid ``w`` [rad/s], from the whole runs' transforms (the mean of
    ``|U|^2`` over the cell's bins, summed over the runs; the nearest bin's where a cell holds none): a resolution of
    one over the run's length, where a short window's main lobe spreads a sweep's power past its end.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 200, 0.01); u = np.sin(2 * np.pi * (0.05 * t + 0.5 * 0.02 * t**2))  # 0.3-25 rad/s
    >>> level = run_input_level([record_from_arrays(t, u, u)], np.array([10.0, 20.0, 40.0]))
    >>> bool(level[2] < 1e-3 * level[1])  # past the sweep's end
    True
    """
    from synth.ident.spectral_windows import cell_edges

    edges = cell_edges(np.asarray(w, float))
    total = np.zeros(len(w))
    for r in runs:
        power = np.abs(np.fft.rfft(r.u - np.mean(r.u))) ** 2 / r.n
        bins = 2 * np.pi * np.fft.rfftfreq(r.n, r.dt)
        at = np.searchsorted(bins, edges)
        cum = np.r_[0.0, np.cumsum(power)]
        count = np.diff(at)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = (cum[at[1:]] - cum[at[:-1]]) / count
        total += np.where(count > 0, mean, np.interp(w, bins, power))
    return total
