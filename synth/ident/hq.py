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
``log w`` between measured points. For measured data with a rough phase the phase at ``2 w180``
comes from a least-squares line through the phase between ``w180`` and ``2 w180`` (seed 2,
fig. 15), and every metric gets a 1-sigma uncertainty from the coherence: the random error of a
spectral estimate with ``n_d`` averages is ``sqrt(1 - g^2) / (|g| sqrt(2 n_d))`` (relative in
magnitude, radians in phase), propagated through the slope of the curve at the crossing.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import brentq

from synth.errors import DataError, ModelError
from synth.plant import Plant

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


def coherence_random_error(coherence: np.ndarray | float, averages: float) -> np.ndarray:
    """Normalized random error of a frequency-response estimate from its coherence.

    ``e = sqrt(1 - g^2) / (|g| sqrt(2 n_d))`` with ``g^2`` the coherence and ``n_d`` the number of
    averages (independent segments). It is the relative 1-sigma error of the magnitude and the
    1-sigma error of the phase in radians.

    Examples
    --------
    >>> round(float(coherence_random_error(0.8, 10)), 4)
    0.1118
    """
    g2 = np.clip(np.asarray(coherence, float), 1e-12, 1.0)
    return np.sqrt(1.0 - g2) / (np.sqrt(g2) * np.sqrt(2.0 * averages))


# --------------------------------------------------------------------------- exact phase of a model
def _zeros(plant: Plant) -> np.ndarray:
    num = np.trim_zeros(plant.num, "f")
    return np.roots(num) if num.size > 1 else np.array([], complex)


def _low_frequency_form(plant: Plant) -> tuple[int, float]:
    """Integrators (poles minus zeros at s = 0) and the sign of the low-frequency gain."""
    num, den = np.trim_zeros(plant.num, "f"), plant.den
    nz0 = int(num.size - np.trim_zeros(num, "b").size)
    np0 = int(den.size - np.trim_zeros(den, "b").size)
    c = np.trim_zeros(num, "b")[-1] / np.trim_zeros(den, "b")[-1]
    return np0 - nz0, float(np.sign(c))


