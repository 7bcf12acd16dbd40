"""Disturbance and noise spectra (seed 1, section 5): Welch PSD, trend, floor, spikes, power share.

The estimate is :func:`synth.ident.welch.welch_psd` (one-sided, ``unit^2/(rad/s)`` on ``w`` in
rad/s); floor, spikes, trend and share frequency are defined in :mod:`synth.ident.spectrum_features`;
the bandwidth requirement that follows in :mod:`synth.ident.bandwidth_suggestion`. Here they are
put together:

- **Noise floor**: given a noise record (the seed's "sensor noise test", motor stopped), its PSD is
  used instead of the upper half of the axis. When the spectrum still falls across the floor band
  the floor is an upper bound, and the notes say so.
- **Trend band** (default): from the lowest bin to where the running median first comes within
  3 dB of the floor.
- **Share frequency**: the disturbance power density is ``S - floor`` (not clipped, so noise-only
  bins add nothing on average), spikes replaced by the running median.
- **Evidence for a requirement**: a Welch bin's estimate scatters as ``S chi2(nu)/nu`` (``nu`` the
  degrees of freedom of the averaged segments), so on a pure floor the power above the floor,
  ``sum(S - floor) dw``, scatters about zero with the standard deviation
  :attr:`PsdAnalysis.disturbance_power_scatter` (the bins' own scatter, adjacent Hann bins correlated,
  plus the floor estimate's, a median over its band). Power above the floor below
  ``SIGNIFICANCE_Z`` of these (false-alarm rate :data:`FALSE_ALARM_RATE` per record) is what the
  estimate's scatter explains: no share frequency and no bandwidth requirement follow from it. With
  fewer than :data:`MIN_SEGMENTS` segments averaged the spectrum is too rough for a requirement at all:
  the suggestion is "undetermined".
- **Uneven time stamps** (:func:`synth.ident.psd_stamps.load_psd_record`): stamps jittering around a uniform grid are used as
  they are on that grid (interpolation would low-pass the spectrum); otherwise the linear interpolation
  is kept and its attenuation stated; the variance of the raw samples is reported either way. A record is split
  at gaps of its stamps (:func:`synth.ident.psd_stamps.load_psd_records`, :data:`~synth.ident.psd_stamps.GAP_FACTOR`
  intervals or more) and its pieces averaged as records; where tones interpolated across dropped stamps spread
  at least half the power above the floor over the band (:func:`analyze_records`), no suggestion is made.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.data.disturbance import DisturbanceRecord
from synth.distributions import chi2_median, chi2_sf, norm_ppf
from synth.errors import DataError
from synth.ident.spectrum_features import (
    Spike,
    Trend,
    find_spikes,
    fit_trend,
    noise_floor,
    running_median_db,
    share_frequency,
)
from synth.ident.welch import effective_dof, unit_squared, welch_psd

__all__ = ["FALSE_ALARM_RATE", "KNEE_DB", "MIN_SEGMENTS", "RESOLVED_SHARE", "PsdAnalysis", "analyze_psd",
           "analyze_records", "check_band", "mean_square"]

#: the trend band ends where the running median comes within this many dB of the floor
KNEE_DB = 3.0
#: fewer Welch segments than this (fewer than about 7.7 degrees of freedom, each bin's estimate spread over
#: a factor of 6 for 90 % of its chi-square distribution) give no requirement: "undetermined"
MIN_SEGMENTS = 4
#: a signal whose values vary by less than this: its power (the square, times a sample interval) underflows
TINY_SPREAD = 1e-140
#: probability that a pure noise floor's power above the floor passes as a disturbance (one-sided)
FALSE_ALARM_RATE = 1e-3
#: the same as a number of standard deviations of the above-floor power (normal approximation)
SIGNIFICANCE_Z = float(norm_ppf(1.0 - FALSE_ALARM_RATE))
#: variance of a sum of Hann-windowed periodogram bins over the sum of their variances: the squared correlation
#: of adjacent bins' Fourier coefficients is (2/3)^2, of bins two apart (1/6)^2
_HANN_BIN_VARIANCE_FACTOR = 1.0 + 2.0 * (2.0 / 3.0) ** 2 + 2.0 * (1.0 / 6.0) ** 2


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
        Mean square of the signals (the spectrum's integral) and the part above the floor [unit^2].
    disturbance_power_scatter : float
        Standard deviation of ``disturbance_power`` on a pure noise floor [unit^2] (module text).
    suggestion_withheld : str or None
        Why no bandwidth requirement follows from the spectrum (too few segments, or power above the
        floor within the estimate's scatter); None when one does.
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
    disturbance_power_scatter: float = 0.0
    suggestion_withheld: str | None = None

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
            "disturbance_power_scatter": self.disturbance_power_scatter,
            "significance": {"false_alarm_rate": FALSE_ALARM_RATE, "z": SIGNIFICANCE_Z,
                             "min_segments": MIN_SEGMENTS},
            "suggestion_withheld": self.suggestion_withheld,
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
        if b is not None:
            check_band(b, dt, f"psd: {name}")
    if w_min is not None and not (np.isfinite(w_min) and w_min > 0):
        raise DataError(f"w_min must be > 0 rad/s, got {w_min!r}", where="psd")
    if not (math.isfinite(spike_db) and spike_db > 0):
        raise DataError(f"must be a finite number of dB > 0, got {spike_db!r}", where="psd: spike_db")
    notes: list[str] = []
    w, S, k = welch_psd(signals, dt, segment, w_min, detrend)
    dw = float(w[1] - w[0])
    median = running_median_db(S)
    spikes, mask = find_spikes(w, S, spike_db, median)
    if noise:
        try:
            wn, Sn, kn = welch_psd(noise, dt, 2 * np.pi / dw * 1.0, None, detrend)
        except DataError as exc:  # its segments are the records' (the same bins)
            raise DataError(f"the noise record is shorter than one segment of the records' spectrum: {exc.message}",
                            where="--noise-data") from None
        floor, fband = noise_floor(wn, Sn, kn, floor_band or (float(wn[0]), float(wn[-1])))
        source = "noise record"
        floor_bins, floor_segments = int(np.count_nonzero((wn >= fband[0]) & (wn <= fband[1]))), kn
    else:
        floor, fband = noise_floor(w, S, k, floor_band, mask)
        floor_bins, floor_segments = int(np.count_nonzero((w >= fband[0]) & (w <= fband[1]))), k
        source = "median of the floor band" if floor_band else "median of the upper half"
        sel = (w >= fband[0]) & (w <= fband[1]) & ~mask
        if np.count_nonzero(sel) >= 3:
            flat = fit_trend(w, S, fband, mask)
            if abs(flat.slope_db_per_decade) > 6.0:
                notes.append(f"the spectrum is not flat in the floor band ({flat.slope_db_per_decade:+.1f} dB/decade): "
                             "the floor is an upper bound; give a noise record or a floor band")
    floor_db = 10 * np.log10(floor)
    at_floor = False
    if band is None:
        below = np.flatnonzero(median <= floor_db + KNEE_DB)
        knee = float(w[below[0]]) if below.size else float(w[-1])
        at_floor = bool(below.size) and below[0] < 3
        band = (float(w[0]), max(knee, float(w[min(2, w.size - 1)])))
        if not at_floor:
            notes.append(f"trend band {band[0]:.4g}-{band[1]:.4g} rad/s: from the lowest bin to where the running "
                         f"median comes within {KNEE_DB:g} dB of the floor")
    trend: Trend | None = None
    if at_floor:  # a slope through the first bins of a flat spectrum is their scatter, not a trend
        notes.append(f"no trend: the running median is within {KNEE_DB:g} dB of the floor from the lowest bins on "
                     "(the spectrum is at its floor)")
    else:
        try:
            trend = fit_trend(w, S, band, mask)
        except DataError as exc:
            notes.append(f"no trend: {exc.message}")
    smooth = np.where(mask, 10 ** (median / 10) / (chi2_median(effective_dof(k)) / effective_dof(k)), S)
    total = float(np.sum(S) * dw)
    disturbance = float(np.sum(smooth - floor) * dw)
    scatter = _above_floor_scatter(floor, dw, w.size, k, floor_bins, floor_segments, source != "noise record")
    withheld: str | None = None
    wf = wf_spikes = None
    sq = unit_squared(unit)
    if disturbance <= SIGNIFICANCE_Z * scatter:
        broadband = "the broadband power above the floor (spikes left out)" if spikes else "the power above the floor"
        withheld = (f"not significant: {broadband}, {disturbance:.3g} {sq} "
                    f"({100 * disturbance / total:.2g} % of the mean square), is within the scatter of the Welch "
                    f"estimate ({SIGNIFICANCE_Z:.2f} sigma = {SIGNIFICANCE_Z * scatter:.3g} {sq}, chi-square with "
                    f"{effective_dof(k):.3g} degrees of freedom per bin; false-alarm rate {100 * FALSE_ALARM_RATE:g} %)")
        if spikes:  # a tone far above the floor is significant: say what it carries, and where the power lies with it
            tones = float(np.sum((S - smooth)[mask]) * dw)
            withheld += (f"; the {len(spikes)} spike(s) carry {tones:.3g} {sq} ({100 * tones / total:.3g} % of the "
                         "mean square): tones, listed with their amplitudes, which a loop rejects only with its "
                         "bandwidth above them (or a notch)")
            with contextlib.suppress(DataError):
                wf_spikes = share_frequency(w, S - floor, share)
        notes.append(f"no share frequency and no bandwidth requirement: {withheld}")
    else:
        try:
            wf = share_frequency(w, smooth - floor, share)
            wf_spikes = share_frequency(w, S - floor, share)
        except DataError as exc:
            withheld = f"none: {exc.message}"
            notes.append(f"no share frequency: {exc.message}")
    resolved = total / mean_square(signals, detrend)
    if resolved < RESOLVED_SHARE:
        notes.append(f"the bins from {w[0]:.4g} rad/s up hold {100 * resolved:.3g} % of the records' mean square "
                     f"(after removing each record's {detrend} trend): the rest is slower than one segment "
                     f"({2 * np.pi / dw:.4g} s); the share frequency and the power above the floor count the resolved "
                     "part only (a longer --segment resolves more)")
    if k < MIN_SEGMENTS:
        withheld = f"undetermined: {k} segments averaged, need >= {MIN_SEGMENTS}"
        notes.append(f"{withheld} (each bin's estimate is chi-square with {effective_dof(k):.3g} degrees of freedom: "
                     "a longer record, or a shorter --segment, gives more)")
    return PsdAnalysis(w, S, unit, len(signals), k, (2 * np.pi / dw), dw, floor, fband, source, trend, tuple(spikes),
                       share, wf, wf_spikes, total, disturbance, tuple(notes), scatter, withheld)


RESOLVED_SHARE = 0.8
"""Below this share of the records' mean square in the Welch bins, a note says how much lies below the lowest bin (a
DC motor's speed: 34 % resolved by the default 0.65 s segments, its 90 % share frequency counting that third only)."""


