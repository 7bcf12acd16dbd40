"""Windows and averaging of a sweep's frequency-response estimate: segments, spectra, composite, record length.

*Segments.* For one window length ``T_w`` every run is cut into segments of
``N = round(T_w fs)`` samples overlapping by at least ``overlap`` (default 50 %),
spread evenly so that the first starts at the run's start and the last ends at
its end (a sweep's highest frequencies come last; plain Welch drops that tail);
a segment never straddles two runs. Each segment is linearly detrended and multiplied by a
Hann window. The segments of **all runs are averaged together** (the seed
concatenates its two best runs; averaging the segments of both is the same
data without the artificial transient at the join).

*Spectra.* One-sided densities per rad/s: ``Gxx = 2 <|X|^2> / (2 pi fs sum w^2)``,
likewise ``Gyy`` and ``Gxy = 2 <conj(X) Y> / (...)``.

*Log grid.* Results are on a log grid in rad/s (``points_per_decade``). A grid
point takes the mean of the FFT bins of its cell (edges at the geometric
midpoints); a cell without a bin is linearly interpolated from its neighbours.

*Averages.* ``n_d`` is the equivalent number of independent averages: for the
overlapping Hann segments of each run ``K / (1 + 2 sum_m (1 - m/K) rho(m D))``
(Welch's variance formula, ``rho`` the squared window overlap correlation), summed
over runs, times the equivalent number of bins averaged in the cell
(``c^2 / sum_ij rho_bin(|i - j|)``, adjacent Hann bins are correlated).

*Composite.* The longest window is used from two of its periods up
(``w >= 2 * 2 pi / T_w``), the shorter ones from five periods up: noise-free
simulated sweeps showed short windows biased by leakage (an error of tens of
percent with a coherence near 0.9) within a few periods of their limit. At each frequency the windows' ``Gxx``, ``Gyy``,
``Gxy`` are averaged with weights ``1 / eps_i^2`` (inverse random-error variance);
the combined ``n_d`` is the weighted mean of the windows' ``n_d`` (the windows reuse
the same data, so their averages do not add). A shorter window is also left out wherever its
``H`` differs from the longest window's by more than :data:`CONSISTENCY` times their combined
random error: near a lightly damped mode a short window's leakage flattens the peak (by about 5 dB for a
7 Hz mode of 1 % damping seen through an 11 s window) while its many averages would otherwise
give it the larger weight.

*Record length.* A record is too short for ``w_min`` when the longest window it
needs, ``T_w = 2 * 2 pi / w_min`` (two periods), fits fewer than
:data:`MIN_SEGMENTS` times (with overlap) into the runs: stricter than
:meth:`synth.data.Record.require_duration` (one period).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.signal import detrend as _detrend
from scipy.signal.windows import hann

from synth.data import Record
from synth.errors import DataError
from synth.ident.coherence import coherence_from_spectra

__all__ = [
    "CONSISTENCY", "MIN_SEGMENTS", "PERIODS_PER_WINDOW", "SAME_RATE", "USE_PERIODS", "WindowSpectra", "as_runs",
    "cell_edges", "check_length", "combine_windows", "default_windows", "log_grid", "lowest_frequency", "required_window",
    "window_spectra",
]

#: periods of a frequency a window must hold before that window is used there
PERIODS_PER_WINDOW = 2.0
#: periods a shorter window must hold at a frequency before the composite uses it there (the longest
#: window is used from PERIODS_PER_WINDOW): near their limit short windows are biased by leakage
USE_PERIODS = 5.0
#: fewest (overlapping) segments of the longest window for a usable estimate
MIN_SEGMENTS = 3
#: a shorter window is used at a frequency only where its H lies within this many combined random errors
#: of the longest window's H (leakage bias near a lightly damped mode shows up as a disagreement)
CONSISTENCY = 3.0
#: runs whose sample intervals differ by less than this share are at one rate (a clock drift of 1e-6 over a 100 s
#: run moves the last sample by 0.1 ms)
SAME_RATE = 1e-6


def as_runs(records: Record | Sequence[Record]) -> list[Record]:
    """One record or several as a list of runs, checked to share one sample interval.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 1, 0.01)
    >>> len(as_runs(record_from_arrays(t, np.sin(t), np.cos(t))))
    1
    """
    runs = [records] if isinstance(records, Record) else list(records)
    if not runs:
        raise DataError("no records given")
    dt = runs[0].dt
    for r in runs[1:]:
        if abs(r.dt - dt) > SAME_RATE * dt:  # time stamps written to 6 decimals differ by 3e-7 of a 60 Hz interval
            raise DataError(f"sample interval {r.dt:.9g} s differs from the first run's {dt:.9g} s "
                            f"({runs[0].source}); resample the runs to one rate", where=r.source)
    return runs


def _segment_count(n: int, nseg: int, step: int) -> int:
    return 0 if n < nseg else (n - nseg) // step + 1


def _starts(n: int, nseg: int, step: int) -> np.ndarray:
    """Segment starts spread evenly from the run's start to its end (overlap at least the nominal one)."""
    k = int(np.ceil((n - nseg) / step)) + 1
    return np.round(np.linspace(0, n - nseg, k)).astype(int) if k > 1 else np.zeros(1, int)


