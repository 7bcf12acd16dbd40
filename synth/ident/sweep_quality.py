"""Quality of each sweep run, and which runs to keep (the NASA report, sections 5-6.1).

The report flies three sweeps per axis and keeps the best two, chosen on "a strong
coherence function for the individual runs" over the band of interest; each run is
"visually inspected for symmetry of input and output, and frequency content"; excessive
off-axis inputs are a common source of reduced coherence. Per run, on the grid and
band of the composite estimate:

- ``coherent_share``: share of the band (in decades: the grid is logarithmic) where the
  run's own coherence is at least 0.8; ``mean_coherence`` its mean there.
- input autospectrum: ``input_db_spread``, the 90th minus the 10th percentile of ``10 log10 (w Gxx)``
  (power per decade) over the band [dB]; ``under_excited_share``, the share of the band where the input
  is under-excited, and ``under_excited_bands``, those stretches [rad/s]. A frequency is under-excited
  when its input autospectrum lies more than :data:`UNDER_EXCITED_DB` below the band's own level (90th
  percentile) on both of two scales (:func:`excitation_deficit`): per rad/s, ``Gxx`` (flat for white
  noise, a multisine, a linear chirp) and per decade, ``w Gxx`` (flat for a sweep that spends equal time
  in every decade, as :mod:`synth.ident.sweep_design`'s does). Any input whose spectrum lies between
  those two shapes passes whole; a sweep that stops short of the band's top, or a hole in the spectrum,
  falls far below both. (Judged per decade alone, a flat spectrum fell 10 dB per decade below its top
  and a white-noise or Schroeder-multisine input read as under-excited over 60 % of two decades.)
- ``output_asymmetry``: ``(P - N) / (P + N)``, ``P`` and ``N`` the RMS of the positive
  and the negative excursions of the output from trim (the median output before the input
  first moves by 2 % of its range); 0 for a symmetric response, +-1 for one-sided.
- ``off_axis_share`` (with an off-axis channel): ``int Gvv / (int Gxx + int Gvv)`` over the
  band, the share of the input power that went into the off-axis control (same units).

Ranking: by ``coherent_share``, then ``mean_coherence``; the best two of three or more runs
are suggested (all of one or two), each with its reason and any warnings (under-excited
over more than 20 % of the band or over any stretch of at least :data:`UNDER_EXCITED_MIN_DECADES`,
named in rad/s; asymmetry beyond 0.3, off-axis share beyond 0.2).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.data import Record
from synth.errors import DataError
from synth.ident.coherence import COHERENCE_THRESHOLD, coherence_from_spectra
from synth.ident.spectral_windows import combine_windows, window_spectra

__all__ = [
    "ASYMMETRY_WARN", "OFF_AXIS_WARN", "UNDER_EXCITED_DB", "UNDER_EXCITED_MIN_DECADES", "UNDER_EXCITED_WARN",
    "RunQuality", "excitation_deficit", "output_asymmetry", "rank_runs", "run_quality", "under_excited_bands",
]

#: dB below the input autospectrum's own level (90th percentile over the band) that counts as under-excited
UNDER_EXCITED_DB = 10.0
#: warn when a run is under-excited over more than this share of the band
UNDER_EXCITED_WARN = 0.2
#: ... or over any contiguous stretch at least this wide [decades] (a hole, a sweep stopping short)
UNDER_EXCITED_MIN_DECADES = 0.05
#: warn when the output asymmetry exceeds this
ASYMMETRY_WARN = 0.3
#: warn when the off-axis share of the input power exceeds this
OFF_AXIS_WARN = 0.2


@dataclass(frozen=True)
class RunQuality:
    """Quality figures of one sweep run (module text).

    Attributes
    ----------
    source : str
    coherent_share, mean_coherence : float
    input_db_spread, under_excited_share : float
    output_asymmetry : float
    off_axis_share : float or None
        ``None`` without an off-axis channel.
    rank : int
        1 = best.
    keep : bool
        Suggested for the composite.
    reason : str
        Why it ranks where it does, and its warnings.
    under_excited_bands : tuple of (float, float)
        The under-excited stretches of the band [rad/s], lowest first.

    Examples
    --------
    >>> q = RunQuality("run1.csv", 0.9, 0.95, 6.0, 0.0, 0.02, None, 1, True, "coherence >= 0.8 over 90 %")
    >>> q.to_dict()["keep"], q.to_dict()["off_axis_share"]
    (True, None)
    """

    source: str
    coherent_share: float
    mean_coherence: float
    input_db_spread: float
    under_excited_share: float
    output_asymmetry: float
    off_axis_share: float | None
    rank: int = 0
    keep: bool = True
    reason: str = ""
    under_excited_bands: tuple[tuple[float, float], ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready figures."""
        return {"source": self.source, "rank": self.rank, "keep": self.keep, "reason": self.reason,
                "coherent_share": self.coherent_share, "mean_coherence": self.mean_coherence,
                "input_db_spread": self.input_db_spread, "under_excited_share": self.under_excited_share,
                "under_excited_bands": [list(b) for b in self.under_excited_bands],
                "output_asymmetry": self.output_asymmetry, "off_axis_share": self.off_axis_share}


