"""Disturbance and noise spectra (seed 1, section 5): Welch PSD, trend, floor, spikes, power share.

Conventions (as :mod:`synth.sim.signals`): one-sided PSD in ``unit^2/(rad/s)`` on ``w`` in rad/s,
so that the variance is ``integral_0^inf S(w) dw``; in dB, ``10 log10(S)`` re 1 ``unit^2/(rad/s)``.

- **Welch estimate**: Hann window, 50 % overlap, mean removed per segment; several records (same
  sample interval) are averaged segment by segment. The DC bin is dropped.
- **Noise floor**: the median of the PSD over a floor band (default: the upper half of the
  frequency axis, spikes left out), divided by the median of the estimate's chi-square
  distribution so that it estimates the mean level. Given a noise record (the seed's
  "sensor noise test", motor stopped), its PSD is used instead. When the spectrum still falls
  across the floor band the floor is an upper bound, and the notes say so.
- **Spikes**: local peaks standing more than ``spike_db`` above a running median of the dB spectrum
  (window +-max(8 bins, 5 % of the frequency)), with frequency (parabolic interpolation),
  height, and the power standing above the median.
- **Trend**: least-squares line of dB against ``log10 w`` with equal weight per decade, spikes left
  out, over a band (default: from the lowest bin to where the running median first comes within
  3 dB of the floor). The slope is in dB/decade.
- **Share frequency**: the frequency below which ``share`` of the disturbance power lies; the
  disturbance power density is ``S - floor`` (not clipped, so noise-only bins add nothing on
  average), spikes replaced by the running median.
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import signal as sps
from scipy.stats import chi2

from synth.data.record import uniform_columns
from synth.errors import DataError

#: correlation of adjacent 50 %-overlapped Hann segments' estimates (Welch 1967), for the degrees of freedom
_HANN_OVERLAP_CORRELATION = 0.167
#: the trend band ends where the running median comes within this many dB of the floor
KNEE_DB = 3.0


# --------------------------------------------------------------------------------------- loading
@dataclass(frozen=True, eq=False)
class DisturbanceRecord:
    """One uniformly sampled disturbance (or noise) signal: no input, just a measured channel.

    Examples
    --------
    >>> r = disturbance_from_arrays(np.arange(100) * 0.01, np.sin(np.arange(100)))
    >>> r.dt, r.x.size
    (0.01, 100)
    """

    t: np.ndarray
    x: np.ndarray
    name: str = "y"
    unit: str = ""
    source: str = "arrays"
    notes: tuple[str, ...] = ()

    @property
    def dt(self) -> float:
        """Sample interval [s]."""
        return float(round((self.t[-1] - self.t[0]) / (self.t.size - 1), 12))

    @property
    def duration(self) -> float:
        """Record length [s]."""
        return float(self.t[-1] - self.t[0])

    def to_dict(self) -> dict[str, Any]:
        """Summary for JSON (not the samples)."""
        return {"source": self.source, "signal": self.name, "unit": self.unit, "samples": int(self.x.size),
                "dt": self.dt, "duration": self.duration, "notes": list(self.notes)}


def disturbance_from_arrays(t: Any, x: Any, name: str = "y", unit: str = "", source: str = "arrays",
                            time_name: str = "time") -> DisturbanceRecord:
    """Validate a time column and a signal column (irregular time is resampled linearly, with a note).

    Raises
    ------
    DataError
        NaN or inf, different lengths, fewer than 16 samples, non-increasing time, a constant signal.

    Examples
    --------
    >>> t = np.arange(20.0); t[5] = t[4]
    >>> disturbance_from_arrays(t, np.arange(20.0))
    Traceback (most recent call last):
    synth.errors.DataError: arrays: column 'time': time is not strictly increasing at sample 5 (t = 4 s)
    """
    tt, cols, notes = uniform_columns({time_name: t, name: x}, time_name, source, min_samples=16)
    xx = cols[name]
    if np.ptp(xx) == 0:
        raise DataError(f"column '{name}': the signal is constant ({xx[0]:g}); it has no spectrum", where=source)
    return DisturbanceRecord(tt, xx, name, unit, source, notes)


def load_disturbance(path: str | Path, time: str | None, signal: str, unit: str = "",
                     dt: float | None = None) -> DisturbanceRecord:
    """Read one disturbance channel from a CSV or MAT file (see :func:`synth.data.record.read_columns`).

    Parameters
    ----------
    path : str or Path
    time : str or None
        Time column [s]; ``None`` with ``dt`` for a file without one.
    signal : str
        The measured channel.
    unit : str
        Its unit (labels and JSON).
    dt : float, optional
        Sample interval [s] when there is no time column.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "d.csv"
    >>> _ = p.write_text("t,speed\\n" + "".join(f"{k * 0.001},{(-1) ** k}\\n" for k in range(20)))
    >>> load_disturbance(p, "t", "sped")
    Traceback (most recent call last):
    synth.errors.DataError: ...d.csv: signal column 'sped' not found; did you mean 'speed'?
    """
    from synth.data.record import read_columns

    path = Path(path)
    columns = read_columns(path)
    for role, name in (("time", time), ("signal", signal)):
        if name is not None and name not in columns:
            close = difflib.get_close_matches(name, list(columns), n=1)
            hint = f"; did you mean '{close[0]}'?" if close else f"; columns are {', '.join(columns) or 'none'}"
            raise DataError(f"{role} column '{name}' not found{hint}", where=str(path))
    x = columns[signal]
    if time is None:
        if dt is None or not (np.isfinite(dt) and dt > 0):
            raise DataError("no time column given: give the sample interval dt > 0 s", where=str(path))
        t = np.arange(x.size) * float(dt)
    else:
        t = columns[time]
    return disturbance_from_arrays(t, x, signal, unit, str(path), time or "time")


def unit_squared(unit: str) -> str:
    """``unit^2`` written unambiguously (parentheses around a compound unit).

    Examples
    --------
    >>> unit_squared("rad/s"), unit_squared("V"), unit_squared("")
    ('(rad/s)^2', 'V^2', 'unit^2')
    """
    unit = unit or "unit"
    return f"({unit})^2" if any(c in unit for c in "/* ") else f"{unit}^2"


# ------------------------------------------------------------------------------------------ parts
@dataclass(frozen=True)
class Spike:
    """A narrow-band peak of the spectrum.

    Attributes
    ----------
    w : float
        Peak frequency [rad/s] (parabolic interpolation on the dB values of three bins).
    level_db : float
        PSD at the peak [dB re 1 unit^2/(rad/s)].
    height_db : float
        How far the peak stands above the running median [dB].
    power : float
        Power above the running median over the peak's bins [unit^2]; a sinusoid of amplitude
        ``A`` gives ``A^2/2``.

    Examples
    --------
    >>> Spike(200.0, -10.0, 25.0, 0.5).amplitude
    1.0
    """

    w: float
    level_db: float
    height_db: float
    power: float

    @property
    def amplitude(self) -> float:
        """Amplitude of the sinusoid with this power [unit]."""
        return float(np.sqrt(2.0 * max(self.power, 0.0)))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"w": self.w, "level_db": self.level_db, "height_db": self.height_db, "power": self.power,
                "amplitude": self.amplitude}


@dataclass(frozen=True)
class Trend:
    """Straight line of the PSD in dB against ``log10 w``.

    Attributes
    ----------
    band : tuple of float
        Frequencies fitted [rad/s].
    slope_db_per_decade : float
    level_db_at_1 : float
        Line at ``w = 1`` rad/s [dB].
    rms_residual_db : float
    points : int

    Examples
    --------
    >>> float(Trend((1.0, 100.0), -20.0, -10.0, 0.5, 50).value_db(10.0))
    -30.0
    """

    band: tuple[float, float]
    slope_db_per_decade: float
    level_db_at_1: float
    rms_residual_db: float
    points: int

    def value_db(self, w: float | np.ndarray) -> float | np.ndarray:
        """Trend line at ``w`` [dB]."""
        return self.level_db_at_1 + self.slope_db_per_decade * np.log10(w)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"band": list(self.band), "slope_db_per_decade": self.slope_db_per_decade,
                "level_db_at_1_rad_s": self.level_db_at_1, "rms_residual_db": self.rms_residual_db,
                "points": self.points}


def welch_psd(signals: Sequence[np.ndarray], dt: float, segment: float | None = None,
              w_min: float | None = None, detrend: str = "constant") -> tuple[np.ndarray, np.ndarray, int]:
    """One-sided Welch PSD [unit^2/(rad/s)] on ``w`` [rad/s] of one or several signals, averaged.

    Parameters
    ----------
    signals : sequence of numpy.ndarray
        Signals with the sample interval ``dt``.
    dt : float
        Sample interval [s].
    segment : float, optional
        Segment length [s]. Default: long enough that the bin spacing is half of ``w_min``
        (``4 pi / w_min``), or an eighth of the shortest signal.
    w_min : float, optional
        Lowest frequency of interest [rad/s].
    detrend : {"constant", "linear"}
        What is removed from each segment.

    Returns
    -------
    w : numpy.ndarray
        Frequencies [rad/s], DC left out.
    S : numpy.ndarray
        PSD [unit^2/(rad/s)].
    segments : int
        Number of segments averaged over all signals.

    Raises
    ------
    DataError
        A signal shorter than one segment (too short for ``w_min``).

    Examples
    --------
    >>> x = np.random.default_rng(0).normal(size=40000)
    >>> w, S, k = welch_psd([x], 0.001)
    >>> round(float(np.mean(S) * np.pi / 0.001), 2)  # white noise of variance 1: S = dt/pi
    1.0
    """
    if detrend not in ("constant", "linear"):
        raise DataError(f"detrend must be 'constant' or 'linear', got {detrend!r}", where="psd")
    shortest = min(np.asarray(x).size for x in signals)
    if segment is not None:
        nper = round(segment / dt)
    elif w_min is not None:
        nper = int(np.ceil(4 * np.pi / (w_min * dt)))
    else:
        nper = max(16, shortest // 8)
    if nper < 8:
        raise DataError(f"segment of {nper} samples is too short; give a longer segment", where="psd")
    if shortest < nper:
        need = nper * dt
        what = f"the lowest frequency {w_min:g} rad/s needs" if w_min is not None and segment is None else "needs"
        raise DataError(f"a record holds {shortest} samples ({shortest * dt:.4g} s); {what} segments of "
                        f"{need:.4g} s", where="psd")
    total, count = None, 0
    for x in signals:
        x = np.asarray(x, float)
        f, p = sps.welch(x, fs=1.0 / dt, window="hann", nperseg=nper, noverlap=nper // 2, detrend=detrend,
                         scaling="density")
        k = 1 + (x.size - nper) // (nper - nper // 2)
        total = p * k if total is None else total + p * k
        count += k
    S = total / count / (2 * np.pi)
    return 2 * np.pi * f[1:], S[1:], count


def _effective_dof(segments: int) -> float:
    c2 = _HANN_OVERLAP_CORRELATION**2
    return 2.0 * segments / (1.0 + 2.0 * c2 * (segments - 1) / max(segments, 1))


def running_median_db(S: np.ndarray, min_half: int = 8, fraction: float = 0.05) -> np.ndarray:
    """Running median of ``10 log10 S``: symmetric window of +-max(``min_half``, ``fraction`` k) bins.

    The window shrinks symmetrically at the ends, so a monotonic spectrum is its own median.

    Examples
    --------
    >>> s = np.ones(50); s[25] = 1000.0
    >>> float(running_median_db(s)[25])
    0.0
    """
    db = 10 * np.log10(np.maximum(S, np.finfo(float).tiny))
    n = db.size
    out = np.empty(n)
    for k in range(n):
        h = min(max(min_half, int(fraction * (k + 1))), k, n - 1 - k)
        out[k] = np.median(db[k - h:k + h + 1])
    return out


def find_spikes(w: np.ndarray, S: np.ndarray, threshold_db: float = 10.0,
                median_db: np.ndarray | None = None) -> tuple[list[Spike], np.ndarray]:
    """Narrow-band peaks standing more than ``threshold_db`` above the running median.

    Returns the spikes and a boolean mask of the bins they occupy (each spike's bins extend from
    its peak while they stand more than 3 dB above the median).

    Examples
    --------
    >>> w = np.arange(1, 201) * 1.0; S = np.ones(200); S[99] = 100.0
    >>> spikes, mask = find_spikes(w, S)
    >>> [(float(s.w), round(s.height_db)) for s in spikes], int(mask.sum())
    ([(100.0, 20)], 1)
    """
    db = 10 * np.log10(np.maximum(S, np.finfo(float).tiny))
    med = running_median_db(S) if median_db is None else median_db
    excess = db - med
    mask = np.zeros(S.size, bool)
    spikes: list[Spike] = []
    dw = float(np.median(np.diff(w))) if w.size > 1 else 1.0
    above = excess > threshold_db
    k = 1
    while k < S.size - 1:
        if not above[k]:
            k += 1
            continue
        j = k
        while j + 1 < S.size and above[j + 1]:
            j += 1
        peak = k + int(np.argmax(db[k:j + 1]))
        lo, hi = peak, peak
        while lo > 0 and excess[lo - 1] > 3.0:
            lo -= 1
        while hi < S.size - 1 and excess[hi + 1] > 3.0:
            hi += 1
        wp = float(w[peak])
        if 0 < peak < S.size - 1:
            a, b, c = db[peak - 1], db[peak], db[peak + 1]
            denom = a - 2 * b + c
            if denom < 0:
                wp += 0.5 * (a - c) / denom * dw
        power = float(np.sum(S[lo:hi + 1] - 10 ** (med[lo:hi + 1] / 10)) * dw)
        spikes.append(Spike(float(wp), float(db[peak]), float(excess[peak]), power))
        mask[lo:hi + 1] = True
        k = max(j, hi) + 1
    return spikes, mask


def fit_trend(w: np.ndarray, S: np.ndarray, band: tuple[float, float], exclude: np.ndarray | None = None) -> Trend:
    """Least-squares line of ``10 log10 S`` against ``log10 w`` on ``band``, equal weight per decade.

    Bins are uniformly spaced in ``w``, so each gets the weight ``1/w`` (its width in ``log w``);
    an unweighted fit would let the top decade decide.

    Raises
    ------
    DataError
        Fewer than 3 bins in the band.

    Examples
    --------
    >>> w = np.arange(1.0, 1001.0)
    >>> round(fit_trend(w, 1 / w**2, (1.0, 1000.0)).slope_db_per_decade, 6)
    -20.0
    """
    sel = (w >= band[0]) & (w <= band[1])
    if exclude is not None:
        sel &= ~exclude
    n = int(np.count_nonzero(sel))
    if n < 3:
        raise DataError(f"only {n} bin(s) between {band[0]:.4g} and {band[1]:.4g} rad/s; the trend needs 3",
                        where="psd: band")
    x = np.log10(w[sel])
    y = 10 * np.log10(np.maximum(S[sel], np.finfo(float).tiny))
    sw = np.sqrt(1.0 / w[sel])
    A = np.column_stack([np.ones(n), x])
    coef, *_ = np.linalg.lstsq(A * sw[:, None], y * sw, rcond=None)
    resid = y - A @ coef
    return Trend((float(band[0]), float(band[1])), float(coef[1]), float(coef[0]),
                 float(np.sqrt(np.average(resid**2, weights=sw**2))), n)


def noise_floor(w: np.ndarray, S: np.ndarray, segments: int, band: tuple[float, float] | None = None,
                exclude: np.ndarray | None = None) -> tuple[float, tuple[float, float]]:
    """Mean PSD level of a flat noise floor, estimated robustly as a bias-corrected median.

    The median of ``S`` over ``band`` (default: the upper half of the frequency axis; bins in
    ``exclude`` left out) is divided by the median of ``chi2(nu)/nu``, ``nu`` the estimate's
    degrees of freedom for ``segments`` 50 %-overlapped Hann segments.

    Returns the floor [unit^2/(rad/s)] and the band used.

    Examples
    --------
    >>> x = np.random.default_rng(1).normal(size=100000)
    >>> w, S, k = welch_psd([x], 0.001)
    >>> floor, band = noise_floor(w, S, k)
    >>> round(floor * np.pi / 0.001, 2)
    1.0
    """
    band = band or (float(w[-1]) / 2, float(w[-1]))
    sel = (w >= band[0]) & (w <= band[1])
    if exclude is not None and np.count_nonzero(sel & ~exclude) >= 3:
        sel &= ~exclude
    if np.count_nonzero(sel) < 3:
        raise DataError(f"fewer than 3 bins between {band[0]:.4g} and {band[1]:.4g} rad/s for the noise floor",
                        where="psd: floor band")
    nu = _effective_dof(segments)
    return float(np.median(S[sel]) / (chi2.median(nu) / nu)), (float(band[0]), float(band[1]))


def share_frequency(w: np.ndarray, D: np.ndarray, share: float) -> float:
    """Frequency below which ``share`` of the power of density ``D`` lies (first crossing, interpolated).

    Each bin covers ``w_k +- dw/2``; ``D`` may be negative in places (floor subtracted, not clipped).

    Examples
    --------
    >>> w = np.arange(1.0, 101.0)
    >>> share_frequency(w, np.ones(100), 0.9)
    90.5
    """
    if not 0 < share < 1:
        raise DataError(f"share must lie strictly between 0 and 1, got {share!r}", where="psd: share")
    dw = float(np.median(np.diff(w)))
    cum = np.cumsum(D) * dw
    total = cum[-1]
    if not total > 0:
        raise DataError("no disturbance power above the noise floor", where="psd")
    target = share * total
    k = int(np.argmax(cum >= target))
    prev = cum[k - 1] if k > 0 else 0.0
    upper = w[k] + dw / 2
    return float(upper - dw + dw * (target - prev) / (cum[k] - prev))


# ----------------------------------------------------------------------------------------- result
@dataclass(frozen=True)
class PsdAnalysis:
    """A disturbance spectrum and what it says (see the module text for every definition).

    Attributes
    ----------
    w, psd : numpy.ndarray
        Frequencies [rad/s] and one-sided PSD [unit^2/(rad/s)] (left out of ``to_dict`` unless asked).
    unit : str
        Unit of the signal.
    records : int
        Signals averaged.
    segments : int
        Welch segments averaged in all.
    segment_length, resolution : float
        Segment length [s] and bin spacing [rad/s].
    floor : float
        Noise floor [unit^2/(rad/s)].
    floor_band : tuple of float
        Where the floor was measured [rad/s].
    floor_source : str
        ``"median of the upper half"``, ``"median of the floor band"`` or ``"noise record"``.
    trend : Trend or None
    spikes : tuple of Spike
    share : float
        Chosen share of the disturbance power.
    share_frequency : float
        Frequency below which that share lies, spikes left out [rad/s].
    share_frequency_with_spikes : float
        The same with the spikes counted [rad/s].
    total_power, disturbance_power : float
        Mean square of the signals and the part above the floor [unit^2].
    notes : tuple of str

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> a = analyze_psd([rng.normal(size=20000)], 0.001, spike_db=15)
    >>> round(a.floor_db, 1), a.spikes
    (-35.0, ())
    """

    w: np.ndarray = field(repr=False)
    psd: np.ndarray = field(repr=False)
    unit: str
    records: int
    segments: int
    segment_length: float
    resolution: float
    floor: float
    floor_band: tuple[float, float]
    floor_source: str
    trend: Trend | None
    spikes: tuple[Spike, ...]
    share: float
    share_frequency: float | None
    share_frequency_with_spikes: float | None
    total_power: float
    disturbance_power: float
    notes: tuple[str, ...] = ()

    @property
    def psd_db(self) -> np.ndarray:
        """PSD in dB re 1 unit^2/(rad/s)."""
        return 10 * np.log10(np.maximum(self.psd, np.finfo(float).tiny))

    @property
    def floor_db(self) -> float:
        """Noise floor in dB re 1 unit^2/(rad/s)."""
        return float(10 * np.log10(self.floor))

    def to_dict(self, curves: bool = False) -> dict[str, Any]:
        """JSON-ready form; ``curves=True`` adds ``w``, ``psd`` and ``psd_db``."""
        sq = unit_squared(self.unit)
        u = f"{sq}/(rad/s)"
        out: dict[str, Any] = {
            "records": self.records, "segments": self.segments, "segment_length": self.segment_length,
            "resolution": self.resolution, "floor": self.floor, "floor_db": self.floor_db,
            "floor_band": list(self.floor_band), "floor_source": self.floor_source,
            "trend": self.trend.to_dict() if self.trend else None,
            "spikes": [s.to_dict() for s in self.spikes], "share": self.share,
            "share_frequency": self.share_frequency, "share_frequency_with_spikes": self.share_frequency_with_spikes,
            "total_power": self.total_power, "disturbance_power": self.disturbance_power,
            "units": {"w": "rad/s", "psd": u, "psd_db": f"dB re 1 {u}", "segment_length": "s",
                      "resolution": "rad/s", "power": sq, "share_frequency": "rad/s"},
            "notes": list(self.notes),
        }
        if curves:
            out["curves"] = {"w": self.w, "psd": self.psd, "psd_db": self.psd_db}
        return out


def analyze_psd(signals: Sequence[np.ndarray], dt: float, share: float = 0.9, band: tuple[float, float] | None = None,
                segment: float | None = None, w_min: float | None = None, floor_band: tuple[float, float] | None = None,
                noise: Sequence[np.ndarray] | None = None, spike_db: float = 10.0, detrend: str = "constant",
                unit: str = "") -> PsdAnalysis:
    """Welch PSD of one or several disturbance records with trend, floor, spikes and power share.

    Parameters
    ----------
    signals : sequence of numpy.ndarray
        Disturbance records, all sampled every ``dt`` seconds.
    dt : float
        Sample interval [s].
    share : float
        Share of the disturbance power (above the floor) for ``share_frequency``.
    band : tuple of float, optional
        Trend band [rad/s]; default from the lowest bin to the knee (the running median within
        3 dB of the floor).
    segment, w_min : float, optional
        Welch segment length [s] or the lowest frequency of interest [rad/s] (see :func:`welch_psd`).
    floor_band : tuple of float, optional
        Band where the spectrum is flat noise [rad/s]; default the upper half of the axis.
    noise : sequence of numpy.ndarray, optional
        Noise-only records (sensor noise test); their PSD's level over ``floor_band`` is the floor.
    spike_db : float
        How far above the running median a peak must stand to count as a spike [dB].
    detrend : {"constant", "linear"}
    unit : str
        Unit of the signal.

    Returns
    -------
    PsdAnalysis

    Examples
    --------
    >>> t = np.arange(0, 60, 0.001)
    >>> x = np.sin(200 * t) + 0.01 * np.random.default_rng(2).normal(size=t.size)
    >>> a = analyze_psd([x], 0.001)
    >>> round(a.spikes[0].w), round(a.spikes[0].amplitude, 2)
    (200, 1.0)
    """
    if not (np.isfinite(dt) and dt > 0):
        raise DataError(f"dt must be > 0 s, got {dt!r}", where="psd")
    if not 0 < share < 1:
        raise DataError(f"share must lie strictly between 0 and 1, got {share!r}", where="psd: share")
    for name, b in (("band", band), ("floor band", floor_band)):
        if b is not None and not (len(b) == 2 and 0 <= b[0] < b[1]):
            raise DataError(f"expected two increasing frequencies >= 0 rad/s, got {list(b)}", where=f"psd: {name}")
    if w_min is not None and not (np.isfinite(w_min) and w_min > 0):
        raise DataError(f"w_min must be > 0 rad/s, got {w_min!r}", where="psd")
    notes: list[str] = []
    w, S, k = welch_psd(signals, dt, segment, w_min, detrend)
    dw = float(w[1] - w[0])
    median = running_median_db(S)
    spikes, mask = find_spikes(w, S, spike_db, median)
    if noise:
        wn, Sn, kn = welch_psd(noise, dt, 2 * np.pi / dw * 1.0, None, detrend)
        floor, fband = noise_floor(wn, Sn, kn, floor_band or (float(wn[0]), float(wn[-1])))
        source = "noise record"
    else:
        floor, fband = noise_floor(w, S, k, floor_band, mask)
        source = "median of the floor band" if floor_band else "median of the upper half"
        sel = (w >= fband[0]) & (w <= fband[1]) & ~mask
        if np.count_nonzero(sel) >= 3:
            flat = fit_trend(w, S, fband, mask)
            if abs(flat.slope_db_per_decade) > 6.0:
                notes.append(f"the spectrum is not flat in the floor band ({flat.slope_db_per_decade:+.1f} dB/decade): "
                             "the floor is an upper bound; give a noise record or a floor band")
    floor_db = 10 * np.log10(floor)
    if band is None:
        below = np.flatnonzero(median <= floor_db + KNEE_DB)
        knee = float(w[below[0]]) if below.size else float(w[-1])
        band = (float(w[0]), max(knee, float(w[min(2, w.size - 1)])))
        notes.append(f"trend band {band[0]:.4g}-{band[1]:.4g} rad/s: from the lowest bin to where the running "
                     f"median comes within {KNEE_DB:g} dB of the floor")
    try:
        trend: Trend | None = fit_trend(w, S, band, mask)
    except DataError as exc:
        trend = None
        notes.append(f"no trend: {exc.message}")
    smooth = np.where(mask, 10 ** (median / 10) / (chi2.median(_effective_dof(k)) / _effective_dof(k)), S)
    total = float(np.sum(S) * dw)
    disturbance = float(np.sum(smooth - floor) * dw)
    try:
        wf = share_frequency(w, smooth - floor, share)
        wf_spikes = share_frequency(w, S - floor, share)
    except DataError as exc:
        wf = wf_spikes = None
        notes.append(f"no share frequency: {exc.message}")
    return PsdAnalysis(w, S, unit, len(signals), k, (2 * np.pi / dw), dw, floor, fband, source, trend, tuple(spikes),
                       share, wf, wf_spikes, total, disturbance, tuple(notes))


@dataclass(frozen=True)
class BandwidthSuggestion:
    """A closed-loop bandwidth requirement derived from a disturbance spectrum.

    Rule: feedback attenuates a disturbance only below the loop's bandwidth, so the closed-loop
    bandwidth must reach ``factor`` times the frequency below which ``share`` of the disturbance
    power lies (narrow-band spikes left out: they call for a notch or a filter, not bandwidth).

    Examples
    --------
    >>> BandwidthSuggestion(0.9, 62.0, 1.0, 62.0).spec_entry()
    {'type': 'bandwidth', 'min': 62.0}
    """

    share: float
    share_frequency: float
    factor: float
    min_bandwidth: float

    def spec_entry(self) -> dict[str, Any]:
        """The requirement as a spec-file entry (``docs/spec-format.md``)."""
        return {"type": "bandwidth", "min": float(f"{self.min_bandwidth:.3g}")}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"share": self.share, "share_frequency": self.share_frequency, "factor": self.factor,
                "min_bandwidth": self.min_bandwidth, "spec_entry": self.spec_entry(),
                "rule": f"closed-loop bandwidth >= {self.factor:g} x the frequency below which "
                        f"{100 * self.share:g} % of the disturbance power (above the noise floor, spikes left out) lies"}


def suggest_bandwidth(analysis: PsdAnalysis, factor: float = 1.0) -> BandwidthSuggestion:
    """Turn the share frequency of a spectrum into a minimum closed-loop bandwidth (rule above).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> from scipy.signal import lfilter
    >>> x = lfilter([0.05], [1, -0.95], rng.normal(size=60000))   # first-order low-pass, ~51 rad/s corner
    >>> s = suggest_bandwidth(analyze_psd([x], 0.001))
    >>> s.spec_entry()["type"], 100 < s.min_bandwidth < 2000
    ('bandwidth', True)
    """
    if not (np.isfinite(factor) and factor > 0):
        raise DataError(f"factor must be > 0, got {factor!r}", where="psd: bandwidth factor")
    if analysis.share_frequency is None:
        raise DataError("the spectrum has no disturbance power above its noise floor; no bandwidth follows from it",
                        where="psd")
    return BandwidthSuggestion(analysis.share, analysis.share_frequency, factor, factor * analysis.share_frequency)


def analyze_records(records: Sequence[DisturbanceRecord], noise: Sequence[DisturbanceRecord] = (),
                    **options: Any) -> PsdAnalysis:
    """:func:`analyze_psd` of loaded records, after checking they share one sample interval.

    Parameters
    ----------
    records : sequence of DisturbanceRecord
    noise : sequence of DisturbanceRecord
        Noise-only records for the floor.
    **options
        Passed to :func:`analyze_psd` (``share``, ``band``, ``w_min``, ...).

    Examples
    --------
    >>> t = np.arange(0, 2, 0.001)
    >>> a = disturbance_from_arrays(t, np.sin(50 * t)); b = disturbance_from_arrays(t[::2], np.cos(50 * t[::2]))
    >>> analyze_records([a, b])
    Traceback (most recent call last):
    synth.errors.DataError: arrays: sample interval 0.002 s differs from the 0.001 s of arrays; resample first
    """
    if not records:
        raise DataError("give at least one record", where="psd")
    everything = [*records, *noise]
    dt0 = everything[0].dt
    for r in everything[1:]:
        if abs(r.dt - dt0) > 1e-6 * dt0:
            raise DataError(f"sample interval {r.dt:g} s differs from the {dt0:g} s of {everything[0].source}; "
                            "resample first", where=r.source)
    unit = options.pop("unit", records[0].unit)
    result = analyze_psd([r.x for r in records], dt0, noise=[r.x for r in noise] or None, unit=unit, **options)
    notes = tuple(f"{r.source}: {n}" for r in everything for n in r.notes)
    return PsdAnalysis(**{**result.__dict__, "notes": notes + result.notes})