def mean_square(signals: Sequence[np.ndarray], detrend: str) -> float:
    """Mean square of the records, each with its mean (``"constant"``) or straight line (``"linear"``) removed.

    Examples
    --------
    >>> round(mean_square([np.array([1.0, 3.0, 1.0, 3.0])], "constant"), 6)
    1.0
    """
    from scipy.signal import detrend as remove_trend

    values = np.concatenate([remove_trend(np.asarray(x, float), type=detrend) if detrend in ("constant", "linear")
                             else np.asarray(x, float) for x in signals])
    return float(np.mean(values**2))


def _chi2_over_nu_pdf(x: float, nu: float) -> float:
    """Density of ``chi2(nu)/nu`` at ``x > 0``."""
    y, h = nu * x, nu / 2.0
    return nu * math.exp((h - 1.0) * math.log(y) - y / 2.0 - h * math.log(2.0) - math.lgamma(h))


def _above_floor_scatter(floor: float, dw: float, bins: int, segments: int, floor_bins: int,
                         floor_segments: int, overlap: bool) -> float:
    """Standard deviation [unit^2] of ``sum(S - floor) dw`` over ``bins`` bins when ``S`` is the floor alone.

    In units of the floor, each bin's estimate is ``X = chi2(nu)/nu`` (variance ``2/nu``); the floor is the
    median ``M`` of ``floor_bins`` such bins over the median ``m`` of ``chi2/nu`` (asymptotic variance
    ``1 / (4 n f(m)^2)``, ``f`` the density). When the floor band lies in the summed bins (``overlap``) the
    two covary: ``Cov(sum over the band of X, M) = (1/2 - F_{nu+2}(nu m)) / f(m)`` (the asymptotic
    covariance of a sum and a median, ``E[X 1{X < m}] = F_{nu+2}(nu m)`` for chi-square). Sums over
    adjacent Hann bins are correlated: every term is scaled by :data:`_HANN_BIN_VARIANCE_FACTOR`.

    Examples
    --------
    >>> round(_above_floor_scatter(1.0, 1.0, 100, 40, 50, 40, True) / 100, 3)  # 100 bins, 40 segments
    0.033
    """
    c = _HANN_BIN_VARIANCE_FACTOR
    nu, nu_f, n_f = effective_dof(segments), effective_dof(floor_segments), max(floor_bins, 1)
    m = float(chi2_median(nu_f)) / nu_f
    f = _chi2_over_nu_pdf(m, nu_f)
    var = 2.0 * bins / nu + bins**2 / (4.0 * n_f * (f * m) ** 2)
    if overlap:
        cov_band_median = (float(chi2_sf(nu_f * m, nu_f + 2.0)) - 0.5) / f
        var -= 2.0 * bins * cov_band_median / m
    return float(floor * dw * math.sqrt(c * max(var, 2.0 * bins / nu * 0.1)))


