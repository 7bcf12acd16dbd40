"""Simulation-error fit of a parametric structure to a sampled record, with casadi (IPOPT).

The model, its exact zero-order-hold discretization with a fractional delay and the Gauss-Newton IPOPT problem are
in :mod:`synth.ident.sim_error_problem`; the deterministic start (SRIVC on a delay grid, mapped onto the structure) in
:mod:`synth.ident.srivc`. Here: the fit itself (the whole-sample delay search, the fallback starts) and its
uncertainty; :func:`synth.ident.identification.identify` averages a step train first.

Delay search
------------
The fractional delay ``f`` is bounded in ``[0, dt]``; if it ends on a bound, the whole-sample part ``m`` moves by
one sample and the fit is repeated (at ``f = dt`` the models for ``m`` and ``m + 1`` coincide: the cost is continuous).
IPOPT starts at the deterministic initial model; only where it fails or ends worse than it, Levenberg-Marquardt
from the same start and scaled starts are tried (not after a bounded run that reached its iteration limit below its
start, crawling along a bound; by Levenberg-Marquardt where IPOPT crawled to its limit and Levenberg-Marquardt
converged: :func:`~synth.ident.start_kept.crawl_over`), and a start no Gauss-Newton step improves is kept.

Uncertainty
-----------
``cov = s^2 (J^T J)^{-1}`` with ``s^2 = SSR/(N - p)`` and ``J`` the Jacobian of ``yhat`` in the parameters (delay and
offset included; with ``free_start``, the state at the first fitted sample too, as a nuisance); standard errors are
the square roots of its diagonal and the 95 % intervals ``theta +- t_{0.975, N-p} std``. This assumes white noise:
with coloured noise (drift, a disturbance, a model error) the residuals are correlated and these errors too small.

``fit_percent = 100 (1 - ||y - yhat|| / ||y - mean(y)||)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.data.gaps import gap_weights
from synth.data.record import Record
from synth.distributions import t_ppf
from synth.errors import DataError, FitError, ModelError
from synth.ident.coloured_relevance import no_response_p_value
from synth.ident.convolution_problem import ConvolutionProblem
from synth.ident.covariance import fit_covariance
from synth.ident.delay_samples import best_sample, walk_intervals
from synth.ident.fit_arguments import as_sensor, resolve_delay
from synth.ident.fit_failure import (
    LIMIT_STATUSES,
    SIGNIFICANCE,
    fit_failure,
    remaining_improvement,
    roots_beyond_record,
    scaled_jacobian,
    start_ssr,
)
from synth.ident.identifiability import TiedParameter, WeakParameter, coinciding, tied_to_weak, weak_parameters
from synth.ident.misfit import misfit_note
from synth.ident.nyquist import nyquist_note
from synth.ident.residual_whiteness import correlated_residuals_note
from synth.ident.sim_error_problem import SimulationErrorProblem
from synth.ident.srivc import linear_initial_model, map_to_structure
from synth.ident.start_kept import SCALED_BY_LM, START_CONVERGED, converged_replaces, converged_start, crawl_over
from synth.ident.start_state import free_columns, free_start_gram, start_state_test
from synth.ident.structure import Structure, parse_structure
from synth.ident.symmetric_ridge import off_ridge, ridge_split_start
from synth.ident.zero_delay import at_zero_delay, zero_delay_candidate
from synth.plant import Plant

__all__ = ["LONG_RECORD", "TimeFitResult", "fit_structure"]

#: records longer than this (samples) are fitted by :class:`~synth.ident.convolution_problem.ConvolutionProblem`
LONG_RECORD = 10_000


@dataclass(frozen=True, eq=False)
class TimeFitResult:
    """A fitted structure with its uncertainty.

    Attributes
    ----------
    structure : Structure
    parameters : dict
        Fitted values named as in the formula, plus the delay (under the formula's delay name, else ``"delay"``).
    std, ci95 : dict
        Standard errors and 95 % confidence intervals, same keys (a fixed delay has std 0).
    names : list of str
        Order of the rows and columns of ``covariance`` (parameters, delay if fitted, then ``"offset"``).
    covariance : numpy.ndarray
    delay : float
        Delay [s].
    delay_fitted : bool
    offset, offset_std : float
        Output level ``b`` at the reference input ``u_0`` and its standard error.
    fit_percent, residual_std : float
        The fit and ``sqrt(SSR / (N - p))``.
    plant : Plant
        The fitted ``F`` with its delay.
    sensor : Plant or None
        The known sensor ``H``.
    measured : Plant
        ``F H`` with the delay: what the record's output responds with.
    initial : dict
        The deterministic initial values handed to IPOPT.
    solver : dict
        Status (IPOPT's, or ``Start_Converged``: :mod:`synth.ident.start_kept`), iterations, starts, delay shifts.
    t, y, yhat : numpy.ndarray
        The fitted data and the model output (for figures; not in ``to_dict``).
    periodic : bool
    weights : numpy.ndarray or None
        The 0/1 sample weights of the cost, if any (not in ``to_dict``).
    """

    structure: Structure
    parameters: dict[str, float]
    std: dict[str, float]
    ci95: dict[str, tuple[float, float]]
    names: list[str]
    covariance: np.ndarray
    delay: float
    delay_fitted: bool
    offset: float
    offset_std: float
    fit_percent: float
    residual_std: float
    plant: Plant
    sensor: Plant | None
    measured: Plant
    initial: dict[str, float]
    solver: dict[str, Any]
    t: np.ndarray = field(repr=False)
    y: np.ndarray = field(repr=False)
    yhat: np.ndarray = field(repr=False)
    u0: float = 0.0
    periodic: bool = False
    weights: np.ndarray | None = field(default=None, repr=False)

    @property
    def residuals(self) -> np.ndarray:
        """``y - yhat``."""
        return self.y - self.yhat

    @property
    def weak(self) -> list[WeakParameter]:
        """Parameters the record cannot pin down (:func:`synth.ident.identifiability.weak_parameters`).

        Examples
        --------
        >>> from synth.data import record_from_arrays
        >>> from synth.ident.simulate import simulate_plant
        >>> t = np.arange(0, 4, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
        >>> y = simulate_plant(Plant.from_string("2/(s+3)"), t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
        >>> fit_structure(record_from_arrays(t, u, y), "k/(s+p)").weak
        []
        """
        delay_name = self.names[len(self.structure.parameters)] if self.delay_fitted else None
        dt = float(self.t[1] - self.t[0]) if self.t.size > 1 else 0.0
        return weak_parameters(self.names, {**self.parameters, "offset": self.offset}, self.covariance, self.ci95,
                               delay_name, dt)

    @property
    def tied(self) -> list[TiedParameter]:
        """Parameters not flagged weak whose standard error rests on a weak one's
        (:func:`synth.ident.identifiability.tied_to_weak`); empty when nothing is weak.

        Examples
        --------
        >>> from synth.data import record_from_arrays
        >>> t = np.arange(0, 3, 0.01); y = (2 / 3) * (1 - np.exp(-3 * np.clip(t - 0.5, 0, None)))
        >>> fit = fit_structure(record_from_arrays(t, (t >= 0.5) * 1.0, y), "k/(s+p)")
        >>> fit.weak, fit.tied
        ([], [])
        """
        return tied_to_weak(self.names, {**self.parameters, "offset": self.offset}, self.covariance, self.weak)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready result: ``parameters``, ``std``, ``ci95``, ``fit_percent``, ``tf`` and more.

        Examples
        --------
        >>> from synth.data import record_from_arrays
        >>> from synth.ident.simulate import simulate_plant
        >>> t = np.arange(0, 3, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
        >>> y = simulate_plant(Plant.from_string("2/(s+3)"), t, u)
        >>> d = fit_structure(record_from_arrays(t, u, y), "k/(s+p)").to_dict()
        >>> sorted(d["parameters"]), round(d["parameters"]["k"], 6), d["tf"]
        (['delay', 'k', 'p'], 2.0, '2/(s+3)')
        """
        return {
            "structure": self.structure.formula,
            "parameters": dict(self.parameters),
            "std": dict(self.std),
            "ci95": {k: list(v) for k, v in self.ci95.items()},
            "fit_percent": self.fit_percent,
            "tf": self.plant.to_string(6),
            "delay": self.delay,
            "delay_fitted": self.delay_fitted,
            "offset": self.offset,
            "offset_std": self.offset_std,
            "input_reference": self.u0,
            "residual_std": self.residual_std,
            "samples": int(self.y.size),
            "periodic": self.periodic,
            "covariance": {"names": list(self.names), "matrix": self.covariance.tolist()},
            "plant": self.plant.to_dict(),
            "sensor": self.sensor.to_dict() if self.sensor is not None else None,
            "measured_model": self.measured.to_dict(),
            "initial": dict(self.initial),
            "solver": dict(self.solver),
            "weakly_identifiable": [w.to_dict() for w in self.weak],
            "tied_to_weak": [t.to_dict() for t in self.tied],
        }


# ----------------------------------------------------------------- interface


def fit_structure(record: Record, structure: Structure | str, delay: str | float | None = None,
                  sensor: Plant | str | None = None, periodic: bool = False,
                  initial: dict[str, float] | None = None,
                  lower: dict[str, float] | None = None,
                  weights: np.ndarray | None = None, check: bool = False, solver: str = "auto",
                  rtol: float = 0.0, free_start: bool = False) -> TimeFitResult:
    """Fit a structure to a record by simulation error (casadi + IPOPT).

    Parameters
    ----------
    record : Record
        Uniformly sampled input and output (for a step train, the averaged period from :func:`~.steps.average_steps`).
    structure : Structure or str
        E.g. ``"k*(s+z)/((s+p1)*(s+p2))"`` or ``"K*exp(-Td*s)/(T1*s+1)^2"``.
    delay : {"fit", float, None}
        ``"fit"`` estimates it, a number fixes it [s]; ``None`` takes the
        formula's (``exp(-Td*s)`` is fitted, ``exp(-0.02*s)`` fixed, none: 0).
    sensor : Plant or str, optional
        Known sensor ``H`` in series: the record's output is ``F H`` applied to the input.
    periodic : bool
        The record is one period of a periodic response (initial state periodic),
        else the plant starts at rest at the first input sample.
    initial : dict, optional
        Starting values (structure names, optionally ``delay``) instead of the deterministic initialization.
    lower : dict, optional
        Lower bounds of structure parameters (e.g. ``{"p": 0.0}`` keeps a pole in the
        left half-plane); the others are free.
    weights : numpy.ndarray, optional
        Per-sample 0/1 weights of the cost (0: simulated but not fitted, e.g. held-out segments or a start-up
        transient from an unknown initial state); the residual statistics use the weighted samples only. Samples
        that gaps in the record's log made up are weighted 0 too (:func:`synth.data.gaps.gap_weights`).
    check : bool
        Raise :class:`~synth.errors.FitError` when the fit failed (what :func:`synth.ident.identification.identify`,
        ``synth identify`` and :func:`synth.ident.directions.fit_by_direction` do). Without it the reason is in
        ``solver["failure"]`` (empty for a good fit), for callers that try several fits and keep the best.
    solver : {"auto", "ipopt", "convolution"}
        ``"ipopt"``: casadi's symbolic recursion over the record and IPOPT
        (:class:`~synth.ident.sim_error_problem.SimulationErrorProblem`); ``"convolution"``: the same
        cost evaluated by FFT convolution and solved by Levenberg-Marquardt
        (:class:`~synth.ident.convolution_problem.ConvolutionProblem`), whose cost does not grow with
        a symbolic graph; ``"auto"``: the convolution above ``LONG_RECORD`` samples.
    rtol : float
        Convolution solver only: also converged when the SSR decrease still available is below ``rtol`` times
        the SSR (for callers that alternate fits to a tolerance of their own); default 0, to the noise floor.
    free_start : bool
        The plant's state at the first fitted sample is unknown: a nuisance in the covariance (the fit still
        simulates from rest at the first sample; leave out a start that matters with ``weights``).

    Returns
    -------
    TimeFitResult

    Raises
    ------
    ModelError
        Bad structure, sensor or delay option.
    DataError
        Fewer samples than parameters, or a periodic fit of a model with an integrator.
    FitError
        With ``check``: the fit failed (see :func:`synth.ident.fit_failure.fit_failure`): diverged,
        stopped at a limit, absurd parameters, a delay outside the record, or no better than the
        output's mean or than noise.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 4, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
    >>> y = 3.0 + simulate_plant(Plant.from_string("2/(s+3)", delay=0.043), t, u)
    >>> res = fit_structure(record_from_arrays(t, u, y), "k/(s+p)", delay="fit")
    >>> {k: round(v, 6) for k, v in res.parameters.items()}, round(res.offset, 6)
    ({'k': 2.0, 'p': 3.0, 'delay': 0.043}, 3.0)
    """
    st = parse_structure(structure) if isinstance(structure, str) else structure
    args = (sensor, periodic, initial, lower, weights, False, solver, rtol, free_start)
    fit = _fit_structure(record, st, delay, *args)
    if initial is None and (split := ridge_split_start(fit, lower)):  # exchangeable values met (symmetric_ridge)
        fit = off_ridge(_fit_structure(record, st, delay, sensor, periodic, split, *args[3:]), fit)
    if zero_delay_candidate(fit, record.dt):  # a feedthrough's jump at a delay of exactly 0 (synth.ident.zero_delay)
        zero = _fit_structure(record, fit.structure, 0.0, *args)
        if not zero.solver.get("failure") and zero.fit_percent > fit.fit_percent:
            fit = at_zero_delay(zero, fit)
    if check and fit.solver.get("failure"):
        own = {k: v for k, v in fit.parameters.items() if k in fit.structure.parameters}
        raise _failed(fit.structure.formula, fit.solver["failure"], own, fit.solver.get("status"),
                      {k: v for k, v in fit.parameters.items() if k not in own}, record.source)
    return fit


def _failed(formula: str, failure: str, fitted: dict, status: str | None, delay: dict, source: str | None) -> FitError:
    met = coinciding(fitted)  # the FitError of a failed fit (check): a stall where two roots meet named
    return FitError(f"fit of {formula!r} failed: {failure}; {met + '; ' if met else ''}try another structure, a fixed "
                    "delay or a shorter part of the record", where=source, status=status,
                    parameters={**fitted, **delay})


def _fit_structure(record: Record, structure: Structure | str, delay: str | float | None, sensor: Plant | str | None,
                   periodic: bool, initial: dict[str, float] | None, lower: dict[str, float] | None,
                   weights: np.ndarray | None, check: bool, solver: str, rtol: float, free_start: bool) -> TimeFitResult:
    """:func:`fit_structure` at the delay asked for (a fitted delay within ``(0, dt]`` of its intervals)."""
    st = parse_structure(structure) if isinstance(structure, str) else structure
    sensor = as_sensor(sensor)
    fit_delay, fixed_delay, delay_name = resolve_delay(st, delay)
    t, u, y = record.t, record.u, record.y
    n, dt = t.size, record.dt
    p_total = len(st.parameters) + (2 if fit_delay else 1)
    if n <= p_total + 1:
        raise DataError(f"{n} samples cannot determine {p_total} parameters", where=record.source)
    u0 = float(u[0])
    w = u - u0
    if periodic:
        y_ref = float(np.mean(y))
        w_mean = float(np.mean(w))
        wd, yd = w - w_mean, y - y_ref
    else:
        k0 = int(np.flatnonzero(w != 0)[0]) if np.any(w) else 1
        y_ref = float(np.mean(y[:max(1, k0)]))
        wd, yd = w, y - y_ref
    info: dict[str, Any] = {"method": "ipopt (casadi), Gauss-Newton Hessian", "starts": 0, "delay_shifts": 0}
    lin_offset = 0.0
    if initial is None:
        lin_num, lin_den, d0, lin_offset = linear_initial_model(t, wd, yd, st, sensor, periodic,
                                                                None if fit_delay else fixed_delay)
        theta0 = st.canonical_signs(map_to_structure(st, lin_num, lin_den))[0]
        info["initialization"] = "SRIVC linear fit on a delay grid, mapped to the structure"
    else:
        missing = [k for k in st.parameters if k not in initial]
        if missing:
            raise ModelError(f"initial values missing for {', '.join(missing)}")
        theta0 = np.array([float(initial[k]) for k in st.parameters])
        d0 = float(initial.get(delay_name, initial.get("delay", fixed_delay or 0.0)))
        info["initialization"] = "given"
    if not fit_delay:
        d0 = float(fixed_delay or 0.0)
    num_chk, den_chk = st.coefficients(theta0)
    full_den = np.polymul(den_chk, sensor.den) if sensor is not None else den_chk
    if periodic and abs(np.polyval(full_den, 0.0)) < 1e-12 * np.max(np.abs(full_den)):
        raise DataError("a periodic fit (an averaged step train) needs a model without an integrator (no unique "
                        "periodic state); fit the record as it is (average='none', --average none)", record.source)
    has_d = (st.num_degree == st.den_degree) and sensor is None
    if weights is not None:
        weights = np.asarray(weights, float)
        if weights.shape != (n,) or not np.all((weights == 0) | (weights == 1)):
            raise ModelError(f"weights must be {n} values of 0 or 1", where="weights")
    weights = gap_weights(t, u, record.gaps, weights=weights)  # what gaps in the log made up: weight 0
    mask = None if weights is None else weights > 0
    if mask is not None and int(mask.sum()) <= p_total + 1:
        raise DataError(f"{int(mask.sum())} weighted samples cannot determine {p_total} parameters", record.source)
    if solver not in ("auto", "ipopt", "convolution"):
        raise ModelError(f"solver must be 'auto', 'ipopt' or 'convolution', got {solver!r}", where="solver")
    if solver == "convolution" or (solver == "auto" and n > LONG_RECORD):
        prob: Any = ConvolutionProblem(st, sensor, n, dt, periodic, theta0, fit_delay, y, has_d, weights)
        info["method"] = "Levenberg-Marquardt, exact Jacobian by FFT convolution of the sensitivities"
    else:
        prob = SimulationErrorProblem(st, sensor, n, dt, periodic, theta0, fit_delay, y, has_d, weights)
    b0 = y_ref + lin_offset if not periodic else y_ref - float(Plant(num_chk, den_chk).dc_gain()) * w_mean * (
        sensor.dc_gain() if sensor is not None else 1.0)
    initial_out = {**dict(zip(st.parameters, theta0.tolist())), delay_name: d0}
    unknown = sorted(set(lower or {}) - set(st.parameters))
    if unknown:
        raise ModelError(f"bounds for parameters not in the structure: {', '.join(unknown)}", where="lower")
    lb = None if not lower else np.array([float(lower.get(k, -np.inf)) for k in st.parameters])

    solve_options = {"rtol": rtol} if isinstance(prob, ConvolutionProblem) else {}

    noise_dof = max(1, (n if mask is None else int(mask.sum())) - p_total)

    def run(theta_start: np.ndarray, d_start: float,
            within_sample: bool = False) -> tuple[np.ndarray, float, int, dict[str, Any], int]:
        if not fit_delay:
            m = int(np.floor(d_start / dt + 1e-9))
            xs, ssr, st_info = prob.solve(np.r_[theta_start / prob.scale, b0], prob.inputs(w, m, d_start - m * dt),
                                          lower=lb, **solve_options)
            return xs, ssr, m, st_info, 0
        return walk_intervals(lambda x0, m, bounded, inside: prob.solve(
            x0, prob.inputs(w, m), nonnegative_f=bounded, lower=lb, within_sample=inside, **solve_options),
            theta_start / prob.scale, d_start, b0, dt, noise_dof, within_sample)

    xs, ssr, m, st_info, shifts = run(theta0, d0)
    info["starts"] = 1
    yd_fit, y_fit = (yd, y) if mask is None else (yd[mask], y[mask])
    init_ssr = float(np.sum((yd_fit - np.mean(yd_fit)) ** 2))
    ssr_start = start_ssr(prob, theta0, d0, b0, w, y, mask, fit_delay, dt)
    def below_zero(fit: tuple) -> bool:  # a whole delay below 0: no plant's (fit_failure)
        return fit_delay and fit[2] * dt + float(fit[0][len(st.parameters)]) < 0.0
    lost, lm = below_zero((xs, ssr, m)) or not st_info["success"] or not ssr <= min(init_ssr, ssr_start), None
    if isinstance(prob, SimulationErrorProblem) and lb is None and lost:
        # IPOPT lost its way (a cancelling pair trading with the delay, or the delay's bound at 0 missed): Levenberg-
        # Marquardt from the same start; not with lower bounds (IPOPT's constraints, Levenberg-Marquardt's clipping)
        ipopt, failed_status, failed_ssr, prob = prob, st_info.get("status"), ssr, ConvolutionProblem(
            st, sensor, n, dt, periodic, theta0, fit_delay, y, has_d, weights)
        cand = run(theta0, d0)
        info["starts"] += 1
        if (cand[3]["success"] or cand[3].get("status") in LIMIT_STATUSES) and not below_zero(cand) and (  # judged later
                cand[1] < ssr or below_zero((xs, ssr, m)) or converged_replaces(cand[3], cand[1], st_info, ssr, noise_dof)):
            xs, ssr, m, st_info, shifts = cand
            info["method"] = (f"Levenberg-Marquardt, exact Jacobian by FFT convolution of the sensitivities (IPOPT "
                              f"from the same start: {failed_status}, SSR {failed_ssr:.4g}, {ssr_start:.4g} at the start)")
        else:  # IPOPT at its limit on a ridge or where Levenberg-Marquardt converged to its SSR: scaled starts by LM
            ridge = bool(roots_beyond_record(*st.coefficients(xs[:len(st.parameters)] * ipopt.scale), n * dt, dt))
            prob, lm = ipopt, (prob if failed_status in LIMIT_STATUSES and crawl_over(cand, ssr, noise_dof, ridge) else None)
    crawled = lb is not None and st_info.get("status") in LIMIT_STATUSES and ssr < min(init_ssr, ssr_start)  # see above
    if (not st_info["success"] or not np.isfinite(ssr) or ssr > min(init_ssr, ssr_start)) and not crawled:
        prob, kept_prob = (lm or prob), prob
        for factor in (0.5, 2.0, 0.2, 5.0):
            cand = run(theta0 * factor, d0)
            info["starts"] += 1
            if cand[3]["success"] and (cand[1] < ssr or converged_replaces(cand[3], cand[1], st_info, ssr, noise_dof)):
                (xs, ssr, m, st_info, shifts), kept_prob = cand, prob
                if st_info["success"] and ssr <= min(init_ssr, ssr_start):
                    break
        info["method"] += f"; {SCALED_BY_LM}" if lm is not None and kept_prob is lm else ""
        prob = kept_prob
    if fit_delay and st.num_degree >= st.den_degree:  # a jump at the delay: each sample interval its own valley
        xs, ssr, m, st_info, shifts = best_sample(run, xs, ssr, m, st_info, shifts, prob.scale, dt, info)
    if not ssr <= ssr_start and (kept := converged_start(prob, theta0, d0, b0, w, y, mask, fit_delay, dt, lb)):
        info["method"] += (f"; the start kept: the solver ended above it ({st_info.get('status')}, SSR {ssr:.6g} "
                           f"against {ssr_start:.6g}); a Gauss-Newton step from it gains {kept[2]:.2g} std at most")
        (xs, m, _), ssr, shifts, st_info = kept, ssr_start, 0, {**st_info, "success": True, "status": START_CONVERGED}
    info.update(st_info)
    info["delay_shifts"] = shifts
    p = len(st.parameters)
    theta_c, flipped = st.canonical_signs(xs[:p] * prob.scale)  # the same plant, e.g. w, z > 0 for (-w, -z)
    if flipped and (lb is None or np.all(theta_c >= lb)):
        xs, info["signs_flipped"] = np.r_[theta_c / prob.scale, xs[p:]], list(flipped)
    theta = xs[:p] * prob.scale
    if fit_delay:
        f_hat, b_hat = float(xs[p]), float(xs[p + 1])
        par = prob.inputs(w, m)
    else:
        f_hat, b_hat = float(d0 - m * dt), float(xs[p])
        par = prob.inputs(w, m, f_hat)
    d_hat = m * dt + f_hat
    yhat = np.asarray(prob.yhat_fn(xs, par)).ravel()
    J, resid, scale_vec = scaled_jacobian(prob, xs, par, y, yhat, mask, fit_delay)
    fit_pct = float(100.0 * (1.0 - np.linalg.norm(resid) / np.linalg.norm(y_fit - np.mean(y_fit))))
    dof = resid.size - J.shape[1]
    s2 = float(np.sum(resid**2) / dof)
    JtJ, rows = J.T @ J, (np.arange(n) if mask is None else np.flatnonzero(mask))
    # a record known not to start at rest (synth.ident.unknown_start): the state at the first fitted sample is a
    # nuisance whose uncertainty the parameters carry
    columns = None if periodic else free_columns(np.polymul(st.coefficients(theta)[1], [1.0] if sensor is None else
                                                             sensor.den), dt, rows, n)
    gram = free_start_gram(J, JtJ, columns) if free_start and columns is not None else JtJ
    # an output interpolated from uneven stamps: its residuals understate the noise the estimates carry
    cov, note = fit_covariance(gram, s2 * record.noise_factor, p if fit_delay else None, dt)
    cov = cov[:J.shape[1], :J.shape[1]]
    notes = (note, misfit_note(y[rows], (yhat - b_hat)[rows], resid),  # resid is on rows (scaled_jacobian)
             correlated_residuals_note(resid, expected=record.noise_correlation))  # the structure, then the noise
    info.update({"covariance_note": "; ".join(n for n in notes if n)} if any(notes) else {})
    with np.errstate(all="ignore"):
        sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    remaining = float("inf")
    if st_info.get("status") in LIMIT_STATUSES and s2 > 0 and np.all(np.isfinite(JtJ)):
        remaining = remaining_improvement(prob, xs, par, J, resid, JtJ, scale_vec, s2, mask, y, lb, fit_delay, dt)
        info["remaining_improvement_std"] = remaining
    fitted = dict(zip(st.parameters, theta.tolist()))
    ridge = roots_beyond_record(*st.coefficients(theta), n * dt, dt)
    failure = fit_failure(fitted, theta0, st_info.get("status"),
                          bool(st_info.get("success")), fit_pct, d_hat if fit_delay else None, n * dt,
                          int(y_fit.size), p_total, remaining,
                          float(100.0 * (1.0 - np.sqrt(ssr_start) / np.linalg.norm(y_fit - np.mean(y_fit)))),
                          "Levenberg-Marquardt" if isinstance(prob, ConvolutionProblem) else "IPOPT", ridge,
                          no_response_p_value(w, y, y_fit, resid, p_total, SIGNIFICANCE))
    info["failure"] = failure
    if failure and check:
        raise _failed(st.formula, failure, fitted, st_info.get("status"), {delay_name: float(d_hat)}, record.source)
    if -1e-7 <= d_hat < 0.0 or (failure and d_hat < 0.0):  # IPOPT relaxes f >= 0 by 1e-8; a failed fit's delay
        d_hat = 0.0  # below 0 is in solver["failure"], and its model (never a result) is built with none
    tq = float(t_ppf(0.975, dof))
    names = [*st.parameters, *([delay_name] if fit_delay else []), "offset"]
    values = [*theta.tolist(), *([d_hat] if fit_delay else []), b_hat]
    params = {k: float(v) for k, v in zip(names[:-1], values[:-1])}
    std = {k: float(s) for k, s in zip(names[:-1], sd[:-1])}
    if not fit_delay:
        params[delay_name], std[delay_name] = float(d_hat), 0.0
    ci = {k: (params[k] - tq * std[k], params[k] + tq * std[k]) for k in params}
    plant = st.plant(theta, delay=d_hat, input=record.input, output=record.output, label="identified")
    info.update({"nyquist_note": beyond} if (beyond := nyquist_note(plant, dt)) else {})
    measured = plant.series(sensor) if sensor is not None else plant
    if sensor is not None:
        measured = Plant(measured.num, measured.den, d_hat, record.input, record.output, "identified with sensor")
    if not periodic:  # a start state that is not at rest (synth.ident.start_state)
        info["start_state"] = start_state_test(J, JtJ, resid, rows, columns, dt, d_hat, sd, values, names).to_dict()
    return TimeFitResult(st, params, std, ci, names, cov, float(d_hat), fit_delay, b_hat, float(sd[-1]),
                         fit_pct, float(np.sqrt(s2)), plant, sensor, measured, initial_out, info, t.copy(), y.copy(),
                         yhat, u0, periodic, weights)