def _factor_phase(roots: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Sum over ``roots`` of the angle of ``jw - r`` [rad], each on a branch continuous in ``w >= 0``."""
    total = np.zeros_like(w)
    for r in roots:
        y = w - r.imag
        if r.real > 0:  # right half-plane: the branch through pi is the continuous one
            total += np.pi - np.arctan2(y, r.real)
        else:
            total += np.arctan2(y, -r.real)
    return total


def _characteristic_frequencies(plant: Plant) -> np.ndarray:
    roots = np.concatenate([plant.poles(), _zeros(plant)])
    chars = np.abs(roots[np.abs(roots) > 1e-12])
    if plant.delay > 0:
        chars = np.append(chars, 1.0 / plant.delay)
    return chars


def continuous_phase(plant: Plant, w: Sequence[float] | np.ndarray) -> np.ndarray:
    """Unwrapped phase of ``plant(jw)`` in degrees, continuous in ``w`` (exact, delay included).

    The phase is the sum of the angles of ``jw - z`` over the zeros minus those over the poles,
    each on a branch continuous for ``w >= 0``, minus ``w * delay``, shifted by a multiple of
    360 deg so that it starts at -90 deg times the number of integrators (-180 deg more for a
    negative low-frequency gain).

    Examples
    --------
    >>> G = Plant.from_string("1/(s^2+s+1)", delay=0.1)
    >>> continuous_phase(G, [1e-6, 1.0, 10.0]).round(2)
    array([  -0.  ,  -95.73, -231.53])
    """
    w = np.asarray(w, float)
    if not np.any(plant.num):
        raise ModelError("the transfer function is zero; it has no phase")
    zeros, poles = _zeros(plant), plant.poles()
    lead = np.pi if np.trim_zeros(plant.num, "f")[0] < 0 else 0.0  # angle of the leading gain
    integrators, sign = _low_frequency_form(plant)
    start = -np.pi / 2 * integrators + (0.0 if sign > 0 else -np.pi)
    chars = _characteristic_frequencies(plant)
    w0 = np.array([1e-9 * (chars.min() if chars.size else 1.0)])
    ref = lead + float((_factor_phase(zeros, w0) - _factor_phase(poles, w0))[0])
    shift = lead + 2 * np.pi * np.round((start - ref) / (2 * np.pi))
    return (_factor_phase(zeros, w) - _factor_phase(poles, w) - w * plant.delay + shift) * DEG


def model_grid(plant: Plant, points_per_decade: int = 200) -> np.ndarray:
    """Logarithmic frequency grid [rad/s] for crossing searches on a model.

    It spans three decades below the slowest and two above the fastest characteristic
    frequency (pole and zero moduli, ``1/delay``), with extra points across the resonance of
    every lightly damped pole or zero so that narrow phase features are bracketed.

    Examples
    --------
    >>> w = model_grid(Plant.from_string("1/(s^2+s+1)", delay=0.1))
    >>> float(w[0]), float(w[-1])
    (0.001, 1000.0)
    """
    chars = _characteristic_frequencies(plant)
    lo, hi = (chars.min() / 1e3, chars.max() * 1e2) if chars.size else (1e-3, 1e3)
    n = int(np.ceil(np.log10(hi / lo) * points_per_decade)) + 1
    parts = [np.logspace(np.log10(lo), np.log10(hi), n)]
    for r in np.concatenate([plant.poles(), _zeros(plant)]):
        wn = abs(r)
        if wn > 0 and abs(r.imag) > 0:
            zeta = -r.real / wn
            if abs(zeta) < 0.05:
                width = max(10 * abs(zeta), 1e-6)
                parts.append(wn * np.linspace(1 - width, 1 + width, 201))
    w = np.unique(np.concatenate(parts))
    return w[w > 0]


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
        ``"phase"`` or ``"gain"``: which definition sets ``bandwidth`` (``"none"`` if undefined).
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
    w, magnitude_db, phase_deg, coherence : numpy.ndarray or None
        The curve the metrics were read from (for figures; left out of ``to_dict`` by default).

    Examples
    --------
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
    w: np.ndarray | None = field(default=None, repr=False)
    magnitude_db: np.ndarray | None = field(default=None, repr=False)
    phase_deg: np.ndarray | None = field(default=None, repr=False)
    coherence: np.ndarray | None = field(default=None, repr=False)

    def to_dict(self, curves: bool = False) -> dict[str, Any]:
        """JSON-ready form; ``curves=True`` adds the frequency response the metrics came from.

        Examples
        --------
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
        if curves and self.w is not None:
            out["curves"] = {"w": self.w, "magnitude_db": self.magnitude_db, "phase_deg": self.phase_deg,
                             "coherence": self.coherence}
        return out


def _check_choice(value: str, allowed: tuple[str, ...], name: str) -> None:
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
class _Curve:
    """A frequency response the metrics are read from: grid values and (for models) exact functions."""

    w: np.ndarray
    mag_db: np.ndarray
    phase: np.ndarray
    mag_at: Callable[[float], float]
    phase_at: Callable[[float], float]
    exact: bool


def _crossing_metrics(curve: _Curve, notes: list[str]) -> dict[str, Any]:
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
                           "crossings": {"phase_-180": c180, "phase_-135": c135}}
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
    if xg is None:
        notes.append(f"the gain never falls through {level:.4g} dB (6 dB above the gain at w180) below w180: "
                     "the gain bandwidth is undefined")
    out.update(wg=xg.w if xg else None, g180=g180, crossings={**out["crossings"], "gain_+6dB": cg})
    return out


def _bandwidth(response_type: str, w135: float | None, wg: float | None) -> tuple[float | None, str]:
    if response_type == "attitude":
        return (w135, "phase") if w135 is not None else (None, "none")
    candidates = [(v, k) for v, k in ((w135, "phase"), (wg, "gain")) if v is not None]
    if not candidates:
        return None, "none"
    return min(candidates)


