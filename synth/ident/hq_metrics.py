"""Handling-qualities metrics of an attitude response: bandwidth and phase delay (seed 2, sec. 6.2, fig. 1).

Definitions (all on the attitude response to the control input, phase unwrapped):

- ``w180``: the first frequency where the phase falls through -180 deg (neutral stability).
- ``bandwidth_phase`` (``w135``): the first frequency where the phase falls through -135 deg
  (45 deg phase margin). Beyond it a pilot closing the loop there would have less margin.
- ``bandwidth_gain``: the frequency below ``w180`` where the gain is 6 dB above the gain at
  ``w180`` (6 dB gain margin). When the gain crosses that level several times the highest
  downward crossing below ``w180`` is used: it is the crossover of the largest pilot gain
  that still leaves 6 dB of gain margin.
- ``bandwidth``: for rate response types the lesser of the two; for attitude response types
  the phase bandwidth (seed 2, sec. 6.2: "the bandwidth for an attitude response type system is
  defined to be w135"). The response type is detected from the low-frequency behaviour when not
  given: an integrator (phase near -90 deg) means a rate response type.
- ``phase_delay``: ``tau_p = -(phi(2 w180) + 180 deg) / (2 w180)`` with the phase in radians
  (the seed writes 57.3 deg/rad; the exact 180/pi is used).

Crossings are bracketed on a dense logarithmic grid (no curve is assumed monotonic) and refined:
with Brent's method in ``log w`` on the exact response of a model, by linear interpolation in
``log w`` between measured points. This module reads the metrics off a curve and holds the result
(:class:`HQMetrics`); :mod:`synth.ident.hq` estimates them from a model or from measurements.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import brentq

from synth.errors import ModelError

__all__ = [
    "COHERENCE_OK", "DEG", "GAIN_MARGIN_DB", "PHASE_FITS", "RESPONSE_TYPES", "Crossing", "HQMetrics", "PhaseLine",
    "ResponseCurve", "bandwidth_by_type", "check_choice", "crossing_metrics", "find_crossings",
]

DEG = 180.0 / np.pi
#: coherence (gamma^2) below which a metric is flagged as unreliable (seed 2, sec. 6.1)
COHERENCE_OK = 0.8
#: gain margin of the gain bandwidth [dB] (seed 2, fig. 1: exactly 6 dB, not a factor of 2)
GAIN_MARGIN_DB = 6.0
RESPONSE_TYPES = ("auto", "rate", "attitude")
PHASE_FITS = ("auto", "raw", "line")


@dataclass(frozen=True)
class Crossing:
    """One frequency where a curve passes a level.

    Attributes
    ----------
    w : float
        Frequency [rad/s].
    direction : int
        -1 when the curve falls through the level (with increasing ``w``), +1 when it rises.

    Examples
    --------
    >>> Crossing(2.0, -1).to_dict()
    {'w': 2.0, 'direction': 'down'}
    """

    w: float
    direction: int

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"w": self.w, "direction": "down" if self.direction < 0 else "up"}


def find_crossings(w: np.ndarray, y: np.ndarray, level: float,
                   func: Callable[[float], float] | None = None) -> list[Crossing]:
    """Every crossing of ``level`` by the curve ``y(w)``, in increasing frequency.

    Each sign change of ``y - level`` between neighbouring grid points is a bracket. With ``func``
    (the exact curve as a function of ``w``) the bracket is refined by Brent's method in ``log w``;
    without it (measured points) by linear interpolation in ``log w``. Nothing assumes the curve
    is monotonic.

    Parameters
    ----------
    w : numpy.ndarray
        Increasing frequencies [rad/s], > 0.
    y : numpy.ndarray
        Curve values on ``w``.
    level : float
        Level to cross.
    func : callable, optional
        Exact ``y`` at any frequency, continuous between grid points.

    Returns
    -------
    list of Crossing

    Examples
    --------
    >>> w = np.logspace(-0.5, 0.5, 101)
    >>> y = np.sin(3 * np.log(w))           # crosses 0 three times between 0.32 and 3.2 rad/s
    >>> [round(c.w, 4) for c in find_crossings(w, y, 0.0, lambda x: np.sin(3 * np.log(x)))]
    [0.3509, 1.0, 2.8497]
    """
    w = np.asarray(w, float)
    d = np.asarray(y, float) - level
    positive = d >= 0
    idx = np.flatnonzero(positive[:-1] != positive[1:])
    out: list[Crossing] = []
    for i in idx:
        lo, hi = np.log(w[i]), np.log(w[i + 1])
        direction = -1 if positive[i] else 1
        x = lo + (hi - lo) * d[i] / (d[i] - d[i + 1])
        if func is not None:
            fa, fb = func(w[i]) - level, func(w[i + 1]) - level
            if fa == 0 or fb == 0:
                x = lo if fa == 0 else hi
            elif fa * fb < 0:  # else the level sits on a grid point within round-off: keep the interpolation
                x = brentq(lambda z: func(np.exp(z)) - level, lo, hi, xtol=1e-13, rtol=1e-13)
        out.append(Crossing(float(np.exp(x)), direction))
    return out


@dataclass(frozen=True)
class PhaseLine:
    """Least-squares line through the phase on a linear frequency axis (seed 2, fig. 15).

    Attributes
    ----------
    band : tuple of float
        Frequencies [rad/s] whose points were fitted.
    points : int
        Number of points fitted.
    slope : float
        Phase slope [deg/(rad/s)]; ``-slope/57.3`` is the delay that alone would give it [s].
    intercept : float
        Phase of the line at ``w = 0`` [deg].
    rms_residual : float
        Root-mean-square distance of the points from the line [deg].
    phase_2w180 : float
        Phase of the line at ``2 w180`` [deg].

    Examples
    --------
    >>> PhaseLine((8.0, 11.0), 12, -10.0, -90.0, 1.5, -270.0).value(9.0)
    -180.0
    """

    band: tuple[float, float]
    points: int
    slope: float
    intercept: float
    rms_residual: float
    phase_2w180: float

    def value(self, w: float | np.ndarray) -> float | np.ndarray:
        """Phase of the line at ``w`` [deg]."""
        return self.intercept + self.slope * w

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"band": list(self.band), "points": self.points, "slope_deg_per_rad_s": self.slope,
                "intercept_deg": self.intercept, "rms_residual_deg": self.rms_residual,
                "phase_2w180_deg": self.phase_2w180, "equivalent_delay_s": -self.slope / DEG}


@dataclass(frozen=True)
class HQMetrics:
    """Bandwidth and phase delay of an attitude response, with how each number was found.

    Attributes
    ----------
    source : str
        ``"model"`` (exact response) or ``"measured"`` (frequency-response points).
    response_type : str
        ``"rate"`` (bandwidth = lesser of phase and gain bandwidths) or ``"attitude"``
        (bandwidth = phase bandwidth).
    response_type_reason : str
        Given, or what the automatic detection saw.
    w180 : float or None
        First frequency where the phase falls through -180 deg [rad/s].
    bandwidth_phase, bandwidth_gain : float or None
        Phase (-135 deg) and gain (+6 dB over the gain at ``w180``) bandwidths [rad/s].
    bandwidth : float or None
        The bandwidth by the response type's rule [rad/s].
    bandwidth_limit : str
        ``"phase"`` or ``"gain"``: which definition sets ``bandwidth`` (``"none"`` if undefined,
        ``"below_data"`` when a crossing the rule needs lies below the lowest measured frequency).
    phase_delay : float or None
        ``tau_p`` [s].
    gain_w180_db : float or None
        Gain at ``w180`` [dB].
    phase_2w180 : float or None
        Phase at ``2 w180`` used for ``tau_p`` [deg].
    phase_method : str
        ``"exact"`` (model), ``"raw"`` (measured phase interpolated) or ``"line"`` (least-squares line).
    phase_line : PhaseLine or None
        The fitted line when one was computed.
    crossings : dict
        Every crossing found for ``-180``, ``-135`` and the gain level, so the choice is visible.
    uncertainty : dict or None
        1-sigma uncertainty of each metric (same units) from the coherence; measured data only.
    coherence_at : dict or None
        Coherence at each metric's frequency.
    notes : tuple of str
        Choices made (which crossing, why the line was used, assumptions).
    below_data : tuple of str
        Bandwidths (``"phase"``, ``"gain"``) whose crossing lies below the lowest measured frequency, so that the
        data bound them from above only (measured data only).
    w, magnitude_db, phase_deg, coherence : numpy.ndarray or None
        The curve the metrics were read from (for figures; left out of ``to_dict`` by default).

    Examples
    --------
    >>> from synth.ident.hq import hq_from_plant
    >>> from synth.plant import Plant
    >>> m = hq_from_plant(Plant.from_string("1/(s^2+s+1)", delay=0.1))
    >>> round(m.w180, 3), round(m.phase_delay, 4), m.response_type
    (3.262, 0.0761, 'attitude')
    """

    source: str
    response_type: str
    response_type_reason: str
    w180: float | None
    bandwidth_phase: float | None
    bandwidth_gain: float | None
    bandwidth: float | None
    bandwidth_limit: str
    phase_delay: float | None
    gain_w180_db: float | None
    phase_2w180: float | None
    phase_method: str
    phase_line: PhaseLine | None = None
    crossings: dict[str, list[Crossing]] = field(default_factory=dict)
    uncertainty: dict[str, float | None] | None = None
    coherence_at: dict[str, float | None] | None = None
    notes: tuple[str, ...] = ()
    below_data: tuple[str, ...] = ()
    w: np.ndarray | None = field(default=None, repr=False)
    magnitude_db: np.ndarray | None = field(default=None, repr=False)
    phase_deg: np.ndarray | None = field(default=None, repr=False)
    coherence: np.ndarray | None = field(default=None, repr=False)

    def to_dict(self, curves: bool = False) -> dict[str, Any]:
        """JSON-ready form; ``curves=True`` adds the frequency response the metrics came from.

        Examples
        --------
        >>> from synth.ident.hq import hq_from_plant
        >>> from synth.plant import Plant
        >>> d = hq_from_plant(Plant.from_string("1/(s*(s+1))", delay=0.1)).to_dict()
        >>> d["bandwidth_limit"], round(d["bandwidth"], 3)
        ('phase', 0.844)
        """
        out: dict[str, Any] = {
            "source": self.source, "response_type": self.response_type,
            "response_type_reason": self.response_type_reason,
            "w180": self.w180, "bandwidth_phase": self.bandwidth_phase, "bandwidth_gain": self.bandwidth_gain,
            "bandwidth": self.bandwidth, "bandwidth_limit": self.bandwidth_limit, "phase_delay": self.phase_delay,
            "gain_w180_db": self.gain_w180_db, "phase_2w180_deg": self.phase_2w180,
            "phase_method": self.phase_method,
            "phase_line": self.phase_line.to_dict() if self.phase_line else None,
            "crossings": {k: [c.to_dict() for c in v] for k, v in self.crossings.items()},
            "uncertainty": self.uncertainty, "coherence_at": self.coherence_at,
            "units": {"w180": "rad/s", "bandwidth_phase": "rad/s", "bandwidth_gain": "rad/s", "bandwidth": "rad/s",
                      "phase_delay": "s", "gain_w180_db": "dB", "phase_2w180_deg": "deg"},
            "notes": list(self.notes),
        }
        if self.below_data:
            out["below_data"] = {"bandwidths": list(self.below_data), "lowest_frequency": float(self.w[0])}
        if curves and self.w is not None:
            out["curves"] = {"w": self.w, "magnitude_db": self.magnitude_db, "phase_deg": self.phase_deg,
                             "coherence": self.coherence}
        return out


def check_choice(value: str, allowed: tuple[str, ...], name: str) -> None:
    """Raise a one-line ModelError unless ``value`` is one of ``allowed`` (the option ``name``).

    Examples
    --------
    >>> check_choice("rate", RESPONSE_TYPES, "response_type")
    >>> check_choice("pitch", RESPONSE_TYPES, "response_type")
    Traceback (most recent call last):
    synth.errors.ModelError: response_type must be one of auto, rate, attitude; got 'pitch'
    """
    if value not in allowed:
        raise ModelError(f"{name} must be one of {', '.join(allowed)}; got {value!r}")


def _first_down(crossings: list[Crossing]) -> Crossing | None:
    return next((c for c in crossings if c.direction < 0), None)


def _describe(name: str, crossings: list[Crossing], used: Crossing | None, why: str) -> str | None:
    if len(crossings) <= 1:
        return None
    listed = ", ".join(f"{c.w:.4g} ({'down' if c.direction < 0 else 'up'})" for c in crossings)
    chosen = f"{used.w:.4g} rad/s" if used else "none"
    return f"{name}: the curve crosses {len(crossings)} times ({listed} rad/s); used {chosen}: {why}"


@dataclass
class ResponseCurve:
    """A frequency response the metrics are read from: grid values and (for models) exact functions.

    Attributes
    ----------
    w : numpy.ndarray
        Frequencies [rad/s].
    mag_db, phase : numpy.ndarray
        Gain [dB] and unwrapped phase [deg] on ``w``.
    mag_at, phase_at : callable
        Gain and phase at any frequency (exact for a model, interpolated for measurements).
    exact : bool
        ``mag_at``/``phase_at`` are exact (crossings refined by Brent's method).

    Examples
    --------
    >>> w = np.logspace(-1, 1, 5)
    >>> ResponseCurve(w, -20 * np.log10(w), -90 - 20 * w, lambda x: 0.0, lambda x: 0.0, exact=False).exact
    False
    """

    w: np.ndarray
    mag_db: np.ndarray
    phase: np.ndarray
    mag_at: Callable[[float], float]
    phase_at: Callable[[float], float]
    exact: bool


def crossing_metrics(curve: ResponseCurve, notes: list[str]) -> dict[str, Any]:
    """``w180``, the phase and gain bandwidths and the gain at ``w180``, read off a curve.

    Every crossing found is kept (``"crossings"``) and the choice among several is explained
    in ``notes`` (appended to).

    Returns
    -------
    dict
        ``w180``, ``w135``, ``wg`` [rad/s], ``g180`` [dB] (None when undefined) and ``crossings``.

    Examples
    --------
    >>> w = np.logspace(-1, 1, 201)
    >>> curve = ResponseCurve(w, -20 * np.log10(w), -90 - 20 * w,
    ...                       lambda x: float(-20 * np.log10(x)), lambda x: -90 - 20 * x, exact=True)
    >>> found = crossing_metrics(curve, [])
    >>> round(found["w180"], 3), round(found["w135"], 3), round(found["wg"], 3)
    (4.5, 2.25, 2.255)
    """
    fn = (lambda f: f) if curve.exact else (lambda f: None)
    c180 = find_crossings(curve.w, curve.phase, -180.0, fn(curve.phase_at))
    c135 = find_crossings(curve.w, curve.phase, -135.0, fn(curve.phase_at))
    x180, x135 = _first_down(c180), _first_down(c135)
    if curve.phase[0] <= -180.0:
        notes.append("the phase starts at or below -180 deg; w180 is its first downward crossing of -180 deg after that")
    for text in (_describe("w180", c180, x180, "the first downward crossing of -180 deg (neutral stability)"),
                 _describe("bandwidth_phase", c135, x135, "the first downward crossing of -135 deg; beyond it the "
                           "phase margin is short of 45 deg")):
        if text:
            notes.append(text)
    w180 = x180.w if x180 else None
    out: dict[str, Any] = {"w180": w180, "w135": x135.w if x135 else None, "wg": None, "g180": None,
                           "crossings": {"phase_-180": c180, "phase_-135": c135}, "below": []}
    if not curve.exact and curve.phase[0] < -135.0:
        # measured data whose phase is already past -135 deg at the lowest frequency: the first downward crossing
        # lies below the data; a later one inside it is not the phase bandwidth
        out["w135"] = None
        out["below"].append("phase")
        notes.append(f"the phase is {curve.phase[0]:.1f} deg at the lowest measured frequency ({curve.w[0]:.4g} "
                     f"rad/s), already below -135 deg: the phase bandwidth lies below the data (< {curve.w[0]:.4g} "
                     "rad/s); measure lower frequencies to find it")
    if w180 is None:
        notes.append("the phase never falls through -180 deg in the frequency range: w180, the gain bandwidth and "
                     "the phase delay are undefined")
        return out
    g180 = float(curve.mag_at(w180))
    level = g180 + GAIN_MARGIN_DB
    cg = [c for c in find_crossings(curve.w, curve.mag_db, level, fn(curve.mag_at)) if c.w < w180]
    down = [c for c in cg if c.direction < 0]
    xg = down[-1] if down else None
    text = _describe("bandwidth_gain", cg, xg, "the highest downward crossing below w180: the crossover of the "
                     "largest pilot gain that keeps 6 dB of gain margin")
    if text:
        notes.append(text)
    if xg is None and not curve.exact and curve.mag_db[0] < level:
        out["below"].append("gain")
        notes.append(f"the gain is {curve.mag_db[0]:.4g} dB at the lowest measured frequency ({curve.w[0]:.4g} "
                     f"rad/s), already below {level:.4g} dB (6 dB above the gain at w180): the gain bandwidth "
                     f"lies below the data (< {curve.w[0]:.4g} rad/s); measure lower frequencies to find it")
    elif xg is None:
        notes.append(f"the gain never falls through {level:.4g} dB (6 dB above the gain at w180) below w180: "
                     "the gain bandwidth is undefined")
    out.update(wg=xg.w if xg else None, g180=g180, crossings={**out["crossings"], "gain_+6dB": cg})
    return out


def bandwidth_by_type(response_type: str, w135: float | None, wg: float | None,
                      below: tuple[str, ...] | list[str] = ()) -> tuple[float | None, str]:
    """The bandwidth by the response type's rule and which definition sets it.

    An attitude response type takes the phase bandwidth, a rate type the lesser of the two. A bandwidth the rule
    needs whose crossing lies below the data (``below``) leaves the bandwidth unknown (``"below_data"``): below the
    lowest measured frequency, so no measured crossing can be the lesser.

    Examples
    --------
    >>> bandwidth_by_type("rate", 1.4, 2.3), bandwidth_by_type("attitude", None, 2.3)
    ((1.4, 'phase'), (None, 'none'))
    >>> bandwidth_by_type("rate", None, 1.7, below=["phase"])
    (None, 'below_data')
    """
    if "phase" in below or (response_type != "attitude" and "gain" in below):
        return None, "below_data"
    if response_type == "attitude":
        return (w135, "phase") if w135 is not None else (None, "none")
    candidates = [(v, k) for v, k in ((w135, "phase"), (wg, "gain")) if v is not None]
    if not candidates:
        return None, "none"
    return min(candidates)

