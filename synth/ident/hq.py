"""Handling-qualities bandwidth and phase delay, estimated from a model or a measured frequency response.

The definitions and the result are in :mod:`synth.ident.hq_metrics`. From a model the curve is exact
(:mod:`synth.ident.model_phase`). For measured data with a rough phase the phase at ``2 w180``
comes from a least-squares line through the phase between ``w180`` and ``2 w180`` (seed 2,
fig. 15), and every metric gets a 1-sigma uncertainty from the coherence: the random error of a
spectral estimate with ``n_d`` averages is ``sqrt(1 - g^2) / (|g| sqrt(2 n_d))`` (relative in
magnitude, radians in phase), propagated through the slope of the curve at the crossing.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from synth.errors import DataError, ModelError
from synth.ident.hq_metrics import (
    COHERENCE_OK,
    DEG,
    PHASE_FITS,
    RESPONSE_TYPES,
    HQMetrics,
    PhaseLine,
    ResponseCurve,
    bandwidth_by_type,
    check_choice,
    crossing_metrics,
)
from synth.ident.model_phase import anchored_phase, continuous_phase, low_frequency_form, model_grid
from synth.plant import Plant

__all__ = ["CROSSING_DECADES", "coherence_random_error", "crossing_sigma", "fit_phase_line", "hq_from_frd",
           "hq_from_plant"]

CROSSING_DECADES = 0.05
"""Half-width [decades] of the points whose line gives a crossing's slope and scatter (about 12 % either side)."""


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
    from synth.ident.coherence import random_error

    return random_error(np.clip(np.asarray(coherence, float), 1e-12, 1.0), averages)  # finite at gamma^2 = 0


# --------------------------------------------------------------------------- a model's exact response
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
    check_choice(response_type, RESPONSE_TYPES, "response_type")
    if not np.any(plant.num):
        raise ModelError("the transfer function is zero; it has no phase")
    notes: list[str] = []
    unstable = [complex(x) for x in plant.poles() if x.real > 1e-9 * max(1.0, abs(x))]
    if unstable:
        notes.append(f"the model is unstable ({len(unstable)} pole(s) in the right half-plane, the largest real part "
                     f"{max(x.real for x in unstable):.4g} rad/s): the bandwidth and phase delay criteria are meant "
                     "for a stable response; these numbers are read off its frequency response only")
    integrators, sign = low_frequency_form(plant)
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
    curve = ResponseCurve(w, 20 * np.log10(np.abs(plant.freqresp(w))), continuous_phase(plant, w),
                   lambda x: float(20 * np.log10(np.abs(plant.freqresp([x])[0]))),
                   lambda x: float(continuous_phase(plant, [x])[0]), exact=True)
    found = crossing_metrics(curve, notes)
    w180 = found["w180"]
    phase2 = tau = None
    if w180 is not None:
        phase2 = curve.phase_at(2 * w180)
        tau = -(phase2 + 180.0) / (DEG * 2 * w180)
    bw, limit = bandwidth_by_type(response_type, found["w135"], found["wg"])
    return HQMetrics("model", response_type, reason, w180, found["w135"], found["wg"], bw, limit, tau,
                     found["g180"], phase2, "exact", None, found["crossings"], None, None, tuple(notes), (),
                     w, curve.mag_db, curve.phase, None)


# --------------------------------------------------------------------------- measured frequency response
def phase_roughness(w: np.ndarray, phase: np.ndarray) -> float:
    """Point-to-point scatter of a measured phase [deg]: the lesser of two estimates of its noise.

    One is the RMS residual about a least-squares parabola, which a smooth curve with more bending than a parabola
    (a lightly damped mode) also inflates; the other is the RMS second difference over sqrt(6) (exact for white
    scatter of equal spacing), which smooth curvature inflates only on a coarse grid. Noise inflates both, so the
    lesser is not fooled by a smooth curve on either kind of grid.

    Examples
    --------
    >>> w = np.linspace(1.0, 4.0, 40)
    >>> smooth = -90 - np.degrees(np.arctan2(0.4 * w, 4 - w**2))   # a mode with damping 0.1 at 2 rad/s
    >>> noisy = smooth + np.random.default_rng(0).normal(0.0, 8.0, w.size)
    >>> phase_roughness(w, smooth) < 2.0, phase_roughness(w, noisy) > 5.0
    (True, True)
    """
    parabola = float(np.sqrt(np.mean((phase - np.polyval(np.polyfit(w, phase, 2), w)) ** 2)))
    if phase.size < 5:
        return parabola
    second = np.diff(phase, 2)
    return min(parabola, float(np.sqrt(np.mean(second**2) / 6.0)))