def hq_from_plant(plant: Plant, response_type: str = "auto") -> HQMetrics:
    """Bandwidth and phase delay of a model's attitude response, from its exact frequency response.

    Parameters
    ----------
    plant : Plant
        The attitude response to the control input (delay exact).
    response_type : {"auto", "rate", "attitude"}
        ``"auto"``: one integrator (a pole at ``s = 0``) means a rate response type, none an
        attitude response type; anything else falls back to the rate rule (the lesser bandwidth).

    Returns
    -------
    HQMetrics

    Raises
    ------
    ModelError
        An unknown ``response_type`` or a zero transfer function.

    Examples
    --------
    >>> m = hq_from_plant(Plant.from_string("4/(s*(0.1*s+1))", delay=0.05))
    >>> [round(x, 2) for x in (m.w180, m.bandwidth_phase, m.bandwidth_gain)], round(m.phase_delay, 4)
    ([13.07, 5.56, 8.29], 0.036)
    """
    _check_choice(response_type, RESPONSE_TYPES, "response_type")
    if not np.any(plant.num):
        raise ModelError("the transfer function is zero; it has no phase")
    notes: list[str] = []
    integrators, sign = _low_frequency_form(plant)
    if sign < 0:
        plant = plant.scaled(-1.0)
        notes.append("the low-frequency gain is negative; the metrics are those of -G (control polarity reversed)")
    reason = "given"
    if response_type == "auto":
        if integrators == 1:
            response_type, reason = "rate", "auto: one integrator at s = 0 (attitude follows the integral of the input)"
        elif integrators == 0:
            response_type, reason = "attitude", "auto: no integrator at s = 0 (finite low-frequency gain)"
        else:
            response_type = "rate"
            reason = f"auto: {integrators} net integrators at s = 0, neither type; the rate rule (lesser) is used"
    w = model_grid(plant)
    curve = _Curve(w, 20 * np.log10(np.abs(plant.freqresp(w))), continuous_phase(plant, w),
                   lambda x: float(20 * np.log10(np.abs(plant.freqresp([x])[0]))),
                   lambda x: float(continuous_phase(plant, [x])[0]), exact=True)
    found = _crossing_metrics(curve, notes)
    w180 = found["w180"]
    phase2 = tau = None
    if w180 is not None:
        phase2 = curve.phase_at(2 * w180)
        tau = -(phase2 + 180.0) / (DEG * 2 * w180)
    bw, limit = _bandwidth(response_type, found["w135"], found["wg"])
    return HQMetrics("model", response_type, reason, w180, found["w135"], found["wg"], bw, limit, tau,
                     found["g180"], phase2, "exact", None, found["crossings"], None, None, tuple(notes),
                     w, curve.mag_db, curve.phase, None)


# --------------------------------------------------------------------------- measured frequency response
def _validate_frd(w: Any, H: Any, coherence: Any, averages: float | None) -> tuple[np.ndarray, ...]:
    try:
        w = np.asarray(w, float).ravel()
        H = np.asarray(H, complex).ravel()
    except (TypeError, ValueError):
        raise DataError("w and H must be numbers", where="frequency response") from None
    if w.size != H.size:
        raise DataError(f"w has {w.size} points but H has {H.size}", where="frequency response")
    if w.size < 4:
        raise DataError(f"need at least 4 frequency points, got {w.size}", where="frequency response")
    if not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise DataError("w must be finite and > 0 rad/s", where="frequency response: w")
    if np.any(np.diff(w) <= 0):
        k = int(np.flatnonzero(np.diff(w) <= 0)[0]) + 1
        raise DataError(f"frequencies must increase strictly (point {k}, w = {w[k]:g} rad/s)",
                        where="frequency response: w")
    if not np.all(np.isfinite(H)) or np.any(H == 0):
        k = int(np.flatnonzero(~np.isfinite(H) | (H == 0))[0])
        raise DataError(f"the response must be finite and non-zero (point {k}, w = {w[k]:g} rad/s)",
                        where="frequency response: H")
    g2 = None
    if coherence is not None:
        g2 = np.asarray(coherence, float).ravel()
        if g2.size != w.size:
            raise DataError(f"coherence has {g2.size} points, w has {w.size}", where="frequency response: coherence")
        if not np.all(np.isfinite(g2)) or np.any(g2 < 0) or np.any(g2 > 1):
            raise DataError("coherence must lie in [0, 1]", where="frequency response: coherence")
    if averages is not None and not (np.isfinite(averages) and averages >= 1):
        raise DataError(f"averages must be >= 1, got {averages!r}", where="frequency response: averages")
    return w, H, g2


