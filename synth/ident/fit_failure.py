"""When a finished simulation-error fit is not a result (issue 16: a failed fit is a failure).

:func:`synth.ident.timefit.fit_structure` raises :class:`synth.errors.FitError` with the
reason :func:`fit_failure` gives; ``synth identify`` prints it as one line and exits 1.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from synth.distributions import f_sf

__all__ = ["ABSURD_FACTOR", "CONVERGED_WITHIN", "FAILED_STATUSES", "GROWING", "GROWTH_EXPONENT", "LIMIT_STATUSES",
           "NO_RESPONSE", "SIGNIFICANCE", "fit_failure", "remaining_improvement", "roots_beyond_record",
           "scaled_jacobian", "start_point", "start_ssr"]

#: IPOPT return statuses that end a fit without a usable optimum
FAILED_STATUSES = ("Diverging_Iterates", "Maximum_Iterations_Exceeded", "Maximum_CpuTime_Exceeded",
                   "Maximum_WallTime_Exceeded", "Infeasible_Problem_Detected", "Invalid_Number_Detected",
                   "Error_In_Step_Computation", "Not_Enough_Degrees_Of_Freedom", "Invalid_Problem_Definition",
                   "Internal_Error", "Insufficient_Memory", "Unrecoverable_Exception", "NonIpopt_Exception_Thrown",
                   "User_Requested_Stop", "Invalid_Option")

#: statuses of a solver stopped at a limit: accepted if the remaining step is small (see :func:`fit_failure`)
LIMIT_STATUSES = ("Maximum_Iterations_Exceeded", "Maximum_CpuTime_Exceeded", "Maximum_WallTime_Exceeded")

#: less than this many standard errors still to go (see :func:`fit_failure`) counts as converged
CONVERGED_WITHIN = 0.1

#: the words of every failure that finds no response to the input in the record (the F-tests of :func:`fit_failure`)
NO_RESPONSE = "the fitted model explains no more of the output than"

#: p-value of the F-test above which a fit explains no more than noise (see :func:`fit_failure`)
SIGNIFICANCE = 1e-3

#: a fitted parameter this many times larger than its deterministic start (and than 1) is a diverged fit
ABSURD_FACTOR = 1e8

#: a fitted right-half-plane pole whose mode grows by more than e to this power over the record is a failure: the
#: simulation explodes over the record (a black-box test: 5/((s+1)(s+5)) e^(-0.15 s) on uneven stamps, a pole at
#: +0.85 rad/s growing e^170 over 200 s with k = 4.8e-74, fit 0.05 %, exit 0)
GROWTH_EXPONENT = 14.0
GROWING = "in the right half-plane, growing by"


def fit_failure(parameters: dict[str, float], start: np.ndarray, status: str | None, success: bool,
                fit_percent: float, delay: float | None, duration: float, samples: int = 0, free: int = 0,
                remaining_step: float = float("inf"), start_fit_percent: float = float("nan"),
                solver: str = "IPOPT", ridge: str = "", whitened_p: float = 0.0) -> str:
    """Why a finished fit is not a result, or ``""`` if it is one.

    A fit fails when the solver diverged or stopped at a limit (:data:`FAILED_STATUSES`), a
    parameter is not finite or ``ABSURD_FACTOR`` times larger than both its start and 1, the fit is
    no better than the output's mean (``fit_percent <= 0``) or than noise would be (given ``samples``
    and ``free``: the F-test of the explained variance against the residual one has a p-value above
    ``SIGNIFICANCE``), a fitted delay lies outside ``[0, duration)``, the fit ended with a larger residual
    than its own start had (``start_fit_percent``): a local solver that moved uphill did not converge, or the
    model has a pole or zero far outside what the record resolves (``ridge``).

    Parameters
    ----------
    parameters : dict
        Fitted structure parameters.
    start : numpy.ndarray
        Their deterministic starting values (same order).
    status : str or None
        The solver's return status.
    success : bool
        The solver reported success.
    fit_percent : float
    delay : float or None
        The fitted delay [s] (``None`` when it was fixed).
    duration : float
        Length of the fitted record [s].
    samples, free : int
        Fitted samples and free parameters (delay and offset included); 0 skips the F-test.
    remaining_step : float
        How far the final point still is from the optimum, in standard errors: the square root of the
        best decrease of ``SSR / s^2`` along the Gauss-Newton step. A solver stopped at an iteration or
        time limit (:data:`LIMIT_STATUSES`) with less than ``CONVERGED_WITHIN`` to go has converged as
        far as the data can tell (e.g. crawling along a fold such as ``T1 = T2``) and is not a failure;
        diverging is always one.
    start_fit_percent : float
        The fit (same measure as ``fit_percent``) of the starting values, NaN when unknown. The residual norm
        is ``1 - fit/100`` of the output's spread, so the fit is worse than its start when
        ``100 - fit_percent`` exceeds ``100 - start_fit_percent`` by more than a relative ``1e-6``.
    solver : str
        The solver that made the fit, as the message names it (IPOPT, or Levenberg-Marquardt: both report
        IPOPT's status strings).
    whitened_p : float
        p-value that the output moves with the input at all: the cross-correlation of the two, each prewhitened by
        its own autoregressive model (:func:`synth.ident.coloured_relevance.response_p_value`; 0: not tested): above
        ``SIGNIFICANCE`` the model matched an output that wanders on its own, not a response to the input.
    ridge : str
        :func:`roots_beyond_record` of the fitted model: a fit with a pole or zero there ended on a ridge of its
        structure that the record cannot tell apart from its limit (``K (1 - a s)`` with ``K -> 0``,
        ``a -> inf``: a differentiator), where neither the solver's status nor the remaining step says how far
        the optimum is (seen: fit 36 % "converged" where the record's optimum fits 95 %). A failure, named after
        the other reasons (the F-test's on noise).

    Returns
    -------
    str
        What failed, in a few words (empty if nothing did).

    Examples
    --------
    >>> fit_failure({"K": 2e24, "T": 0.1}, np.array([3.0, 0.1]), "Diverging_Iterates", False, -2.19, 0.01, 60.0)
    'IPOPT stopped with Diverging_Iterates (K = 2e+24, fit -2.19 %)'
    >>> fit_failure({"k": 2.0, "p": 3.0}, np.array([2.1, 2.9]), "Solve_Succeeded", True, 99.1, -452.67, 60.0)
    'the fitted delay is -452.67 s, outside [0, 60) s'
    >>> fit_failure({"k": 2.0, "p": 3.0}, np.array([2.1, 2.9]), "Solve_Succeeded", True, 0.2, 0.02, 2.0, 200, 4)
    'fit 0.20 %: the fitted model explains no more of the output than noise would (F-test p = 0.85): a local...'
    >>> fit_failure({"k": 2.0, "p": 3.0}, np.array([2.1, 2.9]), "Solve_Succeeded", True, 99.1, 0.02, 60.0)
    ''
    >>> fit_failure({"k": 2.0, "p": 3.0}, np.array([2.1, 2.9]), "Maximum_Iterations_Exceeded", False, 98.6, 0.02,
    ...             60.0, remaining_step=0.004)  # stopped at the limit, but converged within its uncertainty
    ''
    >>> fit_failure({"K": 5e-6, "a": 1.8e5}, np.array([1e-5, 1.2e5]), "Maximum_Iterations_Exceeded", False, 35.2, None,
    ...             60.0, remaining_step=1e-4, ridge="a zero at 5.6e-06 rad/s, far below what 60 s resolve")
    'IPOPT ended (Maximum_Iterations_Exceeded) on a ridge of the structure (a zero at 5.6e-06 rad/s, far below what 60 s
    resolve, fit 35.20 %)'
    >>> fit_failure({"k": 2e-12, "p": -3.2}, np.array([2.1, 2.9]), "Solved_To_Acceptable_Level", True, 1.74, 9.36,
    ...             60.0, start_fit_percent=96.1)
    'the fit ended worse than its start (fit 1.74 % against 96.10 % at the start): the solver moved away'
    """
    bad = {k: v for (k, v), v0 in zip(parameters.items(), np.asarray(start, float))
           if not np.isfinite(v) or abs(v) > ABSURD_FACTOR * max(1.0, abs(float(v0)) if np.isfinite(v0) else 1.0)}
    shown = ", ".join(f"{k} = {v:.3g}" for k, v in bad.items())
    limited = status in LIMIT_STATUSES and remaining_step < CONVERGED_WITHIN
    if not success and status in FAILED_STATUSES and not limited:
        detail = ", ".join(x for x in (shown, f"fit {_percent(fit_percent)} %" if np.isfinite(fit_percent) else "") if x)
        return f"{solver} stopped with {status}" + (f" ({detail})" if detail else "")
    if bad:
        return f"parameters at absurd magnitudes ({shown})"
    if delay is not None and not (np.isfinite(delay) and -1e-7 <= delay < duration):  # IPOPT relaxes bounds by 1e-8
        return f"the fitted delay is {delay:.5g} s, outside [0, {duration:.5g}) s"
    if np.isfinite(start_fit_percent) and 100.0 - fit_percent > (100.0 - start_fit_percent) * (1.0 + 1e-6):
        return (f"the fit ended worse than its start (fit {_percent(fit_percent)} % against "
                f"{_percent(start_fit_percent)} % at the start): the solver moved away")
    if not np.isfinite(fit_percent) or fit_percent <= 0.0:
        return f"fit {_percent(fit_percent)} %: the model explains the output no better than its mean"
    if samples > free > 1:
        explained = 1.0 - (1.0 - fit_percent / 100.0) ** 2  # share of the variance about the mean
        dof = samples - free
        f_stat = (explained / (free - 1)) / (max(1.0 - explained, 1e-300) / dof)
        p_value = float(f_sf(f_stat, free - 1, dof))
        if p_value > SIGNIFICANCE:
            began = ", ".join(f"{k} = {float(v0):.3g}" for k, v0 in zip(parameters, np.asarray(start, float)))
            return (f"fit {fit_percent:.2f} %: {NO_RESPONSE} noise would "
                    f"(F-test p = {p_value:.2g}): a local minimum reached from the start ({began}), or a record "
                    "without a response to its input")
    if whitened_p > SIGNIFICANCE:
        return (f"fit {_percent(fit_percent)} %: {NO_RESPONSE} the output's own drift would "
                f"(the prewhitened output against the prewhitened input: p = {whitened_p:.2g}): an "
                "output that wanders on its own, not a response to the input")
    if GROWING in ridge:
        return (f"the fitted model is unstable ({ridge.split('; ')[0]}, fit {_percent(fit_percent)} %): its simulation "
                "explodes over the record")
    if ridge:
        return f"{solver} ended ({status}) on a ridge of the structure ({ridge}, fit {_percent(fit_percent)} %)"
    return ""


def roots_beyond_record(num: np.ndarray, den: np.ndarray, duration: float, dt: float) -> str:
    """The model's poles and zeros more than a thousand times slower than the record is long (``|r| < 1e-3 /
    duration``) or faster than its Nyquist frequency (``|r| > 1e3 pi / dt``), and a right-half-plane pole whose mode
    grows by more than ``e^GROWTH_EXPONENT`` over the record, in words; ``""`` if none.

    Examples
    --------
    >>> roots_beyond_record(np.array([-0.88, 5e-6]), np.polymul([0.3, 1.0], [0.3, 1.0]), 60.0, 0.01)
    'a zero at 5.68e-06 rad/s, far below what 60 s resolve'
    >>> roots_beyond_record(np.array([-1.5, 3.0]), np.polymul([1.0, 1.0], [0.25, 1.0]), 60.0, 0.01)
    ''
    >>> roots_beyond_record(np.array([1.0]), np.array([1.0, -0.5]), 60.0, 0.01)  # a mode of e^(0.5 t) for 60 s
    'a pole at +0.5 rad/s in the right half-plane, growing by e^30 over the 60 s record'
    """
    poly = np.trim_zeros(np.asarray(den, float), "f")
    poles = np.roots(poly) if poly.size > 1 else np.zeros(0)
    words = [f"a pole at {p.real:+.3g} rad/s {GROWING} e^{p.real * duration:.3g} over the {duration:.3g} s record"
             for p in poles if p.real * duration > GROWTH_EXPONENT][:1]
    for kind, poly in (("zero", num), ("pole", den)):
        poly = np.trim_zeros(np.asarray(poly, float), "f")
        roots = np.abs(np.roots(poly)) if poly.size > 1 else np.zeros(0)
        roots = roots[roots > 0]  # an integrator or a differentiator is a structure's own choice
        words += [f"a {kind} at {r:.3g} rad/s, far below what {duration:.3g} s resolve" for r in roots
                  if r < 1e-3 / duration]
        words += [f"a {kind} at {r:.3g} rad/s, far beyond the Nyquist frequency {np.pi / dt:.3g} rad/s" for r in roots
                  if r > 1e3 * np.pi / dt]
    return "; ".join(words)


def _percent(value: float) -> str:
    """A fit in percent for a message: two decimals, or three digits where a diverged fit is astronomically bad."""
    return f"{value:.2f}" if abs(value) < 1e6 else f"{value:.3g}"


def start_ssr(prob: Any, theta0: np.ndarray, d0: float, b0: float, w: np.ndarray, y: np.ndarray,
               mask: np.ndarray | None, fit_delay: bool, dt: float) -> float:
    """Sum of squared (weighted) residuals of the starting values, ``inf`` where their simulation is not finite
    (a start whose fit the solver must not end above: see :func:`fit_failure`).

    Parameters
    ----------
    prob : SimulationErrorProblem or ConvolutionProblem
        The fit's problem (its ``scale``, ``inputs`` and ``yhat_fn``).
    theta0 : numpy.ndarray
        Starting structure parameters.
    d0, b0 : float
        Starting delay [s] and output offset.
    w, y : numpy.ndarray
        The input relative to its first sample, and the measured output.
    mask : numpy.ndarray or None
        The fitted samples (None: all).
    fit_delay : bool
        Whether the delay is a decision variable.
    dt : float
        Sample interval [s].

    Returns
    -------
    float

    Examples
    --------
    >>> from synth.ident.convolution_problem import ConvolutionProblem
    >>> from synth.ident.structure import parse_structure
    >>> st, t = parse_structure("k/(s+p)"), np.arange(400) * 0.01
    >>> w = (t >= 0.5).astype(float); y = 2.0 * (1 - np.exp(-(t - 0.5).clip(0)))
    >>> prob = ConvolutionProblem(st, None, t.size, 0.01, False, np.array([2.0, 1.0]), False, y, False, None)
    >>> start_ssr(prob, np.array([2.0, 1.0]), 0.0, 0.0, w, y, None, False, 0.01) < 1e-3
    True
    """
    x0, par, _ = start_point(prob, theta0, d0, b0, w, fit_delay, dt)
    with np.errstate(all="ignore"):
        r = y - np.asarray(prob.yhat_fn(x0, par)).ravel()
        if mask is not None:
            r = r[mask]
        value = float(r @ r)
    return value if np.isfinite(value) else float("inf")


def start_point(prob: Any, theta0: np.ndarray, d0: float, b0: float, w: np.ndarray, fit_delay: bool,
                dt: float) -> tuple[np.ndarray, Any, int]:
    """The starting values as the fit's decision variables (scaled parameters, the delay's fraction of a sample when
    it is fitted, the offset), the problem's inputs for the delay's whole samples, and those samples
    (arguments as :func:`start_ssr`'s).

    Examples
    --------
    >>> from synth.ident.convolution_problem import ConvolutionProblem
    >>> from synth.ident.structure import parse_structure
    >>> t = np.arange(100) * 0.01; w = (t >= 0.2).astype(float)
    >>> prob = ConvolutionProblem(parse_structure("k/(s+p)"), None, t.size, 0.01, False, np.array([2.0, 4.0]), True,
    ...                           w, False, None)
    >>> x0, _, m = start_point(prob, np.array([2.0, 4.0]), 0.035, 0.5, w, True, 0.01)
    >>> x0.round(6).tolist(), m
    ([1.0, 1.0, 0.005, 0.5], 3)
    """
    m = int(np.floor(d0 / dt + 1e-9))
    f = d0 - m * dt
    x0 = np.r_[theta0 / prob.scale, f, b0] if fit_delay else np.r_[theta0 / prob.scale, b0]
    return x0, (prob.inputs(w, m) if fit_delay else prob.inputs(w, m, f)), m


def scaled_jacobian(prob: Any, xs: np.ndarray, par: Any, y: np.ndarray, yhat: np.ndarray, mask: np.ndarray | None,
                    fit_delay: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Jacobian of ``yhat`` in the fit's parameters (unscaled: structure parameters, the delay's fraction when
    fitted, the offset), the residual ``y - yhat`` (both on the fitted samples of ``mask``) and the scale that
    unscales them, as :func:`remaining_improvement` and the covariance take them.

    Examples
    --------
    >>> from synth.ident.convolution_problem import ConvolutionProblem
    >>> from synth.ident.structure import parse_structure
    >>> t = np.arange(100) * 0.01; w = (t >= 0.2).astype(float)
    >>> prob = ConvolutionProblem(parse_structure("k/(s+p)"), None, t.size, 0.01, False, np.array([2.0, 4.0]), False,
    ...                           w, False, None)
    >>> x, par = np.array([1.0, 1.0, 0.0]), prob.inputs(w, 0, 0.0)
    >>> yhat = np.asarray(prob.yhat_fn(x, par)).ravel()
    >>> J, resid, scale = scaled_jacobian(prob, x, par, yhat + 0.1, yhat, t >= 0.5, False)
    >>> J.shape, float(resid.max()), scale.tolist()
    ((50, 3), 0.1, [2.0, 4.0, 1.0])
    """
    scale = np.r_[prob.scale, 1.0, 1.0] if fit_delay else np.r_[prob.scale, 1.0]
    J = np.asarray(prob.jac_fn(xs, par)) / scale[None, :]
    resid = y - yhat
    if mask is not None:
        J, resid = J[mask], resid[mask]
    return J, resid, scale


def remaining_improvement(prob: Any, xs: np.ndarray, par: np.ndarray, J: np.ndarray,
                           resid: np.ndarray, JtJ: np.ndarray, scale_vec: np.ndarray, s2: float, mask: np.ndarray | None,
                           y: np.ndarray, lb: np.ndarray | None, fit_delay: bool, dt: float) -> float:
    """How far a fit stopped at a limit still is from its optimum: ``sqrt`` of the best decrease of
    ``SSR / s^2`` along the Gauss-Newton step (halved down to 1/32), i.e. in standard errors. ``prob`` is the fit's
    problem (:class:`~synth.ident.sim_error_problem.SimulationErrorProblem` or its convolution counterpart), ``xs``
    its scaled decision variables, ``J`` and ``resid`` the Jacobian (in the parameters' units) and residual on the
    fitted samples (``mask``).

    Examples
    --------
    >>> class Line:  # y = a t fitted as a scaled a (the decision variable 2 a)
    ...     p, scale = 1, np.array([0.5])
    ...     def yhat_fn(self, xs, par): return xs[0] * 0.5 * par
    >>> t = np.arange(5.0)
    >>> J, resid = t[:, None], 2.0 * t               # stopped at a = 0 where a = 2 fits
    >>> round(remaining_improvement(Line(), np.array([0.0]), t, J, resid, J.T @ J, np.array([0.5]), 1.0, None,
    ...                             2.0 * t, None, False, 0.1), 3)   # sqrt(SSR drop / s^2) = sqrt(120)
    10.954
    """
    g, p = J.T @ resid, prob.p
    steps = [np.linalg.lstsq(JtJ, g, rcond=None)[0] / scale_vec]
    lo, hi = np.full(xs.size, -np.inf), np.full(xs.size, np.inf)
    if lb is not None:
        lo[:p] = lb / prob.scale
    if fit_delay:
        lo[p], hi[p] = 0.0, dt
    full = xs + steps[0]
    target = np.clip(full, lo, hi)
    held = target != full
    if held.any():  # the step past a bound, clipped, moves the others for a move the bound refuses: also the step
        # with those held at their bounds, the others' Gauss-Newton step given that
        move = np.zeros(xs.size)
        move[held] = (target[held] - xs[held]) * scale_vec[held]
        free = ~held
        move[free] = np.linalg.lstsq(JtJ[np.ix_(free, free)], g[free] - JtJ[np.ix_(free, held)] @ move[held],
                                     rcond=None)[0]
        steps.append(move / scale_vec)
    ssr0 = float(resid @ resid)
    best = 0.0
    for step in steps:
        for alpha in (1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125):
            trial = np.clip(xs + alpha * step, lo, hi)
            try:
                r = y - np.asarray(prob.yhat_fn(trial, par)).ravel()
            except RuntimeError:  # casadi could not evaluate the model there (a matrix exponential overflowed)
                continue
            if mask is not None:
                r = r[mask]
            ssr = float(r @ r)
            if np.isfinite(ssr):
                best = max(best, (ssr0 - ssr) / s2)
    return float(np.sqrt(best))