def _step(nseg: int, overlap: float) -> int:
    return max(1, round(nseg * (1.0 - overlap)))


def _overlap_rho(win: np.ndarray, shift: int) -> float:
    if shift >= win.size:
        return 0.0
    return float(np.dot(win[:-shift] if shift else win, win[shift:]) ** 2 / np.dot(win, win) ** 2)


def _bin_rho(win: np.ndarray, d: int) -> float:
    w2 = win * win
    return float(np.abs(np.sum(w2 * np.exp(-2j * np.pi * d * np.arange(win.size) / win.size))) ** 2 / w2.sum() ** 2)


@dataclass(frozen=True)
class WindowSpectra:
    """Spectra of one window length on the log grid.

    Attributes
    ----------
    length : float
        Window length [s].
    gxx, gyy : numpy.ndarray
        Input and output auto-spectra [unit^2/(rad/s)].
    gxy : numpy.ndarray
        Cross-spectrum.
    n_d : numpy.ndarray
        Equivalent independent averages.

    Examples
    --------
    >>> WindowSpectra(10.0, np.ones(2), np.ones(2), np.ones(2, complex), np.ones(2)).length
    10.0
    """

    length: float
    gxx: np.ndarray
    gyy: np.ndarray
    gxy: np.ndarray
    n_d: np.ndarray


def cell_edges(grid: np.ndarray) -> np.ndarray:
    """The edges of each grid point's cell [rad/s]: the geometric midpoints, the ends mirrored (``grid.size + 1``).

    Examples
    --------
    >>> cell_edges(np.array([1.0, 4.0])).tolist()
    [0.5, 2.0, 8.0]
    """
    if grid.size < 2:
        return np.r_[grid / 1.01, grid * 1.01]
    mid = np.sqrt(grid[1:] * grid[:-1])
    return np.r_[grid[0] ** 2 / mid[0], mid, grid[-1] ** 2 / mid[-1]]