def _interp_log(w: np.ndarray, y: np.ndarray) -> Callable[[float], float]:
    lw = np.log(w)
    return lambda x: float(np.interp(np.log(x), lw, y))


def _local_slope(w: np.ndarray, y: np.ndarray, x: float, half: int = 2) -> float:
    """Least-squares slope dy/dw [per rad/s] of the points nearest ``x`` (``half`` on each side)."""
    k = int(np.searchsorted(w, x))
    lo, hi = max(0, k - half), min(w.size, k + half)
    if hi - lo < 2:
        lo, hi = max(0, hi - 2), max(hi, 2)
    return float(np.polyfit(w[lo:hi], y[lo:hi], 1)[0])


def _detect_type(w: np.ndarray, phase: np.ndarray, g2: np.ndarray | None) -> tuple[str, str]:
    use = np.ones(w.size, bool) if g2 is None else g2 >= 0.6
    if np.count_nonzero(use) < 3:
        use = np.ones(w.size, bool)
    idx = np.flatnonzero(use)[:5]
    p = float(np.median(phase[idx]))
    where = f"median phase {p:.0f} deg over the {idx.size} lowest frequencies ({w[idx[0]]:.3g}-{w[idx[-1]]:.3g} rad/s)"
    if abs(p + 90) < 45:
        return "rate", f"auto: {where}, near -90 deg (an integrator)"
    if abs(p) < 45:
        return "attitude", f"auto: {where}, near 0 deg (finite low-frequency gain)"
    return "rate", f"auto: {where}, neither near 0 nor -90 deg; the rate rule (lesser) is used"


def fit_phase_line(w: np.ndarray, phase_deg: np.ndarray, band: tuple[float, float],
                   sigma_deg: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, float, int]:
    """Weighted least-squares line ``phase = a + b w`` through the points with ``w`` in ``band``.

    Returns the coefficients ``[a, b]``, their covariance (from ``sigma_deg`` when given, scaled
    up by the scatter about the line when that is larger; from the scatter alone otherwise),
    the root-mean-square residual [deg] and the number of points.

    Raises
    ------
    DataError
        Fewer than 3 points in the band.

    Examples
    --------
    >>> w = np.linspace(1, 10, 10)
    >>> coef, cov, rms, n = fit_phase_line(w, -100 - 5.73 * w, (2.0, 8.0))
    >>> coef.round(3).tolist(), n
    ([-100.0, -5.73], 7)
    """
    sel = (w >= band[0]) & (w <= band[1])
    n = int(np.count_nonzero(sel))
    if n < 3:
        raise DataError(f"only {n} point(s) between {band[0]:.4g} and {band[1]:.4g} rad/s; the phase line needs 3",
                        where="frequency response")
    x, y = w[sel], phase_deg[sel]
    s = np.ones(n) if sigma_deg is None else np.maximum(sigma_deg[sel], 1e-9)
    A = np.column_stack([np.ones(n), x]) / s[:, None]
    coef, *_ = np.linalg.lstsq(A, y / s, rcond=None)
    resid = y - (coef[0] + coef[1] * x)
    rms = float(np.sqrt(np.mean(resid**2)))
    cov = np.linalg.inv(A.T @ A)
    chi2 = float(np.sum((resid / s) ** 2)) / max(n - 2, 1)
    cov = cov * (chi2 if sigma_deg is None else max(chi2, 1.0))
    return coef, cov, rms, n


