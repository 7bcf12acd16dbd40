"""From disturbance records to requirements: the sensitivity level, its band, and the bandwidth floor.

The X-4 paper (sec. 5, 6A) reads its disturbance spectrum so: the disturbance power lies below
30 rad/s and decays up to 80 rad/s; attenuating it by more than -15 dB would push it below what the
speed sensor resolves; the closed loop must therefore pass 80 rad/s, 60 rad/s being acceptable "as
the remainder contains little power". This module makes that reading a computation on a
:class:`synth.ident.psd.PsdAnalysis` (all PSDs one-sided, ``unit^2/(rad/s)``, dB re 1):

1. **Sensor floor** ``N``: the largest of the analysis' floor (a noise record's level, or the record's
   own floor) and, given the sensor's resolution ``q``, the quantization-noise level
   ``q^2 / (12 w_N)`` (uniform error of variance ``q^2/12`` spread over ``0..w_N``, ``w_N = pi/dt``).
2. **Disturbance shape**: a least-squares fit, equal weight per decade, spikes and the first bin (biased low by
   each segment's detrend) left out, of
   ``10 log10(10^(h(w)/10) + F)`` to the PSD in dB, ``F`` the analysis' floor and ``h`` a broken line on
   the log-log plot: ``h = L`` (the plateau) up to the corner ``w_c``, then ``L + m log10(w/w_c)``.
3. **Sensitivity** ``|S| <= N_dB - L`` over ``[0, w_c]``: ``|S|^2 D <= N`` brings the plateau down to the
   floor, and no further (set by the plateau and the sensor floor; the band by the corner).
4. **Bandwidth floor** ``w_c 10^((N_dB + margin - L)/m)``: where the fitted disturbance falls to
   ``margin_db`` (default 3 dB, :data:`synth.ident.psd.KNEE_DB`) above the sensor floor; the "ideal"
   bandwidth is where it meets the floor (``margin = 0``). Spikes are listed as evidence, not as
   bandwidth: a narrow band calls for a notch.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from synth.data.disturbance import DisturbanceRecord
from synth.errors import DataError
from synth.ident.bandwidth_suggestion import suggest_bandwidth
from synth.ident.psd import KNEE_DB, PsdAnalysis, analyze_records
from synth.ident.spectrum_features import find_spikes
from synth.ident.welch import unit_squared

__all__ = ["DisturbanceFit", "DisturbanceRequirements", "Evidence", "fit_disturbance_shape",
           "quantization_floor", "requirements_from_disturbance", "requirements_from_records"]


@dataclass(frozen=True)
class Evidence:
    """One number behind a requirement and the spectral feature that sets it.

    Examples
    --------
    >>> Evidence("corner", 30.0, "rad/s", "end of the plateau").to_dict()["unit"]
    'rad/s'
    """

    name: str
    value: float
    unit: str
    feature: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"name": self.name, "value": self.value, "unit": self.unit, "feature": self.feature}


@dataclass(frozen=True)
class DisturbanceFit:
    """The fitted broken line: plateau ``plateau_db`` to ``corner``, then ``slope_db_per_decade``.

    Examples
    --------
    >>> f = DisturbanceFit(-15.0, 30.0, -35.0, 0.5, 100)
    >>> float(f.value_db(300.0)), round(f.frequency_at(-30.0), 1)
    (-50.0, 80.4)
    """

    plateau_db: float
    corner: float
    slope_db_per_decade: float
    rms_residual_db: float
    points: int

    def value_db(self, w: Any) -> np.ndarray:
        """The broken line at ``w`` [dB]."""
        return self.plateau_db + self.slope_db_per_decade * np.maximum(np.log10(np.asarray(w, float) / self.corner), 0)

    def frequency_at(self, level_db: float) -> float:
        """Where the line falls to ``level_db`` (the corner if the plateau is not above it) [rad/s]."""
        rise = level_db - self.plateau_db
        return self.corner * 10 ** (rise / self.slope_db_per_decade) if rise < 0 else self.corner

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"plateau_db": self.plateau_db, "corner": self.corner, "slope_db_per_decade": self.slope_db_per_decade,
                "rms_residual_db": self.rms_residual_db, "points": self.points,
                "units": {"plateau_db": "dB re 1 unit^2/(rad/s)", "corner": "rad/s",
                          "slope_db_per_decade": "dB/decade", "rms_residual_db": "dB"}}


def quantization_floor(resolution: float, w_nyquist: float) -> float:
    """PSD of the error of a quantizer of step ``resolution``: ``q^2 / (12 w_N)`` [unit^2/(rad/s)].

    Examples
    --------
    >>> round(10 * math.log10(quantization_floor(1.2, math.pi / 0.001)), 2)  # 1.2 rad/s at 1 kHz
    -44.18
    """
    if not (math.isfinite(resolution) and resolution > 0):
        raise DataError(f"resolution must be > 0, got {resolution!r}", where="disturbance requirements")
    return resolution**2 / (12.0 * w_nyquist)


def fit_disturbance_shape(w: np.ndarray, S: np.ndarray, floor: float, exclude: np.ndarray | None = None,
                          w_max: float | None = None) -> DisturbanceFit:
    """Fit plateau, corner and decay (module text, step 2) to a PSD with a known white ``floor``.

    Raises
    ------
    DataError
        Fewer than 8 bins to fit.

    Examples
    --------
    >>> w = np.arange(1.0, 2000.0)
    >>> S = 10 ** ((-15 - 35 * np.maximum(np.log10(w / 30), 0)) / 10) + 1e-3
    >>> f = fit_disturbance_shape(w, S, 1e-3)
    >>> round(f.plateau_db, 3), round(f.corner, 2), round(f.slope_db_per_decade, 2)
    (-15.0, 30.0, -35.0)
    """
    sel = np.isfinite(S) & (S > 0)
    if exclude is not None:
        sel &= ~exclude
    if w_max is not None:
        sel &= w <= w_max
    if np.count_nonzero(sel) < 8:
        raise DataError(f"only {int(np.count_nonzero(sel))} bins to fit the disturbance shape; give a longer record",
                        where="disturbance requirements")
    ww, y = w[sel], 10 * np.log10(S[sel])
    x = np.log10(ww)
    sw = np.sqrt(1.0 / ww)
    sw = sw / np.sqrt(np.sum(sw**2))
    floor_db = 10 * math.log10(floor)

    def model(p: np.ndarray) -> np.ndarray:
        h = p[0] + p[2] * np.maximum(x - p[1], 0.0)
        return 10 * np.log10(10 ** (h / 10) + 10 ** (floor_db / 10))

    def residual(p: np.ndarray) -> np.ndarray:
        return (model(p) - y) * sw

    lo_x, hi_x = float(x[0]), float(x[-1])
    best = None
    for xc in np.linspace(lo_x, lo_x + 0.8 * (hi_x - lo_x), 40):
        below = y[x <= xc]
        start = np.array([float(np.median(below)) if below.size else float(y[0]), xc, -20.0])
        fit = least_squares(lambda q, xc=xc: residual(np.array([q[0], xc, q[1]])), start[[0, 2]],
                            bounds=([-np.inf, -300.0], [np.inf, -0.1]))
        if best is None or fit.cost < best[0]:
            best = (fit.cost, np.array([fit.x[0], xc, fit.x[1]]))
    assert best is not None
    fit = least_squares(residual, best[1], bounds=([-np.inf, lo_x, -300.0], [np.inf, hi_x, -0.1]))
    p = fit.x
    rms = float(np.sqrt(np.sum((model(p) - y) ** 2 * sw**2)))
    return DisturbanceFit(float(p[0]), float(10 ** p[1]), float(p[2]), rms, int(y.size))


@dataclass(frozen=True)
class DisturbanceRequirements:
    """The sensitivity level and band, and the bandwidth floor, that a disturbance spectrum asks for.

    Attributes
    ----------
    max_db : float or None
        ``|S|`` needed over ``band`` [dB] (``None``: the disturbance never stands above the sensor floor).
    band : tuple of float
        ``(0, corner)`` [rad/s].
    min_bandwidth : float or None
        Bandwidth floor: the disturbance falls to ``margin_db`` above the sensor floor here [rad/s] (``None``: its
        plateau does not stand ``margin_db`` above the floor, so no frequency is).
    ideal_bandwidth : float or None
        The disturbance meets the sensor floor here [rad/s] (``None``: it never stands above the floor).
    margin_db : float
    sensor_floor_db : float
        [dB re 1 unit^2/(rad/s)]
    sensor_floor_source : str
    fit : DisturbanceFit
    evidence : tuple of Evidence
    notes : tuple of str

    Examples
    --------
    >>> f = DisturbanceFit(-15.0, 30.0, -35.2, 0.5, 100)
    >>> r = DisturbanceRequirements(-15.0, (0.0, 30.0), 65.8, 80.0, 3.0, -30.0, "noise record", f, (), ())
    >>> print(r.yaml())
    requirements:
      - {type: sensitivity, max_db: -15, band: [0, 30]}   # plateau -15 dB vs sensor floor -30 dB (noise record)
      - {type: bandwidth, min: 65.8}   # disturbance 3 dB above the sensor floor; meets it at 80 rad/s
    """

    max_db: float | None
    band: tuple[float, float]
    min_bandwidth: float | None
    ideal_bandwidth: float | None
    margin_db: float
    sensor_floor_db: float
    sensor_floor_source: str
    fit: DisturbanceFit
    evidence: tuple[Evidence, ...]
    notes: tuple[str, ...]

    def spec_entries(self) -> list[dict[str, Any]]:
        """The requirements as spec-file entries (``docs/spec-format.md``), 3 significant digits."""
        out: list[dict[str, Any]] = []
        if self.max_db is not None:
            out.append({"type": "sensitivity", "max_db": _g(self.max_db), "band": [0, _g(self.band[1])]})
        if self.min_bandwidth is not None:
            out.append({"type": "bandwidth", "min": _g(self.min_bandwidth)})
        return out

    def yaml(self) -> str:
        """A ready ``requirements:`` block, each entry with its evidence as a comment."""
        entries = self.spec_entries()
        if not entries:
            return (f"requirements: []   # none: the disturbance's plateau ({self.fit.plateau_db:.3g} dB) does not stand "
                    f"above the sensor floor ({self.sensor_floor_db:.3g} dB, {self.sensor_floor_source})")
        lines = ["requirements:"]
        for e in entries:
            if e["type"] == "sensitivity":
                lines.append(f"  - {{type: sensitivity, max_db: {e['max_db']:g}, band: [0, {e['band'][1]:g}]}}   "
                             f"# plateau {self.fit.plateau_db:.3g} dB vs sensor floor {self.sensor_floor_db:.3g} dB "
                             f"({self.sensor_floor_source})")
            else:
                lines.append(f"  - {{type: bandwidth, min: {e['min']:g}}}   # disturbance {self.margin_db:g} dB above "
                             f"the sensor floor; meets it at {self.ideal_bandwidth:.3g} rad/s")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (with the spec entries and the YAML text)."""
        return {"max_db": self.max_db, "band": list(self.band), "min_bandwidth": self.min_bandwidth,
                "ideal_bandwidth": self.ideal_bandwidth, "margin_db": self.margin_db,
                "sensor_floor_db": self.sensor_floor_db, "sensor_floor_source": self.sensor_floor_source,
                "fit": self.fit.to_dict(), "evidence": [e.to_dict() for e in self.evidence],
                "spec_entries": self.spec_entries(), "yaml": self.yaml(), "notes": list(self.notes),
                "units": {"max_db": "dB", "band": "rad/s", "min_bandwidth": "rad/s", "ideal_bandwidth": "rad/s",
                          "margin_db": "dB", "sensor_floor_db": "dB re 1 unit^2/(rad/s)"}}