def _validate_frd(w: Any, H: Any, coherence: Any, averages: Any) -> tuple[Any, ...]:
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
    nd = None
    if averages is not None:
        try:
            nd = np.asarray(averages, float)
        except (TypeError, ValueError):
            raise DataError(f"averages must be numbers, got {averages!r}", where="frequency response: averages") from None
        if nd.ndim == 0:
            nd = np.full(w.shape, float(nd))
        if nd.shape != w.shape:
            raise DataError(f"averages has {nd.size} values, w has {w.size} (give one number or one per frequency)",
                            where="frequency response: averages")
        if not np.all(np.isfinite(nd)) or np.any(nd < 1):
            bad = averages if np.ndim(averages) == 0 else float(nd[~(np.isfinite(nd) & (nd >= 1))][0])
            raise DataError(f"averages must be >= 1, got {bad!r}", where="frequency response: averages")
    return w, H, g2, nd


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


def crossing_sigma(w: np.ndarray, y: np.ndarray, x: float, sigma_y: float) -> float:
    """1-sigma uncertainty [rad/s] of where the curve ``y(w)`` crosses a level at ``x``: the curve's error over its
    slope there, both from the least-squares line through the points within :data:`CROSSING_DECADES` of ``x``
    (at least two on each side), the window doubled (up to 16 times) until that slope is three of its standard
    errors from zero; the error is the larger of ``sigma_y`` and the points' scatter about the line. ``inf``
    where no window shows a slope.

    The two points next to the crossing alone gave a rough phase's slope (-430 deg/(rad/s) where the response's was
    -37) and w180 +- 0.028 rad/s, 15 of them from the truth (a black-box test).

    Examples
    --------
    >>> w = np.linspace(1.0, 2.0, 41); y = -150.0 - 40.0 * (w - 1.0)
    >>> round(crossing_sigma(w, y, 1.75, 2.0), 4)  # 2 deg over 40 deg/(rad/s)
    0.05
    >>> noisy = y + 8.0 * np.where(np.arange(41) % 2 == 0, 1.0, -1.0)
    >>> round(crossing_sigma(w, noisy, 1.75, 2.0), 2)  # the 8 deg scatter counts, not the 2 deg claimed
    0.2
    """
    k = int(np.searchsorted(w, x))
    side = np.arange(max(0, k - 2), min(w.size, k + 2))
    for half in CROSSING_DECADES * 2.0 ** np.arange(5):
        idx = np.union1d(np.flatnonzero(np.abs(np.log10(w / x)) <= half), side)
        if idx.size < 3:
            continue
        xs = w[idx] - w[idx].mean()
        slope, offset = np.polyfit(xs, y[idx], 1)
        resid = y[idx] - (offset + slope * xs)
        scatter = float(np.sqrt(np.sum(resid ** 2) / (idx.size - 2))) if idx.size > 2 else 0.0
        slope_error = max(scatter, sigma_y) / float(np.sqrt(np.sum(xs ** 2)))
        if abs(slope) >= 3.0 * slope_error:
            return float(max(sigma_y, scatter) / abs(slope))
    return float("inf")


def _detect_type(w: np.ndarray, phase: np.ndarray, g2: np.ndarray | None) -> tuple[str, str]:
    use = np.ones(w.size, bool) if g2 is None else g2 >= 0.6
    if np.count_nonzero(use) < 3:
        use = np.ones(w.size, bool)
    idx = np.flatnonzero(use)[:5]
    p = float(np.median(phase[idx]))
    where = f"median phase {p:.0f} deg over the {idx.size} lowest frequencies ({w[idx[0]]:.3g}-{w[idx[-1]]:.3g} rad/s)"
    if abs(p + 90) < 30:
        return "rate", f"auto: {where}, near -90 deg (an integrator)"
    if abs(p) < 45:
        return "attitude", f"auto: {where}, near 0 deg (finite low-frequency gain)"
    return "rate", (f"auto: {where}, neither near 0 nor -90 deg; the rate rule (lesser) is used; give "
                    "--response-type if the type is known")


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


