"""Transfer-function fit with an exact delay to an identified frequency response; step verification.

The cost is CIFER's (NAVFIT) over the ``n`` grid points of a chosen range:

    J = (20/n) sum W_gamma [W_g (delta dB)^2 + W_p (delta deg)^2],
    W_g = 1, W_p = 0.01745, W_gamma = [1.58 (1 - exp(-gamma^2))]^2,

``delta dB`` and ``delta deg`` the magnitude and phase of ``G_model(jw) / H(jw)``
(the phase wrapped to (-180, 180]). It is minimized with casadi + IPOPT over the
structure's parameters and the delay.

Deterministic start: for each delay on a grid from 0 to 1.5 times the phase slope
``-d phase/d w`` over the top third of the range, a Sanathanan-Koerner fit
(iterated linear least squares of ``N - H e^{jw tau} D`` weighted by
``W_gamma / |H D_prev|^2``, i.e. relative error) gives the rational part; the
delay and rational part with the lowest ``J`` start IPOPT. A formula structure
(:func:`synth.ident.structure.parse_structure`) is started from a few constant
parameter vectors (1 and the range's edges and centre) with the delay of that
order fit, and from the parameters whose coefficients match that order fit's
(:mod:`synth.ident.freqfit_start`), and the best local optimum is kept.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from synth.errors import DataError, ModelError
from synth.ident.freqfit_start import matched_start
from synth.ident.spectra import FrequencyResponse
from synth.ident.structure import Structure, parse_structure
from synth.plant import Plant
from synth.polynomials import format_factored

__all__ = ["ABSURD_ROOT", "IPOPT_OPTIONS", "MIN_FIT_PERCENT", "SOLVED", "W_G", "W_P", "FreqFit", "FrequencyFitError",
           "coherence_weight", "fit_cost", "fit_frequency_response", "fit_percent", "parse_orders"]

W_G = 1.0
W_P = 0.01745
IPOPT_OPTIONS = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": 500,
                 "ipopt.tol": 1e-10, "show_eval_warnings": False}


#: IPOPT return statuses that count as a solution
SOLVED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
#: a fit below this percentage (see :func:`fit_percent`) is a failure, not a result
MIN_FIT_PERCENT = 50.0
#: a fitted pole or zero this many times above the fitted band's top is a failure: the band cannot place it (its
#: phase there is under 0.006 deg; a black-box test's short-band fits returned poles at -1.2e17 rad/s with gains of
#: -8.8e16 as results, and, started from the orders fit's coefficients too, one at +6.3e6 rad/s for a 94 rad/s top)
ABSURD_ROOT = 1e4


class FrequencyFitError(RuntimeError):
    """A structure fit that failed: the solver did not converge, or the fit is too poor to be a result.

    Not a :class:`synth.errors.SynthError` (the input was valid): ``synth freqresp``
    prints its one-line message and exits 1.

    Parameters
    ----------
    message : str
        What failed and what to try.
    status : str
        IPOPT's return status.
    fit_percent : float
        :func:`fit_percent` over the fitted range.
    fit_percent : float
        The fit reached (:func:`fit_percent`).
    structure : str
        The structure that was fitted.

    Examples
    --------
    >>> e = FrequencyFitError("fit 1.2 % < 50 %", "Maximum_Iterations_Exceeded", 1.2, "0/4")
    >>> e.status, str(e)
    ('Maximum_Iterations_Exceeded', 'fit 1.2 % < 50 %')
    """

    def __init__(self, message: str, status: str, fit_percent: float, structure: str) -> None:
        super().__init__(" ".join(str(message).split()))
        self.status = status
        self.fit_percent = fit_percent
        self.structure = structure


def fit_percent(H_model: Any, H_data: Any, coherence: Any) -> float:
    """Fit of a model to a frequency response [%]: ``100 (1 - sqrt(sum W_gamma |G/H - 1|^2 / sum W_gamma))``.

    100 % is a perfect fit; 0 % a relative error as large as the response itself
    (a model of zero scores 0 %); a model worse than that scores below 0 %.

    Examples
    --------
    >>> H = np.array([1.0, 1j, -1.0])
    >>> fit_percent(H, H, np.ones(3)), fit_percent(0.9 * H, H, np.ones(3)), fit_percent(0 * H, H, np.ones(3))
    (100.0, 90.0, 0.0)
    """
    wg = coherence_weight(coherence)
    rel = np.abs(np.asarray(H_model, complex) / np.asarray(H_data, complex) - 1.0) ** 2
    return float(100.0 * (1.0 - np.sqrt(np.sum(wg * rel) / np.sum(wg))))


def coherence_weight(coherence: Any) -> np.ndarray:
    """``W_gamma = [1.58 (1 - exp(-gamma^2))]^2`` (about 1 at ``gamma^2 = 1``).

    Examples
    --------
    >>> round(float(coherence_weight(1.0)), 4), round(float(coherence_weight(0.5)), 4)
    (0.9975, 0.3865)
    """
    return (1.58 * (1.0 - np.exp(-np.asarray(coherence, float)))) ** 2


def fit_cost(H_model: Any, H_data: Any, coherence: Any) -> float:
    """The cost ``J`` of a model response against data (see the module text).

    Examples
    --------
    >>> round(fit_cost([2.0], [1.0], [1.0]), 3)      # 6.02 dB off at one point: 20 * 0.9975 * 6.0206^2
    723.142
    """
    r = np.asarray(H_model, complex) / np.asarray(H_data, complex)
    db = 20.0 * np.log10(np.abs(r))
    deg = np.degrees(np.angle(r))
    wg = coherence_weight(coherence)
    return float(20.0 / r.size * np.sum(wg * (W_G * db ** 2 + W_P * deg ** 2)))


class _Orders:
    """``(b_m s^m + ... + b_0) / (s^n + a_{n-1} s^{n-1} + ... + a_0)`` as a structure."""

    def __init__(self, m: int, n: int) -> None:
        self.num_degree, self.den_degree = m, n
        self.parameters = tuple([f"b{k}" for k in range(m, -1, -1)] + [f"a{k}" for k in range(n - 1, -1, -1)])
        self.formula = f"{m}/{n}"

    def casadi_coefficients(self, theta: Any) -> tuple[list[Any], list[Any]]:
        m = self.num_degree
        num = [theta[i] for i in range(m + 1)]
        den = [1.0] + [theta[m + 1 + i] for i in range(self.den_degree)]
        return num, den

    def coefficients(self, theta: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
        m = self.num_degree
        return np.asarray(theta[:m + 1], float), np.r_[1.0, np.asarray(theta[m + 1:], float)]


def parse_orders(text: str) -> tuple[int, int] | None:
    """``"m/n"`` numerator/denominator orders, or ``None`` if ``text`` is not of that form.

    Examples
    --------
    >>> parse_orders("0/2"), parse_orders("k/(s+p)")
    ((0, 2), None)
    """
    m = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", text)
    if not m:
        return None
    num, den = int(m.group(1)), int(m.group(2))
    if den < 1 or num > den:
        raise ModelError(f"orders {text!r}: need 0 <= numerator order <= denominator order, denominator >= 1")
    return num, den


@dataclass(frozen=True)
class FreqFit:
    """A transfer function fitted to a frequency response.

    Attributes
    ----------
    plant : Plant
        The fitted model (exact delay).
    parameters : dict
        Fitted parameter values (the delay under ``"delay"`` [s]).
    J : float
        The cost (module text) at the optimum.
    structure : str
        ``"m/n"`` orders or the formula.
    w_range : tuple of float
        Fitted range [rad/s].
    n_points : int
        Grid points in the range.
    delay_fitted : bool
    status : str
        IPOPT's return status.
    fit_percent : float
        :func:`fit_percent` over the fitted range.
    uncertainty : FreqFitUncertainty or None
        The parameters' standard errors and the weakly identifiable ones
        (:mod:`synth.ident.freqfit_uncertainty`); None when the response came without its random error
        (plain arrays).
    notes : tuple of str
        What the user should know about the fit (a range reaching outside the coherent band).

    Examples
    --------
    >>> G = Plant.from_string("4/(s+2)", delay=0.1)
    >>> w = np.geomspace(0.5, 20, 40)
    >>> fit = fit_frequency_response((w, G.freqresp(w), np.ones(40)), "0/1")
    >>> round(fit.plant.dc_gain(), 4), round(fit.plant.delay, 4), fit.J < 1e-8
    (2.0, 0.1, True)
    """

    plant: Plant
    parameters: dict[str, float]
    J: float
    structure: str
    w_range: tuple[float, float]
    n_points: int
    delay_fitted: bool
    status: str
    w: np.ndarray = field(repr=False)
    H_model: np.ndarray = field(repr=False)
    fit_percent: float = float("nan")
    uncertainty: Any = None
    notes: tuple[str, ...] = ()

    def tf_text(self) -> str:
        """The fitted model in factored form (with ``exp(-tau*s)``)."""
        text = format_factored(self.plant.num, self.plant.den)
        return f"{text} * exp(-{self.plant.delay:.6g}*s)" if self.plant.delay else text

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: parameters, ``J``, the transfer function, poles and zeros.

        Examples
        --------
        >>> G = Plant.from_string("4/(s+2)")
        >>> w = np.geomspace(0.5, 20, 20)
        >>> d = fit_frequency_response((w, G.freqresp(w), np.ones(20)), "0/1", delay=0.0).to_dict()
        >>> sorted(d["parameters"]), d["delay_fitted"]
        (['a0', 'b0', 'delay'], False)
        """
        return {"structure": self.structure, "parameters": self.parameters, "J": self.J,
                "tf": self.tf_text(), "num": self.plant.num, "den": self.plant.den, "delay_s": self.plant.delay,
                "poles": [[float(p.real), float(p.imag)] for p in self.plant.poles()],
                "w_range": list(self.w_range), "n_points": self.n_points, "delay_fitted": self.delay_fitted,
                "status": self.status, "fit_percent": self.fit_percent,
                "uncertainty": None if self.uncertainty is None else self.uncertainty.to_dict(),
                "notes": list(self.notes),
                "cost": "J = (20/n) sum W_gamma [W_g dB^2 + W_p deg^2], W_g = 1, W_p = 0.01745"}