def check_band(band: Sequence[float], dt: float, where: str) -> tuple[float, float]:
    """A frequency band [rad/s]: two finite increasing frequencies > 0, the upper at most Nyquist (``pi/dt``).

    Raises
    ------
    DataError
        One line at ``where`` saying what is wrong (the Nyquist frequency named in rad/s).

    Examples
    --------
    >>> check_band((10.0, 300.0), 0.01, "--band")
    (10.0, 300.0)
    >>> check_band((10.0, 1000.0), 0.01, "--band")
    Traceback (most recent call last):
    synth.errors.DataError: --band: upper end 1000 rad/s is past the Nyquist frequency 314.2 rad/s (pi/dt, dt = 0.01 s)
    """
    vals = [float(v) for v in band]
    shown = " ".join(f"{v:g}" for v in vals)
    if len(vals) != 2 or not all(math.isfinite(v) and v > 0 for v in vals) or not vals[0] < vals[1]:
        raise DataError(f"expected two increasing frequencies (each must be > 0 rad/s), got {shown}", where=where)
    nyquist = math.pi / dt
    if vals[0] >= nyquist:
        raise DataError(f"{shown.replace(' ', '-')} rad/s lies wholly above the Nyquist frequency {nyquist:.8g} rad/s "
                        f"(pi/dt, dt = {dt:g} s)", where=where)
    if vals[1] > nyquist * (1 + 1e-6):
        raise DataError(f"upper end {vals[1]:.8g} rad/s is past the Nyquist frequency {nyquist:.8g} rad/s "
                        f"(pi/dt, dt = {dt:g} s)", where=where)
    return vals[0], vals[1]

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
    >>> from synth.data.disturbance import disturbance_from_arrays
    >>> t = np.arange(0, 2, 0.001)
    >>> a = disturbance_from_arrays(t, np.sin(50 * t)); b = disturbance_from_arrays(t[::2], np.cos(50 * t[::2]))
    >>> analyze_records([a, b])
    Traceback (most recent call last):
    synth.errors.DataError: arrays: sample interval 0.002 s differs from the 0.001 s of arrays; resample first
    >>> analyze_records([disturbance_from_arrays(t, 1e300 * np.sin(50 * t))])
    Traceback (most recent call last):
    synth.errors.DataError: arrays: column 'y': values up to 1e+300 overflow its power spectrum; rescale the signal
    """
    if not records:
        raise DataError("give at least one record", where="psd")
    everything = [*records, *noise]
    dt0 = everything[0].dt
    for r in everything[1:]:
        if abs(r.dt - dt0) > 1e-6 * dt0:
            raise DataError(f"sample interval {r.dt:g} s differs from the {dt0:g} s of {everything[0].source}; "
                            "resample first", where=r.source)
    for r in everything:
        with np.errstate(over="ignore", invalid="ignore"):
            power = float(np.sum((r.x - np.mean(r.x)) ** 2))
        if not np.isfinite(power):
            raise DataError(f"column '{r.name}': values up to {float(np.max(np.abs(r.x))):.3g} overflow its power "
                            "spectrum; rescale the signal", where=r.source)
        if float(np.ptp(r.x)) < TINY_SPREAD:
            raise DataError(f"column '{r.name}': its values vary by {float(np.ptp(r.x)):.3g} only, and their power "
                            "spectrum underflows double precision; rescale the signal", where=r.source)
    unit = options.pop("unit", records[0].unit)
    result = analyze_psd([r.x for r in records], dt0, noise=[r.x for r in noise] or None, unit=unit, **options)
    notes = tuple(dict.fromkeys(f"{r.source}: {n}" for r in everything for n in r.notes))  # a split file's once
    made_up = sum(r.made_up * r.x.size for r in records) / sum(r.x.size for r in records)
    # a tone interpolated at the midpoint of a dropped stamp misses by A sin(wt) (1 - cos w dt): that error, on the
    # made-up share of the samples, is power spread over every frequency that no record holds
    spread = made_up * sum(sp.power * (1.0 - np.cos(sp.w * dt0)) ** 2 for sp in result.spikes)
    extra: tuple[str, ...] = ()
    if spread > 0.0 and result.suggestion_withheld is None and result.disturbance_power <= 2.0 * spread:
        sq = unit_squared(unit)
        why = (f"interpolated: the power above the floor ({result.disturbance_power:.3g} {sq}) is within twice what "
               f"interpolating the spikes across the dropped stamps ({100 * made_up:.2g} % of the samples) spreads "
               f"over the band (about {spread:.3g} {sq}); a record without dropped stamps shows whether it is the "
               "disturbance's")
        result = PsdAnalysis(**{**result.__dict__, "share_frequency": None, "suggestion_withheld": why})
        extra = (f"no share frequency and no bandwidth requirement: {why}",)
    return PsdAnalysis(**{**result.__dict__, "notes": notes + result.notes + extra})

