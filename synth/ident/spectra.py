"""Frequency response from sweep records: spectra, coherence, composite windows, coherent band.

What is computed, exactly
-------------------------
*Segments.* For one window length ``T_w`` every run is cut into segments of
``N = round(T_w fs)`` samples overlapping by at least ``overlap`` (default 50 %),
spread evenly so that the first starts at the run's start and the last ends at
its end (a sweep's highest frequencies come last; plain Welch drops that tail);
a segment never straddles two runs. Each segment is linearly detrended and multiplied by a
Hann window. The segments of **all runs are averaged together** (the seed
concatenates its two best runs; averaging the segments of both is the same
data without the artificial transient at the join).

*Spectra.* One-sided densities per rad/s: ``Gxx = 2 <|X|^2> / (2 pi fs sum w^2)``,
likewise ``Gyy`` and ``Gxy = 2 <conj(X) Y> / (...)``; ``H = Gxy / Gxx`` and
``gamma^2 = |Gxy|^2 / (Gxx Gyy)``.

*Log grid.* Results are on a log grid in rad/s (``points_per_decade``). A grid
point takes the mean of the FFT bins of its cell (edges at the geometric
midpoints); a cell without a bin is linearly interpolated from its neighbours.

*Averages.* ``n_d`` is the equivalent number of independent averages: for the
overlapping Hann segments of each run ``K / (1 + 2 sum_m (1 - m/K) rho(m D))``
(Welch's variance formula, ``rho`` the squared window overlap correlation), summed
over runs, times the equivalent number of bins averaged in the cell
(``c^2 / sum_ij rho_bin(|i - j|)``, adjacent Hann bins are correlated).

*Random error.* Normalized random error of ``|H|`` (and, in radians, of its phase):
``eps = sqrt(1 - gamma^2) / (|gamma| sqrt(2 n_d))``.

*Composite.* The longest window is used from two of its periods up
(``w >= 2 * 2 pi / T_w``), the shorter ones from five periods up: noise-free
simulated sweeps showed short windows biased by leakage (an error of tens of
percent with a coherence near 0.9) within a few periods of their limit. At each frequency the windows' ``Gxx``, ``Gyy``,
``Gxy`` are averaged with weights ``1 / eps_i^2`` (inverse random-error variance);
``H`` and ``gamma^2`` come from the combined spectra; the combined ``n_d`` is the
weighted mean of the windows' ``n_d`` (the windows reuse the same data, so their
averages do not add).

*Coherent band.* Where ``gamma^2 >= threshold`` (0.8, the seed's criterion) and the
coherence does not oscillate: within +/- ``span`` decades of a point, the total
variation of ``gamma^2`` minus its net change (the back-and-forth part) must stay
below ``roughness`` (default 0.15). The band is the widest contiguous run of such
points.

*Record length.* A record is too short for ``w_min`` when the longest window it
needs, ``T_w = 2 * 2 pi / w_min`` (two periods), fits fewer than
:data:`MIN_SEGMENTS` times (with overlap) into the runs: stricter than
:meth:`synth.data.Record.require_duration` (one period).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy.signal import detrend as _detrend
from scipy.signal.windows import hann

from synth.data import Record
from synth.errors import DataError

#: periods of a frequency a window must hold before that window is used there
PERIODS_PER_WINDOW = 2.0
#: periods a shorter window must hold at a frequency before the composite uses it there (the longest
#: window is used from PERIODS_PER_WINDOW): near their limit short windows are biased by leakage
USE_PERIODS = 5.0
#: periods a shorter window must hold at a frequency before the composite uses it there (the longest
#: window is used from PERIODS_PER_WINDOW): near their limit short windows are biased by leakage
USE_PERIODS = 5.0
#: periods a shorter window must hold at a frequency before the composite uses it there (the longest
#: window is used from PERIODS_PER_WINDOW): near their limit short windows are biased by leakage
USE_PERIODS = 5.0
#: periods a shorter window must hold at a frequency before the composite uses it there (the longest
#: window is used from PERIODS_PER_WINDOW): near their limit short windows are biased by leakage
USE_PERIODS = 5.0
#: fewest (overlapping) segments of the longest window for a usable estimate
MIN_SEGMENTS = 3
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


@dataclass(frozen=True)
class FrequencyResponse:
    """An identified frequency response on a log grid.

    Attributes
    ----------
    w : numpy.ndarray
        Frequencies [rad/s].
    H : numpy.ndarray
        Complex response ``Gxy / Gxx``.
    coherence : numpy.ndarray
        ``gamma^2``.
    random_error : numpy.ndarray
        Normalized random error of ``|H|`` (also the phase error in rad).
    n_averages : numpy.ndarray
        Equivalent independent averages ``n_d``.
    gxx, gyy : numpy.ndarray
        Input and output auto-spectra [unit^2/(rad/s)].
    gxy : numpy.ndarray
        Cross-spectrum.
    band : CoherentBand
    windows : tuple of float
        Window lengths used [s].
    kind : str
        ``"measured"`` or ``"integrated (1/s)"`` after :func:`rate_to_attitude`.
    input, output : str
        Signal labels.
    sources : tuple of str
        The runs.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 60, 0.01); u = np.sin(0.5 * t * (1 + t / 10))
    >>> r = frequency_response(record_from_arrays(t, u, 2 * u), w_min=1.0, w_max=10.0)
    >>> bool(np.allclose(r.magnitude_db, 20 * np.log10(2)))
    True
    """

    w: np.ndarray
    H: np.ndarray
    coherence: np.ndarray
    random_error: np.ndarray
    n_averages: np.ndarray
    gxx: np.ndarray
    gyy: np.ndarray
    gxy: np.ndarray
    band: CoherentBand
    windows: tuple[float, ...]
    kind: str = "measured"
    input: str = "u"
    output: str = "y"
    sources: tuple[str, ...] = ()

    @property
    def magnitude_db(self) -> np.ndarray:
        """``20 log10 |H|`` [dB]."""
        return 20.0 * np.log10(np.abs(self.H))

    @property
    def phase_deg(self) -> np.ndarray:
        """Phase [deg], unwrapped from the lowest frequency."""
        return np.degrees(np.unwrap(np.angle(self.H)))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the grid ``w``, ``magnitude_db``, ``phase_deg``, ``coherence``, ``random_error``, band.

        Examples
        --------
        >>> w = np.array([1.0, 2.0]); b = coherent_band(w, np.ones(2) * 0.9)
        >>> r = FrequencyResponse(w, np.array([1j, 1.0]), np.ones(2) * .9, np.ones(2) * .1, np.ones(2),
        ...                       np.ones(2), np.ones(2), np.ones(2, complex), b, (10.0,))
        >>> r.to_dict()["phase_deg"].tolist()
        [90.0, 0.0]
        """
        return {"w": self.w, "magnitude_db": self.magnitude_db, "phase_deg": self.phase_deg,
                "coherence": self.coherence, "random_error": self.random_error, "n_averages": self.n_averages,
                "coherent_band": self.band.to_dict(), "windows_s": list(self.windows), "kind": self.kind,
                "input": self.input, "output": self.output, "sources": list(self.sources),
                "units": {"w": "rad/s", "magnitude_db": "dB", "phase_deg": "deg"}}