def window_spectra(runs: list[Record], fs: float, nseg: int, overlap: float, grid: np.ndarray,
                   detrend: str) -> WindowSpectra:
    """Segment-averaged spectra of all runs for one window of ``nseg`` samples, on ``grid`` [rad/s].

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 60, 0.01); u = np.sin(0.5 * t * (1 + t / 10))
    >>> s = window_spectra([record_from_arrays(t, u, 2 * u)], 100.0, 1000, 0.5, log_grid(1, 10, 5), "linear")
    >>> bool(np.allclose(s.gxy / s.gxx, 2.0))
    True
    """
    step = _step(nseg, overlap)
    win = hann(nseg, sym=False)
    scale = 2.0 / (2.0 * np.pi * fs * np.dot(win, win))
    nfreq = nseg // 2 + 1
    sxx = np.zeros(nfreq)
    syy = np.zeros(nfreq)
    sxy = np.zeros(nfreq, complex)
    count, n_eff = 0, 0.0
    for r in runs:
        k = _segment_count(r.n, nseg, step)
        if k == 0:
            continue
        starts = _starts(r.n, nseg, step)
        k = starts.size
        idx = starts[:, None] + np.arange(nseg)[None, :]
        xs, ys = r.u[idx], r.y[idx]
        if detrend != "none":
            xs = _detrend(xs, axis=-1, type=detrend)
            ys = _detrend(ys, axis=-1, type=detrend)
        X = np.fft.rfft(xs * win, axis=-1)
        Y = np.fft.rfft(ys * win, axis=-1)
        sxx += np.sum(X.real ** 2 + X.imag ** 2, axis=0)
        syy += np.sum(Y.real ** 2 + Y.imag ** 2, axis=0)
        sxy += np.sum(np.conj(X) * Y, axis=0)
        count += k
        shift = (starts[-1] - starts[0]) / (k - 1) if k > 1 else nseg
        n_eff += k / (1.0 + 2.0 * sum((1.0 - m / k) * _overlap_rho(win, round(m * shift))
                                      for m in range(1, k) if m * shift < nseg))
    if count == 0:
        longest = max(r.n for r in runs) / fs
        raise DataError(f"a window of {nseg / fs:.4g} s fits in none of the runs (the longest {longest:.4g} s)")
    gxx, gyy, gxy = sxx * scale / count, syy * scale / count, sxy * scale / count
    wb = 2.0 * np.pi * fs * np.arange(nfreq) / nseg
    edges = cell_edges(grid)
    cell = np.searchsorted(edges, wb, side="right") - 1
    inside = (cell >= 0) & (cell < grid.size)
    c = np.bincount(cell[inside], minlength=grid.size).astype(float)
    out = []
    for spec in (gxx, gyy, gxy.real, gxy.imag):
        summed = np.bincount(cell[inside], weights=spec[inside], minlength=grid.size)
        interp = np.interp(grid, wb, spec)
        out.append(np.where(c > 0, summed / np.maximum(c, 1), interp))
    rho = [1.0] + [_bin_rho(win, d) for d in range(1, 4)]
    cmax = int(c.max()) if c.size else 0
    bins_eff = np.ones(max(cmax, 1) + 1)   # a band narrower than the bin spacing: no cell holds a bin
    # cc bins of a cell, correlated rho[d] at d bins apart (none beyond 3): the sum of their correlation
    # matrix is cc + 2 sum_d (cc - d) rho[d], in closed form (the matrix itself costs cc^2 per cell size)
    cc = np.arange(2, cmax + 1, dtype=float)
    bins_eff[2:] = cc * cc / (cc + 2.0 * sum(np.maximum(cc - d, 0.0) * rho[d] for d in range(1, 4)))
    n_d = n_eff * bins_eff[np.maximum(c, 1).astype(int)]
    length = nseg / fs
    return WindowSpectra(length, out[0], out[1], out[2] + 1j * out[3], n_d)