def _uncertainties(w: np.ndarray, mag: np.ndarray, phase: np.ndarray, g2: np.ndarray, n_d: np.ndarray,
                   found: dict[str, Any], tau: float | None, phase2: float | None, sig_phi2: float | None,
                   slope2: float | None, limit: str) -> tuple[dict[str, float | None], dict[str, float | None]]:
    """1-sigma uncertainty of each metric: the random error at the crossing over the curve's slope there."""
    coh_at = _interp_log(w, g2)
    nd_at = _interp_log(w, n_d)

    def sig_phase(x: float) -> float:  # deg
        return float(coherence_random_error(coh_at(x), nd_at(x))) * DEG

    def sig_db(x: float) -> float:
        return float(coherence_random_error(coh_at(x), nd_at(x))) * 20 / np.log(10)

    w180, w135, wg = found["w180"], found["w135"], found["wg"]
    unc: dict[str, float | None] = dict.fromkeys(("w180", "bandwidth_phase", "bandwidth_gain", "bandwidth",
                                                  "phase_delay"))
    coh = {k: (coh_at(v) if v is not None and v <= w[-1] else None)
           for k, v in (("w180", w180), ("bandwidth_phase", w135), ("bandwidth_gain", wg),
                        ("2w180", 2 * w180 if w180 is not None else None))}
    if w135 is not None:
        unc["bandwidth_phase"] = crossing_sigma(w, phase, w135, sig_phase(w135))
    if w180 is not None:
        s180 = crossing_sigma(w, phase, w180, sig_phase(w180))
        unc["w180"] = s180
        if wg is not None:
            sf = np.sqrt(sig_db(wg) ** 2 + sig_db(w180) ** 2 + (_local_slope(w, mag, w180) * s180) ** 2)
            unc["bandwidth_gain"] = crossing_sigma(w, mag, wg, float(sf))
        if tau is not None and phase2 is not None and sig_phi2 is not None and slope2 is not None:
            w2 = 2 * w180
            dtau_dw = -2 * slope2 / (DEG * w2) + (phase2 + 180.0) * 2 / (DEG * w2**2)
            dtau_dphi = -1.0 / (DEG * w2)
            unc["phase_delay"] = float(np.hypot(dtau_dw * s180, dtau_dphi * sig_phi2))
    unc["bandwidth"] = {"phase": unc["bandwidth_phase"], "gain": unc["bandwidth_gain"]}.get(limit)
    return unc, coh


