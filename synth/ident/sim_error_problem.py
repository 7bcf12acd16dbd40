"""The casadi simulation-error problem of :func:`synth.ident.timefit.fit_structure`.

Model
-----
``yhat(t_k) = b + [F(s; theta) H(s) exp(-d s)] (u - u_0)`` sampled at ``t_k``,
with ``F`` the structure (:mod:`synth.ident.structure`), ``H`` an optional
known sensor in series (fit ``F H``, report ``F``), ``d`` the delay and ``b``
an output offset (the pre-step level; a nuisance parameter, so an affine
static map such as a friction offset does not bias the gain). The input is
held between samples (zero-order hold), so the sampled model is exact:
``x_{k+1} = Ad x_k + B_early w_{k-m-1} + B_late w_{k-m}`` with ``d = m dt + f``,
``Ad = e^{A dt}``, ``B_late = G(dt - f)``, ``B_early = e^{A (dt - f)} G(f)`` and
``G(h) = int_0^h e^{A s} ds B`` (the same discretization as
:func:`synth.ident.simulate.simulate_plant`). The matrix exponentials are
written symbolically in casadi (Taylor series with scaling and squaring on a
balanced companion realization), so IPOPT gets exact derivatives in the
parameters *and* in the fractional delay ``f``, which is a bounded variable in
``[0, dt]``. The whole-sample part ``m`` is searched outside (by the fit).

Initial state: at rest (``"steady"``: before the first sample the input was
``u_0``) or periodic (the averaged period of a step train, ``"periodic"``:
``x_0 = (I - Ad^N)^{-1} x_N`` with ``x_N`` the state after one period from
zero, exact for a periodic input).

Cost and solver
---------------
``sum_k (y_k - yhat_k)^2``, minimized by IPOPT with the Gauss-Newton Hessian
``J^T J`` (``J`` the casadi Jacobian of ``yhat``), which is what a
least-squares problem needs and is much cheaper than the exact Hessian
through the recursion.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.linalg import matrix_balance

from synth.errors import ModelError
from synth.ident.structure import Structure
from synth.ident.symbolic_model import companion_form, on_sample, taylor_expm, with_sensor
from synth.plant import Plant

__all__ = ["MIN_HESSIAN_PERTURBATION", "SimulationErrorProblem"]

MIN_HESSIAN_PERTURBATION = 1e-12
"""Smallest multiple of the identity IPOPT adds to the Gauss-Newton Hessian when it is singular (a pole-zero pair
that cancels leaves ``J^T J`` without full rank); IPOPT's own floor is 1e-20. The cost is scaled to about 1 and the
parameters to their start, so the curvature is of order 1 and 1e-12 changes no regular step, but it bounds the
steps along the singular direction: at 1e-20 they were up to 1e12 long and the line search cut each about 88
times before a point was accepted, 65 cost evaluations per iteration. A fit of 4,000 samples from a pair cancelled
in the right half-plane (the pair relocation benchmark's problem 14): 31,951 cost evaluations in 12 solves, 18-22 s,
ending in a failure (an invalid number); now 6,261 in 5 solves, 7-9 s, a fit of 99.18 %. The 83 test files that
identify (747 tests) pass unchanged either way."""

# ---------------------------------------------------------------- realization


def _matpow(M: Any, k: int) -> Any:
    import casadi as ca

    result = ca.MX.eye(M.shape[0])
    base = M
    while k:
        if k & 1:
            result = result @ base
        k >>= 1
        if k:
            base = base @ base
    return result


# ------------------------------------------------------------------ the NLP


class SimulationErrorProblem:
    """The casadi simulation-error problem for fixed data length; the delayed inputs are NLP parameters.

    Parameters
    ----------
    st : Structure
    sensor : Plant or None
        Known sensor ``H`` in series (the model output is ``F H``).
    n : int
        Samples.
    dt : float
        Sample time [s].
    periodic : bool
        Periodic initial state, else at rest.
    theta0 : numpy.ndarray
        Initial parameters (they scale the decision variables).
    fit_delay : bool
        The fractional delay ``f`` is a decision variable (else an NLP parameter).
    y : numpy.ndarray
        Measured output.
    has_d : bool
        The model has a direct feedthrough.
    weights : numpy.ndarray, optional
        Per-sample 0/1 weights of the cost.

    Attributes
    ----------
    scale : numpy.ndarray
        Scaling of the structure's parameters.
    yhat_fn, jac_fn : casadi.Function
        Model output and its Jacobian in the decision variables ``(xi, [f,] b)``.
    solver : casadi.Function
        The IPOPT solver with the Gauss-Newton Hessian.

    Examples
    --------
    >>> from synth.ident.structure import parse_structure
    >>> t = np.arange(0, 1, 0.01); w = np.where(t >= 0.2, 1.0, 0.0)
    >>> prob = SimulationErrorProblem(parse_structure("k/(s+p)"), None, t.size, 0.01, False,
    ...                               np.array([2.0, 3.0]), False, np.zeros(t.size), False)
    >>> x = np.r_[1.0, 1.0, 0.0]  # k = 2, p = 3 (scaled), offset 0
    >>> yhat = np.asarray(prob.yhat_fn(x, prob.inputs(w, 0, 0.0))).ravel()
    >>> round(float(yhat[-1]), 4)  # 2/3 (1 - exp(-3 * 0.79)) at t = 0.99 s
    0.6043
    """

    def __init__(self, st: Structure, sensor: Plant | None, n: int, dt: float, periodic: bool, theta0: np.ndarray,
                 fit_delay: bool, y: np.ndarray, has_d: bool, weights: np.ndarray | None = None) -> None:
        import casadi as ca

        self.n, self.dt, self.periodic = n, dt, periodic
        p = len(st.parameters)
        self.scale = np.where(np.abs(theta0) > 1e-8, np.abs(theta0), 1.0)
        xi = ca.MX.sym("xi", p)
        f = ca.MX.sym("f") if fit_delay else ca.MX.sym("f_fixed")
        b = ca.MX.sym("b")
        W = ca.MX.sym("W", 2, n)
        theta = xi * ca.DM(self.scale)
        num, den = with_sensor(*st.casadi_coefficients(theta), sensor)
        num0, den0 = with_sensor(*[list(c) for c in st.coefficients(theta0)], sensor)
        A0, _, _ = companion_form(num0, den0)
        order = len(den) - 1
        if order == 0:
            raise ModelError(f"structure {st.formula!r}: a static gain needs no dynamic fit")
        A0 = np.asarray(A0, float)
        _, (scl, _) = matrix_balance(A0, permute=False, separate=True)
        Tm, Ti = np.diag(scl), np.diag(1.0 / scl)
        A_l, C_l, D = companion_form(num, den)
        A = ca.vertcat(*[ca.horzcat(*row) for row in A_l])
        C = ca.horzcat(*C_l)
        A = ca.DM(Ti) @ A @ ca.DM(Tm)
        Bv = ca.DM(Ti[:, -1])
        C = C @ ca.DM(Tm)
        Mnum = np.zeros((order + 1, order + 1))
        Mnum[:order, :order] = Ti @ A0 @ Tm
        Mnum[:order, order] = Ti[:, -1]
        norm = float(np.linalg.norm(Mnum * dt, 1))
        squarings = int(max(0, np.ceil(np.log2(max(norm, 1e-12)))) + 4)
        M = ca.vertcat(ca.horzcat(A, Bv), ca.DM.zeros(1, order + 1))
        E_dt = taylor_expm(M * dt, squarings, symbolic="MX")
        E_rest = taylor_expm(M * (dt - f), squarings, symbolic="MX")
        E_f = taylor_expm(M * f, squarings, symbolic="MX")
        Ad = E_dt[:order, :order]
        B_late = E_rest[:order, order]
        B_early = E_rest[:order, :order] @ E_f[:order, order]
        block = max(k for k in range(1, 17) if n % k == 0)  # samples per map step: fewer, larger steps are faster
        x = ca.SX.sym("x", order)
        wk = ca.SX.sym("wk", 2, block)
        Adp, Blp, Bep, Cp = (ca.SX.sym("Ad", order, order), ca.SX.sym("Bl", order), ca.SX.sym("Be", order),
                             ca.SX.sym("C", 1, order))
        Dp = ca.SX.sym("D")
        col = 1 if (fit_delay or has_d) else 0
        xs, outs = x, []
        for j in range(block):
            outs.append(Cp @ xs + Dp * wk[col, j])
            xs = Adp @ xs + Blp * wk[0, j] + Bep * wk[1, j]
        step = ca.Function("step", [x, wk, Adp, Blp, Bep, Cp, Dp], [xs, ca.horzcat(*outs)])
        acc = step.mapaccum("acc", n // block)
        Dm = D if not isinstance(D, float) else ca.MX(D)
        Wb = W  # 2 x n; the map reads it as n/block horizontal blocks of 2 x block
        if periodic:
            Xz, _ = acc(ca.MX.zeros(order), Wb, Ad, B_late, B_early, C, Dm)
            x0 = ca.solve(ca.MX.eye(order) - _matpow(Ad, n), Xz[:, -1])
        else:
            x0 = ca.MX.zeros(order)
        _, Y = acc(x0, Wb, Ad, B_late, B_early, C, Dm)
        yhat = Y.T + b
        dec = ca.vertcat(xi, f, b) if fit_delay else ca.vertcat(xi, b)
        params = ca.vertcat(ca.vec(W), f) if not fit_delay else ca.vec(W)
        self.fit_delay = fit_delay
        self.yhat_fn = ca.Function("yhat", [dec, params], [yhat])
        J = ca.jacobian(yhat, dec)
        self.jac_fn = ca.Function("jacobian", [dec, params], [J])
        s2 = float(np.var(y)) * n or 1.0
        self.obj_scale = s2
        if weights is None:
            r = ca.DM(y) - yhat
            Jw = J
        else:  # samples outside the cost (held out, a start-up transient) weigh 0
            wdm = ca.DM(np.asarray(weights, float))
            r = wdm * (ca.DM(y) - yhat)
            Jw = ca.jacobian(wdm * yhat, dec)
        obj = 0.5 * ca.sumsqr(r) / s2
        lam_f = ca.MX.sym("lam_f")
        lam_g = ca.MX.sym("lam_g", 0)
        H = lam_f * (Jw.T @ Jw) / s2
        hess = ca.Function("nlp_hess_l", [dec, params, lam_f, lam_g], [ca.triu(H)],
                           ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"])
        # calc_lam_p: the multipliers of the parameters (the record's input, thousands of samples) are never read;
        # computing them cost a gradient pass per solve and, after a solve that met NaN, printed casadi's "Failed to
        # calculate multipliers" warning to the user's terminal
        opts = {"print_time": False, "hess_lag": hess, "calc_lam_p": False,
                "show_eval_warnings": False,  # diverging trial points: IPOPT recovers
                "ipopt": {"print_level": 0, "sb": "yes", "tol": 1e-12, "acceptable_tol": 1e-9, "max_iter": 300,
                          "min_hessian_perturbation": MIN_HESSIAN_PERTURBATION}}
        self.solver = ca.nlpsol("timefit", "ipopt", {"x": dec, "p": params, "f": obj}, opts)
        self.p = p

    def inputs(self, w: np.ndarray, m: int, fixed_f: float | None = None) -> np.ndarray:
        """NLP parameters: the input ``w`` delayed by ``m`` and ``m + 1`` samples (and a fixed fraction ``f``)."""
        n = self.n
        if self.periodic:
            late, early = np.roll(w, m), np.roll(w, m + 1)
        else:
            late = np.r_[np.zeros(min(m, n)), w[:max(0, n - m)]]
            early = np.r_[np.zeros(min(m + 1, n)), w[:max(0, n - m - 1)]]
        if fixed_f is not None and on_sample(fixed_f, self.dt):
            # a delay of whole samples: the held input reaches the plant at the sample itself, so a direct
            # feedthrough sees u[k - m] there (the 'early' row feeds only D then: B_early is 0 at f = 0)
            early = late
        vec = np.column_stack([late, early]).ravel()  # column-major vec of the 2 x n matrix
        return vec if fixed_f is None else np.r_[vec, fixed_f]

    def solve(self, x0: np.ndarray, par: np.ndarray, nonnegative_f: bool = False,
              lower: np.ndarray | None = None, within_sample: bool = False) -> tuple[np.ndarray, float, dict[str, Any]]:
        """Solve from ``x0``: the decision variables, the sum of squared residuals and IPOPT's status.
        ``within_sample``: the fractional delay kept in ``[0, dt]`` (the integer part as ``par`` holds it)."""
        lbx = -np.inf * np.ones(x0.size)
        ubx = np.inf * np.ones(x0.size)
        if self.fit_delay and within_sample:
            lbx[self.p], ubx[self.p] = 0.0, self.dt
            x0 = x0.copy()
            x0[self.p] = min(max(x0[self.p], 0.0), self.dt)
        if lower is not None:  # bounds on the structure's parameters (scaled like them)
            p = lower.size
            lbx[:p] = lower / self.scale
            x0 = x0.copy()
            x0[:p] = np.maximum(x0[:p], lbx[:p])
        if self.fit_delay and nonnegative_f:  # no delay below 0 (a predictor)
            lbx[self.p] = 0.0
            x0 = x0.copy()
            x0[self.p] = max(x0[self.p], 0.1 * self.dt)
        sol = self.solver(x0=x0, p=par, lbx=lbx, ubx=ubx)
        stats = self.solver.stats()
        # IPOPT relaxes its bounds by a relative 1e-8 (bound_relax_factor): a delay at its bound of 0 would come back
        # as -1e-8, which no plant accepts
        return (np.clip(np.asarray(sol["x"]).ravel(), lbx, ubx), float(sol["f"]) * 2 * self.obj_scale,
                {"status": stats.get("return_status"), "iterations": int(stats.get("iter_count", 0)),
                 "success": bool(stats.get("success"))})