def combine_windows(results: list[WindowSpectra], grid: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The composite ``Gxx``, ``Gyy``, ``Gxy`` and ``n_d``: windows weighted by their inverse random-error variance.

    Examples
    --------
    >>> one = WindowSpectra(10.0, np.ones(2), np.ones(2), np.ones(2, complex), np.ones(2))
    >>> [a.tolist() for a in combine_windows([one], np.array([1.0, 2.0]))][0]
    [1.0, 1.0]
    """
    if len(results) == 1:
        r = results[0]
        return r.gxx, r.gyy, r.gxy, r.n_d
    longest = int(np.argmax([r.length for r in results]))
    eps2s = []
    for r in results:
        coh = coherence_from_spectra(r.gxx, r.gyy, r.gxy)
        eps2s.append((1.0 - np.minimum(coh, 1.0 - 1e-9)) / (np.maximum(coh, 1e-12) * 2.0 * r.n_d))
    ref = results[longest]
    with np.errstate(divide="ignore", invalid="ignore"):
        h_ref = ref.gxy / ref.gxx
    weights = []
    for i, (r, eps2) in enumerate(zip(results, eps2s)):
        periods = PERIODS_PER_WINDOW if i == longest else USE_PERIODS
        usable = (grid >= periods * 2.0 * np.pi / r.length) & np.isfinite(eps2)
        if i != longest:   # leakage bias (a lightly damped mode): a shorter window must agree with the longest
            with np.errstate(divide="ignore", invalid="ignore"):
                dev = np.abs(r.gxy / r.gxx - h_ref) / np.abs(h_ref)
            usable &= np.nan_to_num(dev, nan=np.inf) <= CONSISTENCY * np.sqrt(eps2 + eps2s[longest])
        weights.append(np.where(usable, 1.0 / np.where(usable, eps2, 1.0), 0.0))
    W = np.array(weights)
    W[longest, W.sum(axis=0) == 0] = 1.0   # nothing usable (zero coherence everywhere): the longest window
    W = W / W.sum(axis=0)
    gxx = np.sum(W * np.array([r.gxx for r in results]), axis=0)
    gyy = np.sum(W * np.array([r.gyy for r in results]), axis=0)
    gxy = np.sum(W * np.array([r.gxy for r in results]), axis=0)
    n_d = np.sum(W * np.array([r.n_d for r in results]), axis=0)
    return gxx, gyy, gxy, n_d


def required_window(w_min: float) -> float:
    """The longest window [s] needed for ``w_min`` [rad/s]: two periods, ``2 * 2 pi / w_min``.

    Examples
    --------
    >>> round(required_window(0.4), 2)   # the seed's 0.4 rad/s: T_max = 15.7 s, window 31.4 s
    31.42
    """
    return PERIODS_PER_WINDOW * 2.0 * np.pi / w_min


def check_length(records: Record | Sequence[Record], w_min: float, overlap: float = 0.5) -> None:
    """Raise :class:`DataError` if the runs are too short for ``w_min`` [rad/s].

    The longest window, ``2 * 2 pi / w_min``, must fit :data:`MIN_SEGMENTS`
    times (with ``overlap``) into the runs together.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 40, 0.01)
    >>> check_length(record_from_arrays(t, np.sin(t * t), np.cos(t)), 0.4)
    Traceback (most recent call last):
    synth.errors.DataError: arrays: runs hold 1 segment(s) of the 31.4 s window that w_min = 0.4 rad/s needs ...
    """
    runs = as_runs(records)
    if not (np.isfinite(w_min) and w_min > 0):
        raise DataError(f"w_min must be a positive frequency in rad/s, got {w_min!r}")
    fs = runs[0].fs
    nseg = round(required_window(w_min) * fs)
    step = _step(nseg, overlap)
    total = sum(_segment_count(r.n, nseg, step) for r in runs)
    if total < MIN_SEGMENTS:
        need = (nseg + (MIN_SEGMENTS - 1) * step) / fs
        have = ", ".join(f"{r.duration:.3g} s" for r in runs)
        raise DataError(f"runs hold {total} segment(s) of the {nseg / fs:.3g} s window that w_min = {w_min:g} rad/s "
                        f"needs (two periods); at least {MIN_SEGMENTS} are needed, e.g. one run of {need:.3g} s "
                        f"(runs: {have}); record longer or raise --wmin", where=runs[0].source)


def lowest_frequency(records: Record | Sequence[Record], overlap: float = 0.5) -> float:
    """The lowest ``w_min`` [rad/s] the runs support (see :func:`check_length`).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 90, 0.01)
    >>> round(lowest_frequency(record_from_arrays(t, np.sin(t * t), np.cos(t))), 3)   # a 45 s window
    0.279
    """
    runs = as_runs(records)
    lo, hi = 1e-6, 2.0 * np.pi * runs[0].fs
    for _ in range(60):
        mid = np.sqrt(lo * hi)
        try:
            check_length(runs, mid, overlap)
            hi = mid
        except DataError:
            lo = mid
    return float(hi)


def default_windows(w_min: float, count: int = 5, ratio: float = 10.0, longest: float | None = None) -> tuple[float, ...]:
    """Composite window lengths [s]: ``count`` lengths from ``longest`` down to ``2 * 2 pi / w_min / ratio``.

    ``longest`` defaults to ``2 * 2 pi / w_min``; :func:`frequency_response`
    passes the longest window that fits :data:`MIN_SEGMENTS` times into the runs
    (less leakage bias at the lowest frequencies).

    Examples
    --------
    >>> [round(x, 2) for x in default_windows(0.4)]
    [31.42, 17.67, 9.93, 5.59, 3.14]
    >>> [round(x, 1) for x in default_windows(0.4, longest=60.0)]
    [60.0, 28.7, 13.7, 6.6, 3.1]
    """
    shortest = required_window(w_min) / ratio
    top = max(required_window(w_min), longest or 0.0)
    return tuple(float(x) for x in np.geomspace(top, shortest, count))


def log_grid(w_min: float, w_max: float, points_per_decade: int = 40) -> np.ndarray:
    """Log-spaced frequencies [rad/s] from ``w_min`` to ``w_max``.

    Examples
    --------
    >>> log_grid(1, 100, 10).size
    21
    """
    n = max(2, int(np.ceil(np.log10(w_max / w_min) * points_per_decade)) + 1)
    return np.geomspace(w_min, w_max, n)