def hq_from_frd(w: Any, H: Any, coherence: Any = None, averages: Any = None,
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
    averages : float or array_like, optional
        Number of averages ``n_d`` behind the estimate: one number, or one per frequency (the
        ``n_averages`` that :func:`synth.ident.spectra.frequency_response` reports, interpolated
        in log w at each crossing); without it ``n_d = 1`` is assumed (the largest error; stated
        in ``notes``).
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
    (3.11, 'rate', 0.384)
    """
    check_choice(response_type, RESPONSE_TYPES, "response_type")
    check_choice(phase_fit, PHASE_FITS, "phase_fit")
    if fit_band is not None and not (len(fit_band) == 2 and all(np.isfinite(fit_band))
                                     and 0 < fit_band[0] < fit_band[1]):
        raise DataError(f"expected two increasing frequencies > 0 rad/s, got {list(fit_band)}", where="fit_band")
    w, H, g2, nd = _validate_frd(w, H, coherence, averages)
    notes: list[str] = []
    phase = anchored_phase(H)
    mag = 20 * np.log10(np.abs(H))
    reason = "given"
    if response_type == "auto":
        response_type, reason = _detect_type(w, phase, g2)
    curve = ResponseCurve(w, mag, phase, _interp_log(w, mag), _interp_log(w, phase), exact=False)
    found = crossing_metrics(curve, notes)
    w180, w135, wg = found["w180"], found["w135"], found["wg"]
    coh_at = _interp_log(w, g2) if g2 is not None else None
    n_d = nd if nd is not None else np.ones(w.shape)
    nd_at = _interp_log(w, n_d)
    if nd is not None and np.ptp(nd) > 0 and w180 is not None:
        notes.append(f"averaging count per frequency: n_d = {nd_at(w180):.3g} at w180")
    if g2 is not None and averages is None:
        notes.append("number of averages not given: n_d = 1 assumed, so the uncertainties are upper bounds")
    sig_phase_pts = coherence_random_error(g2, n_d) * DEG if g2 is not None else None

    phase2 = tau = None
    method, line = "raw", None
    sig_phi2 = slope2 = None
    if fit_band is not None and np.count_nonzero((w >= fit_band[0]) & (w <= fit_band[1])) < 3:
        raise DataError(f"the fit band {fit_band[0]:.4g}-{fit_band[1]:.4g} rad/s holds "
                        f"{np.count_nonzero((w >= fit_band[0]) & (w <= fit_band[1]))} of the response's frequencies "
                        f"({w[0]:.4g}-{w[-1]:.4g} rad/s); the phase line needs 3", where="fit_band")
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
            rough = phase_roughness(w[in_band], phase[in_band])
            if rough > rough_deg:
                reasons.append(f"the phase between {band[0]:.4g} and {band[1]:.4g} rad/s scatters {rough:.2g} deg RMS "
                               f"about a smooth curve (> {rough_deg:g} deg)")
        use_line = phase_fit == "line" or (phase_fit == "auto" and bool(reasons))
        if phase_fit == "raw" and w2 > w[-1]:
            raise DataError(f"2 w180 = {w2:.4g} rad/s lies beyond the data (up to {w[-1]:.4g} rad/s); "
                            "use the phase line", where="frequency response")
        why = "; ".join(reasons) if reasons else "requested"
        if use_line and np.count_nonzero(in_band) < 3:
            notes.append(f"phase delay undefined: the phase line needs 3 points on {band[0]:.4g}-{band[1]:.4g} "
                         f"rad/s and the data hold {np.count_nonzero(in_band)} ({why})")
        elif use_line:
            coef, cov, rms, n = fit_phase_line(w, phase, band, sig_phase_pts)
            phase2 = float(coef[0] + coef[1] * w2)
            line = PhaseLine((float(band[0]), float(band[1])), n, float(coef[1]), float(coef[0]), rms, phase2)
            method = "line"
            sig_phi2 = float(np.sqrt(np.array([1.0, w2]) @ cov @ np.array([1.0, w2])))
            slope2 = float(coef[1])
            notes.append(f"phase at 2 w180 from the least-squares line through the phase on {band[0]:.4g}-"
                         f"{band[1]:.4g} rad/s ({n} points, slope {coef[1]:.3g} deg/(rad/s)): {why}")
            if slope2 >= 0.0:  # past w180 a delay and the plant's lags only lower the phase
                notes.append(f"phase delay undefined: the phase line past w180 rises ({slope2:.3g} deg/(rad/s), "
                             f"the points {rms:.2g} deg RMS about it): the data show no roll-off to measure")
                phase2 = None
        else:
            phase2 = curve.phase_at(w2)
            if coh_at:
                sig_phi2 = float(coherence_random_error(coh_at(w2), nd_at(w2))) * DEG
            slope2 = _local_slope(w, phase, w2)
        tau = -(phase2 + 180.0) / (DEG * w2) if phase2 is not None else None

    bw, limit = bandwidth_by_type(response_type, w135, wg, found["below"])
    unc = coh = None
    if g2 is not None:
        unc, coh = _uncertainties(w, mag, phase, g2, n_d, found, tau, phase2, sig_phi2, slope2, limit)
        low = [k for k, v in coh.items() if v is not None and v < COHERENCE_OK]
        if low:
            notes.append(f"coherence below {COHERENCE_OK} (seed 2's accuracy criterion) at: {', '.join(low)}")
    return HQMetrics("measured", response_type, reason, w180, w135, wg, bw, limit, tau, found["g180"], phase2,
                     method, line, found["crossings"], unc, coh, tuple(notes), tuple(found["below"]), w, mag, phase,
                     g2)
