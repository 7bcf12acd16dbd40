"""A deterministic start that is already an optimum, kept where the solver ended above it.

The SRIVC start (:mod:`synth.ident.srivc`) is an instrumental-variable estimate of the same model; on a record it
resolves well it is already at the simulation-error optimum to within the noise. Along a nearly cancelling pair the
cost is flat, and IPOPT (or Levenberg-Marquardt after it) can drift along that valley and stop at its iteration
limit a little above where it began: a first-order-plus-one-pair fit ended at 98.10710 % against 98.10713 % at its
start, and was reported as failed ("ended worse than its start"). When no Gauss-Newton step from the start lowers
the sum of squares by more than :data:`~synth.ident.fit_failure.CONVERGED_WITHIN` standard errors (the test a fit
stopped at its iteration limit passes, :func:`~synth.ident.fit_failure.remaining_improvement`), the start is a
converged fit and is the answer; otherwise the fit fails as before.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from synth.ident.fit_failure import CONVERGED_WITHIN, remaining_improvement, scaled_jacobian, start_point

__all__ = ["SCALED_BY_LM", "START_CONVERGED", "converged_replaces", "converged_start", "crawl_over"]

START_CONVERGED = "Start_Converged"
"""The solver status a fit reports when its start was kept (:func:`converged_start`)."""

SCALED_BY_LM = ("the scaled starts by Levenberg-Marquardt (IPOPT reached its iteration limit, crawling, where "
                "Levenberg-Marquardt from the same start converged)")
"""What a fit's method says when a scaled start by Levenberg-Marquardt is its answer (:func:`crawl_over`)."""


def converged_start(prob: Any, theta0: np.ndarray, d0: float, b0: float, w: np.ndarray, y: np.ndarray,
                    mask: np.ndarray | None, fit_delay: bool, dt: float,
                    lower: np.ndarray | None) -> tuple[np.ndarray, int, float] | None:
    """The start as the fit's decision variables, its delay's whole samples and how far it is from an optimum (in
    standard errors), when that is less than :data:`~synth.ident.fit_failure.CONVERGED_WITHIN`; else None.

    Parameters
    ----------
    prob, theta0, d0, b0, w, y, mask, fit_delay, dt
        As :func:`~synth.ident.fit_failure.start_ssr`'s (the problem needs ``jac_fn`` too).
    lower : numpy.ndarray or None
        Lower bounds of the structure parameters: a start below one is never kept.

    Returns
    -------
    (numpy.ndarray, int, float) or None

    Examples
    --------
    A noisy step's least-squares fit of ``k/(s + p)`` is kept; the truth it was drawn from is not an optimum of
    that record (about one standard error away, as an estimate's scatter says), nor is twice the gain:

    >>> from synth.ident.convolution_problem import ConvolutionProblem
    >>> from synth.ident.structure import parse_structure
    >>> st, t = parse_structure("k/(s+p)"), np.arange(400) * 0.01
    >>> w = (t >= 0.5).astype(float)
    >>> y = 2.0 * (1 - np.exp(-(t - 0.5).clip(0))) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> prob = ConvolutionProblem(st, None, t.size, 0.01, False, np.array([2.0, 1.0]), False, y, False, None)
    >>> xs, _, _ = prob.solve(np.array([1.0, 1.0, 0.0]), prob.inputs(w, 0, 0.0))
    >>> best = xs[:2] * prob.scale
    >>> x, m, left = converged_start(prob, best, 0.0, xs[2], w, y, None, False, 0.01, None)
    >>> m, bool(left < 0.1)
    (0, True)
    >>> [converged_start(prob, theta, 0.0, 0.0, w, y, None, False, 0.01, None) is None
    ...  for theta in (np.array([2.0, 1.0]), np.array([4.0, 1.0]))]
    [True, True]
    """
    if lower is not None and not np.all(theta0 >= lower):
        return None
    x0, par, m = start_point(prob, theta0, d0, b0, w, fit_delay, dt)
    with np.errstate(all="ignore"):
        J, resid, scale = scaled_jacobian(prob, x0, par, y, np.asarray(prob.yhat_fn(x0, par)).ravel(), mask,
                                          fit_delay)
    dof = resid.size - J.shape[1]
    s2 = float(resid @ resid) / dof if dof > 0 else float("nan")
    if not (np.isfinite(s2) and s2 > 0 and np.all(np.isfinite(J))):
        return None
    left = remaining_improvement(prob, x0, par, J, resid, J.T @ J, scale, s2, mask, y, lower, fit_delay, dt)
    return (x0, m, left) if left < CONVERGED_WITHIN else None


def converged_replaces(candidate: dict[str, Any], candidate_ssr: float, current: dict[str, Any], current_ssr: float,
                       noise_dof: int) -> bool:
    """Whether a converged fit replaces one that stopped at a limit with an SSR at most a hundredth of a noise variance
    below it: the same answer, and one that says it converged.

    IPOPT with the delay's bound at 0 active can run its 300 iterations at the optimum, its SSR taken 1e-8 past the
    bound (IPOPT's bound relaxation), so a hair below what any delay of 0 or more gives; Levenberg-Marquardt from the
    same start converges there.

    Parameters
    ----------
    candidate, current : dict
        The solvers' status dicts (``"success"``).
    candidate_ssr, current_ssr : float
        Their sums of squared residuals.
    noise_dof : int
        Samples fitted less parameters: ``current_ssr / noise_dof`` is the noise variance.

    Examples
    --------
    >>> converged_replaces({"success": True}, 6.1873412, {"success": False}, 6.1873396, 1998)
    True
    >>> converged_replaces({"success": True}, 6.19, {"success": False}, 6.18, 1998)
    False
    """
    return bool(candidate["success"]) and not current["success"] \
        and candidate_ssr <= current_ssr * (1.0 + 0.01 / noise_dof)


def crawl_over(candidate: tuple, current_ssr: float, noise_dof: int, ridge: bool) -> bool:
    """Whether IPOPT's stop at its iteration limit was a crawl that Levenberg-Marquardt from the same start finished:
    the latter's fit (``(x, ssr, m, status, shifts)``) converged, and IPOPT ended on a ridge of the structure (a root
    beyond the record: :func:`~synth.ident.fit_failure.roots_beyond_record`) or the fit is within one noise variance
    above IPOPT's ``current_ssr``.

    A structure with one pole too many has its best fit with that pole at infinity: IPOPT crawls along the ridge
    (300 iterations of 20 ms each on 2,000 samples, 200 ms on 8,000: its line search cuts most steps) where
    Levenberg-Marquardt converges in about 20, a little short of IPOPT's SSR (0.1-2 noise variances: the ridge still
    falls). :mod:`synth.ident.timefit` then runs its scaled starts by Levenberg-Marquardt (an identify of a
    second-order structure on a first-order step train of 8,000 samples a cycle: 279 s -> 75 s, the same failure).

    Examples
    --------
    >>> crawl_over((None, 0.022493, 0, {"success": True}, 0), 0.022492, 1997, ridge=False)
    True
    >>> crawl_over((None, 0.0226, 0, {"success": True}, 0), 0.022492, 1997, ridge=False)
    False
    >>> crawl_over((None, 0.0226, 0, {"success": True}, 0), 0.022492, 1997, ridge=True)
    True
    >>> crawl_over((None, 0.022493, 0, {"success": False}, 0), 0.022492, 1997, ridge=True)
    False
    """
    return bool(candidate[3]["success"]) and (ridge or candidate[1] <= current_ssr * (1.0 + 1.0 / noise_dof))