def output_asymmetry(record: Record) -> float:
    """``(P - N) / (P + N)`` of the output's excursions from trim (module text).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 10, 0.01); s = np.sin(2 * np.pi * t)
    >>> round(output_asymmetry(record_from_arrays(t, s, np.where(s > 0, s, 0.5 * s))), 3)
    0.333
    """
    u, y = record.u, record.y
    moved = np.flatnonzero(np.abs(u - u[0]) > 0.02 * max(float(np.ptp(u)), 1e-300))
    first = int(moved[0]) if moved.size else y.size
    trim = float(np.median(y[:max(first, 1)]))
    d = y - trim
    p = float(np.sqrt(np.mean(np.where(d > 0, d, 0.0) ** 2)))
    n = float(np.sqrt(np.mean(np.where(d < 0, d, 0.0) ** 2)))
    return (p - n) / (p + n) if p + n > 0 else 0.0


def excitation_deficit(w: np.ndarray, gxx: np.ndarray, reference: np.ndarray | None = None) -> np.ndarray:
    """dB by which the input autospectrum lies below its own level, on the more lenient of two scales (module text).

    Per point, the smaller of ``P90(10 log10 Gxx) - 10 log10 Gxx`` (per rad/s) and
    ``P90(10 log10 w Gxx) - 10 log10 w Gxx`` (per decade), the 90th percentiles taken over the
    ``reference`` points (default: all). A flat ``Gxx``, a ``1/w`` one and anything between
    read about 0 dB everywhere; a stretch the input does not reach reads tens of dB.

    Parameters
    ----------
    w : numpy.ndarray
        Frequencies [rad/s], increasing.
    gxx : numpy.ndarray
        Input autospectrum at ``w`` (any unit; a value <= 0 reads as an infinite deficit).
    reference : numpy.ndarray of bool, optional
        The points whose level counts as the input's own.

    Returns
    -------
    numpy.ndarray
        Deficit [dB] at each ``w`` (negative above the level).

    Examples
    --------
    White noise, a log sweep, and white noise that stops at 10 rad/s (40 dB of leakage above):

    >>> w = np.geomspace(1, 100, 21)
    >>> round(float(excitation_deficit(w, np.ones(21)).max()), 1), round(float(excitation_deficit(w, 1 / w).max()), 1)
    (0.0, 0.0)
    >>> excitation_deficit(w, np.where(w <= 10, 1.0, 1e-4))[[0, 11, 20]].round(1).tolist()
    [0.0, 37.0, 28.0]
    """
    w, gxx = np.asarray(w, float), np.asarray(gxx, float)
    ref = np.ones(w.shape, bool) if reference is None else np.asarray(reference, bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        per_rad = 10.0 * np.log10(np.where(gxx > 0, gxx, np.nan))
    per_decade = per_rad + 10.0 * np.log10(w)
    out = np.full(w.shape, np.inf)
    ok = np.isfinite(per_rad)
    if not np.any(ok & ref):
        return out
    top_rad = float(np.percentile(per_rad[ok & ref], 90))
    top_decade = float(np.percentile(per_decade[ok & ref], 90))
    out[ok] = np.minimum(top_rad - per_rad[ok], top_decade - per_decade[ok])
    return out


def under_excited_bands(w: np.ndarray, under: np.ndarray) -> tuple[tuple[float, float], ...]:
    """The contiguous stretches of ``w`` flagged in ``under``, as ``(low, high)`` [rad/s].

    Each grid point stands for its cell (edges at the geometric midpoints, the grid's ends at
    its first and last point), so a stretch's width in decades is ``log10(high / low)``.

    Examples
    --------
    >>> w = np.geomspace(1, 100, 21)
    >>> [(round(a, 2), round(b, 1)) for a, b in under_excited_bands(w, w > 30)]
    [(28.18, 100.0)]
    """
    w, under = np.asarray(w, float), np.asarray(under, bool)
    edges = np.r_[w[0], np.sqrt(w[1:] * w[:-1]), w[-1]]
    flips = np.flatnonzero(np.diff(np.r_[0, under.astype(int), 0]))
    return tuple((float(edges[a]), float(edges[b])) for a, b in zip(flips[::2], flips[1::2]))


def _run_spectra(run: Record, windows: Sequence[float], grid: np.ndarray, overlap: float,
                 signal: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Composite spectra of one run (``signal`` replaces the output, e.g. an off-axis input)."""
    if signal is not None:
        run = Record(run.t, run.u, signal, run.input, run.output, {}, run.source)
    fitting = [w for w in windows if round(w * run.fs) * (1.0 + 2.0 * (1.0 - overlap)) <= run.n]
    if not fitting:
        fitting = [min(windows)]
    results = []
    for length in fitting:
        nseg = max(8, min(round(length * run.fs), run.n))
        results.append(window_spectra([run], run.fs, nseg, overlap, grid, "linear"))
    gxx, gyy, gxy, _ = combine_windows(results, grid)
    return gxx, gyy, gxy


def run_quality(run: Record, w: np.ndarray, band: tuple[float, float], windows: Sequence[float],
                off_axis: str | None = None, overlap: float = 0.5,
                threshold: float = COHERENCE_THRESHOLD) -> RunQuality:
    """Quality figures of one run on the grid ``w`` over ``band`` [rad/s] (module text).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.sweep_design import design_sweep
    >>> t, u = design_sweep(1.0, 30.0).signal(sample_rate=100)           # equal time in every decade
    >>> q = run_quality(record_from_arrays(t, u, 2 * u), np.geomspace(1, 30, 41), (1, 30), [12.0])
    >>> round(q.coherent_share, 2), q.under_excited_share, round(q.output_asymmetry, 1)
    (1.0, 0.0, 0.0)
    """
    w = np.asarray(w, float)
    inside = (w >= band[0] * (1 - 1e-12)) & (w <= band[1] * (1 + 1e-12))
    if np.count_nonzero(inside) < 2:
        raise DataError(f"band {band[0]:.4g}-{band[1]:.4g} rad/s holds fewer than 2 grid points", where=run.source)
    gxx, gyy, gxy = _run_spectra(run, windows, w, overlap)
    coh = np.nan_to_num(coherence_from_spectra(gxx, gyy, gxy))[inside]
    good = coh >= threshold
    db = 10.0 * np.log10(np.maximum(w[inside] * gxx[inside], 1e-300))     # power per decade
    under = excitation_deficit(w[inside], gxx[inside]) > UNDER_EXCITED_DB
    off = None
    if off_axis is not None:
        if off_axis not in run.aux:
            raise DataError(f"off-axis column '{off_axis}' not loaded; found {', '.join(run.aux) or 'no aux columns'}",
                            where=run.source)
        _, gvv, _ = _run_spectra(run, windows, w, overlap, signal=np.asarray(run.aux[off_axis], float))
        lw = np.log(w[inside])
        pxx = float(np.trapezoid(gxx[inside] * w[inside], lw))
        pvv = float(np.trapezoid(gvv[inside] * w[inside], lw))
        off = pvv / (pxx + pvv) if pxx + pvv > 0 else 0.0
    return RunQuality(run.source, float(np.mean(good)), float(np.mean(coh)),
                      float(np.percentile(db, 90) - np.percentile(db, 10)), float(np.mean(under)),
                      output_asymmetry(run), off, under_excited_bands=under_excited_bands(w[inside], under))


def rank_runs(qualities: Sequence[RunQuality], keep: int | None = None) -> list[RunQuality]:
    """Rank runs (best first) and suggest which to keep, each with its reason.

    ``keep`` defaults to the report's best 2 of 3 or more (all of one or two).

    Examples
    --------
    >>> a = RunQuality("a", 0.6, 0.8, 5.0, 0.0, 0.0, None); b = RunQuality("b", 0.9, 0.9, 5.0, 0.0, 0.5, None)
    >>> c = RunQuality("c", 0.8, 0.9, 5.0, 0.0, 0.0, None)
    >>> [(q.source, q.rank, q.keep) for q in rank_runs([a, b, c])]
    [('b', 1, True), ('c', 2, True), ('a', 3, False)]
    >>> rank_runs([a, b, c])[0].reason
    'coherence >= 0.8 over 90 % of the band (mean 0.90); warning: output asymmetric (0.50 > 0.3)'
    """
    n = len(qualities)
    keep = (2 if n >= 3 else n) if keep is None else keep
    order = sorted(qualities, key=lambda q: (-q.coherent_share, -q.mean_coherence))
    out = []
    for i, q in enumerate(order):
        why = f"coherence >= 0.8 over {100 * q.coherent_share:.0f} % of the band (mean {q.mean_coherence:.2f})"
        warn = []
        wide = [b for b in q.under_excited_bands if np.log10(b[1] / b[0]) >= UNDER_EXCITED_MIN_DECADES]
        if q.under_excited_share > UNDER_EXCITED_WARN or wide:
            where = ", ".join(f"{a:.4g}-{b:.4g}" for a, b in (wide or q.under_excited_bands))
            warn.append(f"input under-excited over {100 * q.under_excited_share:.0f} % of the band "
                        f"({where} rad/s: more than {UNDER_EXCITED_DB:g} dB below its own level)")
        if abs(q.output_asymmetry) > ASYMMETRY_WARN:
            warn.append(f"output asymmetric ({q.output_asymmetry:.2f} > {ASYMMETRY_WARN:g})")
        if q.off_axis_share is not None and q.off_axis_share > OFF_AXIS_WARN:
            warn.append(f"off-axis input {100 * q.off_axis_share:.0f} % of the input power")
        if warn:
            why += "; warning: " + ", ".join(warn)
        out.append(RunQuality(q.source, q.coherent_share, q.mean_coherence, q.input_db_spread, q.under_excited_share,
                              q.output_asymmetry, q.off_axis_share, i + 1, i < keep, why, q.under_excited_bands))
    return out