def _power_matrices(w: np.ndarray, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Real and imaginary parts of ``(jw)^p`` for descending ``p = degree .. 0``."""
    p = np.arange(degree, -1, -1)
    z = (1j * w[:, None]) ** p[None, :]
    return z.real, z.imag


def _sk_fit(w: np.ndarray, H: np.ndarray, wg: np.ndarray, m: int, n: int, iterations: int = 12) -> np.ndarray:
    """Sanathanan-Koerner fit of a real rational (monic denominator); returns ``theta`` of :class:`_Orders`."""
    s = 1j * w
    Sn = s[:, None] ** np.arange(m, -1, -1)[None, :]
    Sd = s[:, None] ** np.arange(n - 1, -1, -1)[None, :]
    weight = np.sqrt(wg) / np.abs(H)
    dprev = np.ones_like(s)
    theta = np.zeros(m + 1 + n)
    for _ in range(iterations):
        v = weight / np.abs(dprev)
        A = np.hstack([Sn, -H[:, None] * Sd]) * v[:, None]
        rhs = H * s ** n * v
        A2 = np.vstack([A.real, A.imag])
        b2 = np.r_[rhs.real, rhs.imag]
        scale = np.linalg.norm(A2, axis=0)
        scale[scale == 0] = 1.0
        theta = np.linalg.lstsq(A2 / scale, b2, rcond=None)[0] / scale
        dprev = s ** n + Sd @ theta[m + 1:]
    return theta


def _model(structure: Any, theta: Sequence[float], w: np.ndarray, delay: float) -> np.ndarray:
    num, den = structure.coefficients(theta)
    s = 1j * w
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.polyval(num, s) / np.polyval(den, s) * np.exp(-s * delay)


def _ipopt(structure: Any, w: np.ndarray, H: np.ndarray, coh: np.ndarray, theta0: np.ndarray, delay0: float,
           fit_delay: bool, delay_max: float) -> tuple[np.ndarray, float, str]:
    import casadi as ca

    npar = len(structure.parameters)
    x = ca.SX.sym("x", npar + (1 if fit_delay else 0))
    num, den = structure.casadi_coefficients(x)
    Nr, Ni = _power_matrices(w, len(num) - 1)
    Dr, Di = _power_matrices(w, len(den) - 1)
    nv, dv = ca.vertcat(*num), ca.vertcat(*den)
    nr, ni = ca.mtimes(ca.DM(Nr), nv), ca.mtimes(ca.DM(Ni), nv)
    dr, di = ca.mtimes(ca.DM(Dr), dv), ca.mtimes(ca.DM(Di), dv)
    tau = x[npar] if fit_delay else delay0
    c, sn = ca.cos(ca.DM(w) * tau), ca.sin(ca.DM(w) * tau)
    hr, hi = ca.DM(H.real), ca.DM(H.imag)
    fr = hr * c - hi * sn          # conj(H) exp(-j w tau) = fr + j fi
    fi = -(hr * sn + hi * c)
    pr, pi = nr * dr + ni * di, ni * dr - nr * di     # N conj(D)
    zr, zi = pr * fr - pi * fi, pr * fi + pi * fr
    db = 10.0 * ca.log10(nr ** 2 + ni ** 2) - 10.0 * ca.log10(dr ** 2 + di ** 2) - ca.DM(20.0 * np.log10(np.abs(H)))
    deg = ca.atan2(zi, zr) * (180.0 / np.pi)
    wg = ca.DM(coherence_weight(coh))
    J = 20.0 / w.size * ca.sum1(wg * (W_G * db ** 2 + W_P * deg ** 2))
    solver = ca.nlpsol("freqfit", "ipopt", {"x": x, "f": J}, IPOPT_OPTIONS)
    lbx = [-np.inf] * npar + ([0.0] if fit_delay else [])
    ubx = [np.inf] * npar + ([delay_max] if fit_delay else [])
    x0 = list(theta0) + ([min(max(delay0, 0.0), delay_max)] if fit_delay else [])
    sol = solver(x0=x0, lbx=lbx, ubx=ubx)
    xs = np.asarray(sol["x"]).ravel()
    # IPOPT relaxes its bounds by a relative 1e-8 (bound_relax_factor): a delay at its bound of 0 comes back as
    # -1e-8, which no plant accepts (a delay-free sweep's fit failed on it)
    tau = float(np.clip(xs[npar], 0.0, delay_max)) if fit_delay else delay0
    return xs[:npar], tau, str(solver.stats()["return_status"])


def _data(resp: FrequencyResponse | tuple[Any, Any, Any]
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, tuple | None]:
    """Frequencies, response, coherence, random error (None for plain arrays) and the coherent band."""
    if isinstance(resp, FrequencyResponse):
        band = (resp.band.w_min, resp.band.w_max) if resp.band.found else None
        return resp.w, resp.H, resp.coherence, np.asarray(resp.random_error, float), band
    w, H, coh = (np.asarray(a) for a in resp)
    return np.asarray(w, float), np.asarray(H, complex), np.asarray(coh, float), None, None


def fit_frequency_response(
    resp: FrequencyResponse | tuple[Any, Any, Any],
    structure: str | Structure = "0/2",
    w_range: tuple[float, float] | None = None,
    delay: str | float = "fit",
    min_fit_percent: float = MIN_FIT_PERCENT,
) -> FreqFit:
    """Fit a transfer function with an exact delay to a frequency response, minimizing ``J``.

    Parameters
    ----------
    resp : FrequencyResponse or (w, H, coherence)
        The identified response.
    structure : str or Structure
        Orders ``"m/n"`` (numerator/denominator, monic denominator) or a formula
        such as ``"k*(s+z)/((s+p1)*(s+p2))"`` or ``"K*exp(-Td*s)/((s+p1)*(s+p2))"``.
    w_range : (float, float), optional
        Frequencies to fit [rad/s]; default the coherent band (all points for arrays).
    delay : "fit" or float
        Fit the delay, or hold it at this value [s]. A formula with its own
        ``exp(...)`` factor uses that instead.
    min_fit_percent : float
        A fit below this (:func:`fit_percent`) is a failure.

    Returns
    -------
    FreqFit

    Raises
    ------
    ModelError
        A bad structure or delay, or fewer points than parameters.
    DataError
        An empty range or no coherent band.
    FrequencyFitError
        IPOPT did not converge (its status is not in :data:`SOLVED`), the result
        is not finite, or the fit is below ``min_fit_percent``; never returned as a result.

    Examples
    --------
    >>> G = Plant.from_string("31.6/((s+0.49)*(s+2.30))", delay=0.041)
    >>> w = np.geomspace(0.4, 12, 60)
    >>> fit = fit_frequency_response((w, G.freqresp(w), np.ones(60)), "k*exp(-Td*s)/((s+p1)*(s+p2))")
    >>> {k: round(v, 3) for k, v in sorted(fit.parameters.items())}
    {'Td': 0.041, 'k': 31.6, 'p1': 0.49, 'p2': 2.3}
    """
    w_all, H_all, coh_all, eps_all, band = _data(resp)
    lo, hi = w_range if w_range is not None else (band if band is not None else (w_all.min(), w_all.max()))
    if band is None and w_range is None and isinstance(resp, FrequencyResponse):
        raise DataError("no coherent band to fit; give the range explicitly (--fit-range)")
    keep = (w_all >= lo * (1 - 1e-12)) & (w_all <= hi * (1 + 1e-12)) & np.isfinite(H_all) & (np.abs(H_all) > 0)
    w, H, coh = w_all[keep], H_all[keep], coh_all[keep]
    eps = eps_all[keep] if eps_all is not None else None
    text = structure.formula if isinstance(structure, Structure) else str(structure)
    orders = parse_orders(text) if not isinstance(structure, Structure) else None
    st: Any = _Orders(*orders) if orders else (structure if isinstance(structure, Structure) else parse_structure(text))
    own_delay = getattr(st, "delay", None)
    if st.den_degree == 0 and st.num_degree == 0 and own_delay is None and delay != "fit":
        raise ModelError(f"structure {text!r} has no s and no delay: a static gain needs no frequency-response fit "
                         "(give orders like 0/2, or a formula in s)")
    if own_delay is not None and delay != "fit":
        raise ModelError(f"structure {text!r} has its own delay factor; do not also give a delay")
    if isinstance(delay, str) and delay != "fit":
        raise ModelError(f"delay must be 'fit' or a number of seconds, got {delay!r}")
    if not isinstance(delay, str) and not (np.isfinite(delay) and delay >= 0):
        raise ModelError(f"delay must be >= 0 s, got {delay!r}")
    fit_delay = (delay == "fit" and own_delay is None) or isinstance(own_delay, str)
    fixed = float(own_delay) if isinstance(own_delay, float) else (0.0 if isinstance(delay, str) else float(delay))
    npar = len(st.parameters) + (1 if fit_delay else 0)
    if w.size < npar + 1:
        raise ModelError(f"{w.size} frequency points in {lo:.4g}-{hi:.4g} rad/s cannot fit {npar} parameters; "
                         "widen the range")
    wg = coherence_weight(coh)
    m, n = st.num_degree, st.den_degree
    phase = np.unwrap(np.angle(H))
    top = w >= w[-1] - (w[-1] - w[0]) / 3
    slope = -np.polyfit(w[top], phase[top], 1)[0] if np.count_nonzero(top) >= 2 else 0.0
    delay_hi = max(1.5 * slope, 0.5 / w[-1])
    candidates = np.linspace(0.0, delay_hi, 31) if fit_delay else np.array([fixed])
    best = (np.inf, None, fixed)
    for tau in candidates:
        th = _sk_fit(w, H * np.exp(1j * w * tau), wg, m, n)
        J = fit_cost(_model(_Orders(m, n), th, w, tau), H, coh)
        if J < best[0]:
            best = (J, th, tau)
    theta_orders, tau0 = best[1], best[2]
    delay_max = max(3.0 * delay_hi, 2.0 * tau0, 1e-3)
    if orders:
        theta, tau, status = _ipopt(st, w, H, coh, theta_orders, tau0, fit_delay, delay_max)
        fit = _checked(st, theta, float(tau), text, w, H, coh, bool(fit_delay), status, own_delay, min_fit_percent)
    else:
        starts = [np.full(len(st.parameters), v) for v in (1.0, lo, np.sqrt(lo * hi), hi)]
        matched = matched_start(st, *_Orders(m, n).coefficients(theta_orders), starts)  # any signs (freqfit_start)
        starts += [matched] if matched is not None else []
        results = []
        for x0 in starts:
            try:
                th, _, stat = _ipopt(st, w, H, coh, x0, tau0, False, delay_max)
                results.append((fit_cost(_model(st, th, w, tau0), H, coh), th, stat))
            except (RuntimeError, ValueError, ModelError):
                continue
        if not results:
            raise ModelError(f"structure {text!r}: no start converged")
        start_cost, start, start_status = min(results, key=lambda r: r[0] if np.isfinite(r[0]) else np.inf)
        theta, tau, status = _ipopt(st, w, H, coh, start, tau0, fit_delay, delay_max)
        # the start (its delay held at the grid's best) is a point of the polish's own problem: a polish that ends
        # worse than it lost its way, and the start stands
        if not fit_cost(_model(st, theta, w, tau), H, coh) <= start_cost * (1 + 1e-9):
            theta, tau, status = start, tau0, start_status
        fit = _checked(st, theta, float(tau), text, w, H, coh, bool(fit_delay), status, own_delay, min_fit_percent)
    if band is not None and w_range is not None and (w[0] < band[0] * (1 - 1e-9) or w[-1] > band[1] * (1 + 1e-9)):
        outside = int(np.count_nonzero((w < band[0] * (1 - 1e-9)) | (w > band[1] * (1 + 1e-9))))
        fit = replace(fit, notes=(f"the fit range {w[0]:.4g}-{w[-1]:.4g} rad/s reaches outside the coherent band "
                                  f"{band[0]:.4g}-{band[1]:.4g} rad/s: {outside} of its {w.size} points are not "
                                  "trusted (leakage or noise whatever their coherence)",))
    if eps is None:
        return fit
    from synth.ident.freqfit_uncertainty import fit_uncertainty

    delay_name = own_delay if isinstance(own_delay, str) else "delay"
    return replace(fit, uncertainty=fit_uncertainty(st, theta, float(tau), bool(fit_delay), w, H,
                                                    coherence_weight(coh), eps, (W_G, W_P), delay_name))


def _checked(st: Any, theta: np.ndarray, tau: float, text: str, w: np.ndarray, H: np.ndarray, coh: np.ndarray,
             fit_delay: bool, status: str, own_delay: Any, min_fit_percent: float) -> FreqFit:
    """The fit as a result, or :class:`FrequencyFitError` saying what failed and what to try."""
    band = f"{w[0]:.4g}-{w[-1]:.4g} rad/s"
    hint = ("try another structure (fewer modes or lower orders), a fixed --delay, or a shorter band "
            "(--fit-range) where the coherence is high")
    if not (np.all(np.isfinite(theta)) and np.isfinite(tau)):
        raise FrequencyFitError(f"fit of {text!r} over {band} failed: IPOPT {status}, parameters not finite; {hint}",
                                status, float("nan"), text)
    num, den = st.coefficients(theta)
    try:
        plant = Plant(num, den, tau)
    except ModelError as exc:
        raise FrequencyFitError(f"fit of {text!r} over {band} failed: IPOPT {status}, {exc.message}; {hint}",
                                status, float("nan"), text) from None
    H_model = plant.freqresp(w)
    percent = fit_percent(H_model, H, coh) if np.all(np.isfinite(H_model)) else float("-inf")
    if status not in SOLVED:
        raise FrequencyFitError(f"fit of {text!r} over {band} failed: IPOPT {status} (fit {percent:.1f} %); {hint}",
                                status, percent, text)
    if not percent >= min_fit_percent:
        raise FrequencyFitError(f"fit of {text!r} over {band} failed: fit {percent:.1f} % < {min_fit_percent:g} % "
                                f"(IPOPT {status}); {hint}", status, percent, text)
    roots = np.concatenate([plant.poles(), plant.zeros()])  # the fitted plant's own
    if roots.size and np.max(np.abs(roots)) > ABSURD_ROOT * w[-1]:
        far = roots[np.argmax(np.abs(roots))]
        raise FrequencyFitError(f"fit of {text!r} over {band} failed: a pole or zero at {abs(far):.3g} rad/s, more "
                                f"than {ABSURD_ROOT:.0e} times above the band (IPOPT {status}): the band cannot place "
                                f"it; {hint}", status, percent, text)
    params = {name: float(v) for name, v in zip(st.parameters, theta)}
    params[own_delay if isinstance(own_delay, str) else "delay"] = tau
    return FreqFit(plant, params, fit_cost(H_model, H, coh), text, (float(w[0]), float(w[-1])), int(w.size),
                   fit_delay, status, w, H_model, percent)