def _uncertainties(w: np.ndarray, mag: np.ndarray, phase: np.ndarray, g2: np.ndarray, n_d: float,
                   found: dict[str, Any], tau: float | None, phase2: float | None, sig_phi2: float | None,
                   slope2: float | None, limit: str) -> tuple[dict[str, float | None], dict[str, float | None]]:
    """1-sigma uncertainty of each metric: the random error at the crossing over the curve's slope there."""
    coh_at = _interp_log(w, g2)

    def sig_phase(x: float) -> float:  # deg
        return float(coherence_random_error(coh_at(x), n_d)) * DEG

    def sig_db(x: float) -> float:
        return float(coherence_random_error(coh_at(x), n_d)) * 20 / np.log(10)

    w180, w135, wg = found["w180"], found["w135"], found["wg"]
    unc: dict[str, float | None] = dict.fromkeys(("w180", "bandwidth_phase", "bandwidth_gain", "bandwidth",
                                                  "phase_delay"))
    coh = {k: (coh_at(v) if v is not None and v <= w[-1] else None)
           for k, v in (("w180", w180), ("bandwidth_phase", w135), ("bandwidth_gain", wg),
                        ("2w180", 2 * w180 if w180 is not None else None))}
    if w135 is not None:
        unc["bandwidth_phase"] = sig_phase(w135) / abs(_local_slope(w, phase, w135))
    if w180 is not None:
        s180 = sig_phase(w180) / abs(_local_slope(w, phase, w180))
        unc["w180"] = s180
        if wg is not None:
            sf = np.sqrt(sig_db(wg) ** 2 + sig_db(w180) ** 2 + (_local_slope(w, mag, w180) * s180) ** 2)
            unc["bandwidth_gain"] = float(sf / abs(_local_slope(w, mag, wg)))
        if tau is not None and phase2 is not None and sig_phi2 is not None and slope2 is not None:
            w2 = 2 * w180
            dtau_dw = -2 * slope2 / (DEG * w2) + (phase2 + 180.0) * 2 / (DEG * w2**2)
            dtau_dphi = -1.0 / (DEG * w2)
            unc["phase_delay"] = float(np.hypot(dtau_dw * s180, dtau_dphi * sig_phi2))
    unc["bandwidth"] = {"phase": unc["bandwidth_phase"], "gain": unc["bandwidth_gain"]}.get(limit)
    return unc, coh