def _as_runs(records: Record | Sequence[Record]) -> list[Record]:
    runs = [records] if isinstance(records, Record) else list(records)
    if not runs:
        raise DataError("no records given")
    dt = runs[0].dt
    for r in runs[1:]:
        if abs(r.dt - dt) > 1e-9 * dt:
            raise DataError(f"sample interval {r.dt:g} s differs from the first run's {dt:g} s "
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
class _WindowResult:
    length: float
    gxx: np.ndarray
    gyy: np.ndarray
    gxy: np.ndarray
    n_d: np.ndarray


def _window_on_grid(runs: list[Record], fs: float, nseg: int, overlap: float, grid: np.ndarray,
                    detrend: str) -> _WindowResult:
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
    gxx, gyy, gxy = sxx * scale / count, syy * scale / count, sxy * scale / count
    wb = 2.0 * np.pi * fs * np.arange(nfreq) / nseg
    edges = np.sqrt(grid[1:] * grid[:-1])
    first = grid[0] ** 2 / edges[0] if grid.size > 1 else grid[0] / 1.01
    last = grid[-1] ** 2 / edges[-1] if grid.size > 1 else grid[0] * 1.01
    edges = np.r_[first, edges, last]
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
    bins_eff = np.ones(cmax + 1)
    for cc in range(2, cmax + 1):
        d = np.abs(np.subtract.outer(np.arange(cc), np.arange(cc)))
        bins_eff[cc] = cc * cc / np.sum(np.where(d < 4, np.take(rho, np.minimum(d, 3)), 0.0))
    n_d = n_eff * bins_eff[np.maximum(c, 1).astype(int)]
    length = nseg / fs
    return _WindowResult(length, out[0], out[1], out[2] + 1j * out[3], n_d)


def _coherence(gxx: np.ndarray, gyy: np.ndarray, gxy: np.ndarray) -> np.ndarray:
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
    runs = _as_runs(records)
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
    runs = _as_runs(records)
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


def frequency_response(
    records: Record | Sequence[Record],
    w_min: float | None = None,
    w_max: float | None = None,
    windows: Sequence[float] | None = None,
    overlap: float = 0.5,
    points_per_decade: int = 40,
    coherence_threshold: float = COHERENCE_THRESHOLD,
    detrend: str = "linear",
) -> FrequencyResponse:
    """Composite multi-window frequency response of one or several sweep runs.

    Parameters
    ----------
    records : Record or sequence of Record
        The runs (same sample rate); their segments are averaged together.
    w_min, w_max : float, optional
        Frequency range [rad/s]; defaults: the lowest frequency the runs support
        (:func:`lowest_frequency`) and a fifth of the Nyquist frequency.
    windows : sequence of float, optional
        Window lengths [s]; default :func:`default_windows`: 5 lengths from the
        longest that fits :data:`MIN_SEGMENTS` times into the runs (at least
        ``2 * 2 pi / w_min``) down to a tenth of ``2 * 2 pi / w_min``. One length
        gives a single-window estimate.
    overlap : float
        Segment overlap fraction (0 <= overlap < 1).
    points_per_decade : int
        Density of the output grid.
    coherence_threshold : float
        For the coherent band (the seed: 0.8).
    detrend : {"linear", "constant", "none"}
        Per-segment detrending.

    Returns
    -------
    FrequencyResponse

    Raises
    ------
    DataError
        Runs too short for ``w_min`` (:func:`check_length`), different sample
        rates, a bad range or window.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> from synth.ident.sweep_design import design_sweep
    >>> G = Plant.from_string("5/(s+2)", delay=0.05)
    >>> t, u = design_sweep(0.4, 10).signal(sample_rate=50)
    >>> r = frequency_response(record_from_arrays(t, u, simulate_plant(G, t, u, "zero")), 0.4, 10)
    >>> k = np.argmin(abs(r.w - 2)); round(float(abs(r.H[k])), 2), round(float(abs(G.freqresp(r.w[k]))), 2)
    (1.79, 1.77)
    """
    runs = _as_runs(records)
    fs = runs[0].fs
    if not 0 <= overlap < 1:
        raise DataError(f"overlap must be in [0, 1), got {overlap:g}")
    if detrend not in ("linear", "constant", "none"):
        raise DataError(f"detrend must be 'linear', 'constant' or 'none', got {detrend!r}")
    nyquist = np.pi * fs
    w_min = lowest_frequency(runs, overlap) if w_min is None else float(w_min)
    w_max = 0.2 * nyquist if w_max is None else float(w_max)
    if not (0 < w_min < w_max):
        raise DataError(f"need 0 < w_min < w_max, got w_min = {w_min:g}, w_max = {w_max:g} rad/s")
    if w_max > nyquist:
        raise DataError(f"w_max = {w_max:g} rad/s is above the Nyquist frequency {nyquist:.4g} rad/s "
                        f"(sample rate {fs:g} Hz)")
    check_length(runs, w_min, overlap)
    if windows is None:
        lengths = default_windows(w_min, longest=required_window(lowest_frequency(runs, overlap)) * (1 - 1e-9))
    else:
        lengths = tuple(windows)
    grid = log_grid(w_min, w_max, points_per_decade)
    longest_run = max(r.n for r in runs)
    results = []
    for length in lengths:
        nseg = round(float(length) * fs)
        if nseg < 8 or nseg > longest_run:
            raise DataError(f"window {length:g} s must hold at least 8 samples and fit in the longest run "
                            f"({longest_run / fs:.4g} s)")
        results.append(_window_on_grid(runs, fs, nseg, overlap, grid, detrend))
    gxx, gyy, gxy, n_d = _combine(results, grid)
    coh = _coherence(gxx, gyy, gxy)
    with np.errstate(divide="ignore", invalid="ignore"):
        H = gxy / gxx
    err = random_error(coh, n_d)
    band = coherent_band(grid, coh, coherence_threshold)
    return FrequencyResponse(grid, H, coh, err, n_d, gxx, gyy, gxy, band, tuple(float(x) for x in lengths),
                             "measured", runs[0].input.label(), runs[0].output.label(),
                             tuple(r.source for r in runs))


def _combine(results: list[_WindowResult], grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    if len(results) == 1:
        r = results[0]
        return r.gxx, r.gyy, r.gxy, r.n_d
    longest = int(np.argmax([r.length for r in results]))
    weights = []
    for i, r in enumerate(results):
        periods = PERIODS_PER_WINDOW if i == longest else USE_PERIODS
        coh = _coherence(r.gxx, r.gyy, r.gxy)
        eps2 = (1.0 - np.minimum(coh, 1.0 - 1e-9)) / (np.maximum(coh, 1e-12) * 2.0 * r.n_d)
        usable = (grid >= periods * 2.0 * np.pi / r.length) & np.isfinite(eps2)
        weights.append(np.where(usable, 1.0 / np.where(usable, eps2, 1.0), 0.0))
    W = np.array(weights)
    W[longest, W.sum(axis=0) == 0] = 1.0   # nothing usable (zero coherence everywhere): the longest window
    W = W / W.sum(axis=0)
    gxx = np.sum(W * np.array([r.gxx for r in results]), axis=0)
    gyy = np.sum(W * np.array([r.gyy for r in results]), axis=0)
    gxy = np.sum(W * np.array([r.gxy for r in results]), axis=0)
    n_d = np.sum(W * np.array([r.n_d for r in results]), axis=0)
    return gxx, gyy, gxy, n_d


def rate_to_attitude(resp: FrequencyResponse) -> FrequencyResponse:
    """Integrate a rate response to an attitude response: ``H / (j w)``.

    Magnitude drops by ``20 log10 w`` dB, phase by 90 deg; coherence and random
    error are unchanged (the seed, fig. 11: ``theta = p / s``).

    Examples
    --------
    >>> w = np.array([2.0]); b = coherent_band(np.r_[w, 3.0], np.ones(2))
    >>> r = FrequencyResponse(w, np.array([4.0 + 0j]), np.ones(1), np.zeros(1), np.ones(1),
    ...                       np.ones(1), np.ones(1), np.ones(1, complex), b, (10.0,))
    >>> a = rate_to_attitude(r); complex(a.H[0]), a.kind
    (-2j, 'integrated (1/s)')
    """
    return replace(resp, H=resp.H / (1j * resp.w), gxy=resp.gxy / (1j * resp.w), gyy=resp.gyy / resp.w ** 2,
                   kind="integrated (1/s)")