def _g(x: float) -> float:
    return float(f"{x:.3g}")


def requirements_from_disturbance(analysis: PsdAnalysis, resolution: float | None = None, dt: float | None = None,
                                  margin_db: float = KNEE_DB) -> DisturbanceRequirements:
    """Sensitivity level and band, and bandwidth floor, from a disturbance spectrum (module text).

    Parameters
    ----------
    analysis : PsdAnalysis
        The disturbance spectrum (with a noise record's floor when one was given).
    resolution : float, optional
        Sensor resolution [unit]; its quantization floor joins the sensor floor.
    dt : float, optional
        Sample interval [s] for the quantization floor; default ``pi`` over the highest frequency.
    margin_db : float
        Level above the sensor floor that sets the bandwidth floor [dB].

    Returns
    -------
    DisturbanceRequirements

    Examples
    --------
    >>> from synth.ident.psd import analyze_records
    >>> from synth.ident.disturbance_synthetic import synthetic_disturbance_record, synthetic_noise_record
    >>> a = analyze_records([synthetic_disturbance_record()], [synthetic_noise_record()])
    >>> r = requirements_from_disturbance(a, resolution=1.2)
    >>> round(r.max_db), round(r.band[1]), 60 <= r.min_bandwidth <= 80
    (-15, 30, True)
    """
    if not (math.isfinite(margin_db) and margin_db >= 0):
        raise DataError(f"margin_db must be >= 0, got {margin_db!r}", where="disturbance requirements")
    w, S = analysis.w, analysis.psd
    w_nyq = math.pi / dt if dt else float(w[-1])
    _, mask = find_spikes(w, S)
    # the first bin shares the Hann main lobe of the segment mean each segment's detrend removes: it reads
    # 0.8 dB (mean removed) to 1.4 dB (line removed) low on white noise, and carries a decade's weight in the fit
    mask = mask | (w < 1.5 * (w[1] - w[0]))
    w_max = analysis.floor_band[0] if analysis.floor_source != "noise record" else None
    fit = fit_disturbance_shape(w, S, analysis.floor, mask, w_max)
    floors = {analysis.floor_source: analysis.floor}
    if resolution is not None:
        floors[f"resolution {resolution:g} {analysis.unit}".strip()] = quantization_floor(resolution, w_nyq)
    source = max(floors, key=lambda k: floors[k])
    sensor_db = 10 * math.log10(floors[source])
    notes: list[str] = []
    excess = fit.plateau_db - sensor_db
    max_db = -excess if excess > 0 else None
    if max_db is None:
        notes.append(f"the plateau ({fit.plateau_db:.3g} dB) does not stand above the sensor floor ({sensor_db:.3g} dB): "
                     "no sensitivity requirement follows")
    if fit.corner <= w[2]:
        notes.append("the fitted corner lies at the lowest bins: the spectrum has no plateau in the record "
                     "(a longer record resolves lower frequencies)")
    # frequency_at gives the corner for a level the plateau does not reach: no frequency, then, meets that level
    ideal = fit.frequency_at(sensor_db) if fit.plateau_db > sensor_db else None
    minimum = fit.frequency_at(sensor_db + margin_db) if fit.plateau_db > sensor_db + margin_db else None
    if minimum is None:
        notes.append(f"the plateau ({fit.plateau_db:.3g} dB) does not stand {margin_db:g} dB above the sensor floor "
                     f"({sensor_db:.3g} dB): no bandwidth floor follows")
    if (max_db is not None or minimum is not None) and analysis.suggestion_withheld is not None \
            and analysis.suggestion_withheld.startswith("not significant"):
        notes.append("the power above the floor is within the Welch estimate's scatter (not significant): a "
                     "requirement above rests on a plateau the record may not show")
    D = np.where(mask, 0.0, S - analysis.floor)
    level = f"dB re 1 {unit_squared(analysis.unit)}/(rad/s)"
    share_below = float(np.sum(D[w <= fit.corner]) / np.sum(D)) if np.sum(D) > 0 else float("nan")
    ev = [
        Evidence("plateau level", fit.plateau_db, level,
                 "fitted disturbance level below the corner; sets max_db = sensor floor - plateau"),
        Evidence("sensor floor", sensor_db, level, "largest of: " + ", ".join(
            f"{k} {10 * math.log10(v):.3g} dB" for k, v in floors.items())),
        Evidence("corner", fit.corner, "rad/s", "end of the plateau; sets the sensitivity band [0, corner]"),
        Evidence("share of disturbance power below the corner", share_below, "1",
                 "power above the measured floor, spikes left out"),
        Evidence("decay", fit.slope_db_per_decade, "dB/decade", "log-log slope above the corner"),
    ]
    ev += [Evidence(name, value, "rad/s", what) for name, value, what in (
        ("bandwidth floor", minimum, f"fitted disturbance {margin_db:g} dB above the sensor floor"),
        ("ideal bandwidth", ideal, "fitted disturbance meets the sensor floor")) if value is not None]
    if analysis.share_frequency is not None and analysis.suggestion_withheld is None:
        s = suggest_bandwidth(analysis)
        ev.append(Evidence(f"{100 * s.share:g} % power frequency", s.share_frequency, "rad/s",
                           "synth.ident.psd.suggest_bandwidth, for comparison"))
    ev += [Evidence("spike", sp.w, "rad/s", f"narrow band {sp.height_db:.3g} dB above the running median: a notch, "
                    "not bandwidth") for sp in analysis.spikes]
    return DisturbanceRequirements(max_db, (0.0, fit.corner), minimum, ideal, float(margin_db), sensor_db, source, fit,
                                   tuple(ev), tuple(notes))


def requirements_from_records(records: Sequence[DisturbanceRecord], noise: Sequence[DisturbanceRecord] = (),
                              resolution: float | None = None, margin_db: float = KNEE_DB,
                              **options: Any) -> tuple[PsdAnalysis, DisturbanceRequirements]:
    """:func:`synth.ident.psd.analyze_records` then :func:`requirements_from_disturbance`.

    Examples
    --------
    >>> from synth.ident.disturbance_synthetic import synthetic_disturbance_record
    >>> a, r = requirements_from_records([synthetic_disturbance_record()])
    >>> r.spec_entries()[0]["type"], r.sensor_floor_source
    ('sensitivity', 'median of the upper half')
    """
    analysis = analyze_records(records, noise, **options)
    return analysis, requirements_from_disturbance(analysis, resolution, records[0].dt, margin_db)