def hq_from_frd(w: Any, H: Any, coherence: Any = None, averages: float | None = None,
                response_type: str = "auto", phase_fit: str = "auto", fit_band: tuple[float, float] | None = None,
                rough_deg: float = 5.0) -> HQMetrics:
    """Bandwidth and phase delay from a measured attitude frequency response.

    Parameters
    ----------
    w : array_like
        Frequencies [rad/s], strictly increasing, > 0.
    H : array_like of complex
        Frequency response at ``w``. The phase is unwrapped along ``w`` and shifted by a multiple of
        360 deg so that the first point lies in (-270, 90] deg.
    coherence : array_like, optional
        Coherence ``gamma^2`` at ``w``; gives every metric a 1-sigma uncertainty.
    averages : float, optional
        Number of averages ``n_d`` behind the estimate; without it ``n_d = 1`` is assumed (the
        largest error; stated in ``notes``).
    response_type : {"auto", "rate", "attitude"}
        ``"auto"`` reads the median phase of the lowest frequencies: near -90 deg a rate type,
        near 0 deg an attitude type, otherwise the rate rule.
    phase_fit : {"auto", "raw", "line"}
        How the phase at ``2 w180`` is read. ``"raw"``: interpolated; ``"line"``: from the
        least-squares line through the phase on ``fit_band`` (seed 2, fig. 15). ``"auto"`` uses
        the line when ``2 w180`` lies beyond the data, when the coherence there is below 0.8, or
        when the phase between ``w180`` and ``2 w180`` is rough (points scatter more than
        ``rough_deg`` RMS about a quadratic in ``w``).
    fit_band : tuple of float, optional
        Band of the line [rad/s]; default ``(w180, 2 w180)``.
    rough_deg : float
        Roughness threshold of ``"auto"`` [deg].

    Returns
    -------
    HQMetrics

    Examples
    --------
    >>> G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    >>> w = np.logspace(-1, 1.5, 60)
    >>> m = hq_from_frd(w, G.freqresp(w), coherence=np.full(60, 0.9), averages=10)
    >>> round(m.w180, 2), m.response_type, round(m.uncertainty["w180"], 3)
    (3.11, 'rate', 0.395)
    """
    _check_choice(response_type, RESPONSE_TYPES, "response_type")
    _check_choice(phase_fit, PHASE_FITS, "phase_fit")
    w, H, g2 = _validate_frd(w, H, coherence, averages)
    notes: list[str] = []
    phase = np.unwrap(np.angle(H)) * DEG
    phase -= 360.0 * np.ceil((phase[0] - 90.0) / 360.0)
    mag = 20 * np.log10(np.abs(H))
    reason = "given"
    if response_type == "auto":
        response_type, reason = _detect_type(w, phase, g2)
    curve = _Curve(w, mag, phase, _interp_log(w, mag), _interp_log(w, phase), exact=False)
    found = _crossing_metrics(curve, notes)
    w180, w135, wg = found["w180"], found["w135"], found["wg"]
    coh_at = _interp_log(w, g2) if g2 is not None else None
    n_d = float(averages) if averages is not None else 1.0
    if g2 is not None and averages is None:
        notes.append("number of averages not given: n_d = 1 assumed, so the uncertainties are upper bounds")
    sig_phase_pts = coherence_random_error(g2, n_d) * DEG if g2 is not None else None

    phase2 = tau = None
    method, line = "raw", None
    sig_phi2 = slope2 = None
    if w180 is not None:
        w2 = 2 * w180
        band = fit_band or (w180, min(w2, w[-1]))
        in_band = (w >= band[0]) & (w <= band[1])
        reasons = []
        if w2 > w[-1]:
            reasons.append(f"2 w180 = {w2:.4g} rad/s lies beyond the data (up to {w[-1]:.4g} rad/s)")
        elif coh_at and coh_at(w2) < COHERENCE_OK:
            reasons.append(f"the coherence at 2 w180 is {coh_at(w2):.2f} < {COHERENCE_OK}")
        if np.count_nonzero(in_band) >= 4:
            x, y = w[in_band], phase[in_band]
            rough = float(np.sqrt(np.mean((y - np.polyval(np.polyfit(x, y, 2), x)) ** 2)))
            if rough > rough_deg:
                reasons.append(f"the phase between {band[0]:.4g} and {band[1]:.4g} rad/s scatters {rough:.2g} deg RMS "
                               f"about a smooth curve (> {rough_deg:g} deg)")
        use_line = phase_fit == "line" or (phase_fit == "auto" and bool(reasons))
        if phase_fit == "raw" and w2 > w[-1]:
            raise DataError(f"2 w180 = {w2:.4g} rad/s lies beyond the data (up to {w[-1]:.4g} rad/s); "
                            "use the phase line", where="frequency response")
        if use_line:
            coef, cov, rms, n = fit_phase_line(w, phase, band, sig_phase_pts)
            phase2 = float(coef[0] + coef[1] * w2)
            line = PhaseLine((float(band[0]), float(band[1])), n, float(coef[1]), float(coef[0]), rms, phase2)
            method = "line"
            sig_phi2 = float(np.sqrt(np.array([1.0, w2]) @ cov @ np.array([1.0, w2])))
            slope2 = float(coef[1])
            why = "; ".join(reasons) if reasons else "requested"
            notes.append(f"phase at 2 w180 from the least-squares line through the phase on {band[0]:.4g}-"
                         f"{band[1]:.4g} rad/s ({n} points, slope {coef[1]:.3g} deg/(rad/s)): {why}")
        else:
            phase2 = curve.phase_at(w2)
            if coh_at:
                sig_phi2 = float(coherence_random_error(coh_at(w2), n_d)) * DEG
            slope2 = _local_slope(w, phase, w2)
        tau = -(phase2 + 180.0) / (DEG * w2)

    bw, limit = _bandwidth(response_type, w135, wg)
    unc = coh = None
    if g2 is not None:
        unc, coh = _uncertainties(w, mag, phase, g2, n_d, found, tau, phase2, sig_phi2, slope2, limit)
        low = [k for k, v in coh.items() if v is not None and v < COHERENCE_OK]
        if low:
            notes.append(f"coherence below {COHERENCE_OK} (seed 2's accuracy criterion) at: {', '.join(low)}")
    return HQMetrics("measured", response_type, reason, w180, w135, wg, bw, limit, tau, found["g180"], phase2,
                     method, line, found["crossings"], unc, coh, tuple(notes), w, mag, phase, g2)
