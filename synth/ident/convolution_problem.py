"""The simulation-error problem of :func:`synth.ident.timefit.fit_structure` for long records: FFT convolution.

Same model, parameters and cost as :class:`synth.ident.sim_error_problem.SimulationErrorProblem`
(the exact zero-order-hold discretization with a fractional delay, at rest or periodic), evaluated
another way. The casadi problem builds a symbolic recursion over all ``N`` samples and
differentiates it; for 400,000 samples building it alone takes seconds. Here casadi only
differentiates the small discrete matrices ``Ad, B_late, B_early, C, D`` in the parameters, and
the output and its sensitivities come from one linear time-invariant system:

- the state ``[x, dx/dq_1, ..., dx/dq_m]`` (``q`` the scaled parameters and the fractional delay)
  follows ``A_aug = [[Ad, 0], [dAd/dq_i, Ad]]`` (block lower triangular), so its impulse response
  ``C_aug A_aug^(k-1) B_aug`` holds the model's impulse response and its exact derivatives;
- the impulse response is computed in blocks (``C_aug A^(iL)`` times ``A^j B_aug``, one matrix
  product per block) and convolved with the two delayed inputs by FFT: linear convolution for a
  record starting at rest, circular convolution with the periodized response
  ``C (I - A^N)^(-1) A^(k-1) B`` for a periodic one.

The least-squares problem is solved by Levenberg-Marquardt on these exact Jacobians (the
Gauss-Newton Hessian, as in the IPOPT problem), stopped when the remaining Gauss-Newton step is
below ``1e-4`` standard errors (or at machine precision for noise-free data).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.linalg import matrix_balance

from synth.errors import ModelError
from synth.ident.structure import Structure
from synth.ident.symbolic_model import companion_form, on_sample, taylor_expm, with_sensor
from synth.plant import Plant

__all__ = ["ConvolutionProblem"]

_BLOCK = 256  # samples per block of the impulse response
_BUILT_KEEP = 64  # symbolic builds kept for reuse (a few MB)
_BUILT: dict[tuple[Any, ...], tuple[Any, int, int]] = {}
_MAX_ITER = 100
_PROGRESS_WINDOW = 50
_MAX_ITER_PROGRESSING = 1000
"""Beyond :data:`_MAX_ITER` iterations Levenberg-Marquardt goes on while the last :data:`_PROGRESS_WINDOW` lowered
the SSR by more than the noise variance ``SSR/dof`` (a likelihood-meaningful amount), up to this many. A near
pole-zero cancellation's fit crawls along a curved valley: stopped at 100 iterations (case 20, seed 0 of
``benchmarks/ident_crb.py``), it was 48 noise variances of SSR above where it converged at 279, and the
Gauss-Newton step's line search (:func:`synth.ident.timefit._remaining_improvement`) saw none of that, so the
stopped fit was accepted."""


@dataclass(frozen=True)
class _Inputs:
    """The input delayed by ``m`` samples, its spectra by FFT length, and a fixed fraction ``f``."""

    w: np.ndarray
    spectra: dict[int, np.ndarray]
    fixed_f: float | None


class ConvolutionProblem:
    """The simulation-error problem evaluated by FFT convolution and solved by Levenberg-Marquardt.

    Same constructor, attributes (``scale``, ``p``, ``yhat_fn``, ``jac_fn``) and methods
    (``inputs``, ``solve``) as :class:`synth.ident.sim_error_problem.SimulationErrorProblem`,
    which :func:`synth.ident.timefit.fit_structure` uses for short records.

    Examples
    --------
    >>> from synth.ident.structure import parse_structure
    >>> t = np.arange(0, 1, 0.01); w = np.where(t >= 0.2, 1.0, 0.0)
    >>> prob = ConvolutionProblem(parse_structure("k/(s+p)"), None, t.size, 0.01, False,
    ...                           np.array([2.0, 3.0]), False, np.zeros(t.size), False)
    >>> x = np.r_[1.0, 1.0, 0.0]  # k = 2, p = 3 (scaled), offset 0
    >>> yhat = prob.yhat_fn(x, prob.inputs(w, 0, 0.0))
    >>> round(float(yhat[-1]), 4)  # 2/3 (1 - exp(-3 * 0.79)) at t = 0.99 s
    0.6043
    """

    def __init__(self, st: Structure, sensor: Plant | None, n: int, dt: float, periodic: bool, theta0: np.ndarray,
                 fit_delay: bool, y: np.ndarray, has_d: bool, weights: np.ndarray | None = None) -> None:
        self.n, self.dt, self.periodic, self.fit_delay = n, dt, periodic, fit_delay
        self.p = len(st.parameters)
        self.scale = np.where(np.abs(theta0) > 1e-8, np.abs(theta0), 1.0)
        self.y = np.asarray(y, float)
        self.mask = None if weights is None else np.asarray(weights, float) > 0
        self.col = 1 if (fit_delay or has_d) else 0
        theta0 = np.asarray(theta0, float)
        key = (st.formula, tuple(st.parameters), None if sensor is None else (sensor.num.tobytes(), sensor.den.tobytes()),
               float(dt), theta0.tobytes(), bool(fit_delay))
        built = _BUILT.pop(key, None)  # popped and put back: the dict's order is the recency of use
        if built is None:
            built = _build(st, sensor, dt, theta0, self.scale, fit_delay)
        _BUILT[key] = built
        while len(_BUILT) > _BUILT_KEEP:
            del _BUILT[next(iter(_BUILT))]
        self._mats, self.order, self.q = built


    # ------------------------------------------------------------ evaluation

    def inputs(self, w: np.ndarray, m: int, fixed_f: float | None = None) -> _Inputs:
        """The input ``w`` delayed by ``m`` samples (the ``m + 1`` one is the same one sample later), and a fixed ``f``."""
        n = self.n
        late = np.roll(w, m) if self.periodic else np.r_[np.zeros(min(m, n)), w[:max(0, n - m)]]
        return _Inputs(np.asarray(late, float), {}, fixed_f)

    def _spectrum(self, par: _Inputs, nfft: int) -> np.ndarray:
        from scipy.fft import rfft

        if nfft not in par.spectra:
            par.spectra.clear()
            par.spectra[nfft] = rfft(par.w, nfft)
        return par.spectra[nfft]

    def _system(self, dec: np.ndarray, par: _Inputs, derivatives: bool) -> tuple[np.ndarray, ...]:
        o, p = self.order, self.p
        f = float(dec[p]) if self.fit_delay else float(par.fixed_f or 0.0)
        mats, jac = self._mats(dec[:p], f)
        mats = np.asarray(mats).ravel()
        cuts = np.cumsum([o * o, o, o, o])
        Ad, Bl, Be, C, D = np.split(mats, cuts)
        Ad = Ad.reshape(o, o, order="F")
        B = np.column_stack([Bl, Be])
        if not derivatives:
            return Ad, B, C[None, :], D
        jac = np.asarray(jac)
        q, s = self.q, o * (self.q + 1)
        A_aug = np.zeros((s, s))
        B_aug = np.zeros((s, 2))
        C_aug = np.zeros((q + 1, s))
        D_aug = np.zeros(q + 1)
        A_aug[:o, :o], B_aug[:o], C_aug[0, :o], D_aug[0] = Ad, B, C, D[0]
        for i in range(q):
            dAd, dBl, dBe, dC, dD = np.split(jac[:, i], cuts)
            blk = slice(o * (i + 1), o * (i + 2))
            A_aug[blk, :o] = dAd.reshape(o, o, order="F")
            A_aug[blk, blk] = Ad
            B_aug[blk] = np.column_stack([dBl, dBe])
            C_aug[i + 1, :o] = dC
            C_aug[i + 1, blk] = C
            D_aug[i + 1] = dD[0]
        return A_aug, B_aug, C_aug, D_aug

    def _impulse(self, A: np.ndarray, B: np.ndarray, C: np.ndarray, length: int) -> np.ndarray:
        """``C A^k B`` for ``k = 0 .. length - 1`` (shape: rows, 2, length), cut where every row has decayed to 0
        in double precision (below ``1e-17`` of its largest value, over a whole block)."""
        s = A.shape[0]
        blk = min(_BLOCK, length)
        # [B, A B, ..., A^(blk-1) B] by doubling: [U, A^k U] doubles a block of k columns (log2(blk) products
        # instead of blk, each of which also advanced A^k one step)
        U, P = B[:, None, :], A  # (s, k, 2) and A^k
        while U.shape[1] < blk:
            U = np.concatenate([U, np.einsum("ij,jkl->ikl", P, U)], axis=1)
            P = P @ P
        P = np.linalg.matrix_power(A, blk) if U.shape[1] != blk else P
        U = U[:, :blk].reshape(s, 2 * blk)
        blocks, peak, g = [], np.zeros(C.shape[0]), C
        for _ in range(-(-length // blk)):
            R = g @ U  # rows x (blk * 2)
            size = np.max(np.abs(R), axis=1)
            if not np.all(np.isfinite(size)):
                return np.full((C.shape[0], 2, length), np.nan)
            peak = np.maximum(peak, size)
            blocks.append(R)
            if np.all(size <= 1e-17 * peak):
                break
            g = g @ P
        R = np.concatenate(blocks, axis=1).reshape(C.shape[0], -1, 2).transpose(0, 2, 1)
        return R[:, :, :length]

    def _outputs(self, dec: np.ndarray, par: _Inputs, derivatives: bool) -> np.ndarray:
        """Rows: the model output without the offset, then its derivatives in the scaled parameters (and ``f``)."""
        from scipy.fft import irfft, next_fast_len, rfft

        cached = getattr(self, "_last", None)  # the solver's last point: the fit asks for it again
        if cached is not None and cached[1] is par and np.array_equal(cached[0], dec):
            return cached[2] if derivatives else cached[2][:1]
        A, B, C, D = self._system(dec, par, derivatives)
        n = self.n
        with np.errstate(all="ignore"):
            if self.periodic:
                An = np.linalg.matrix_power(A, n)
                try:
                    Cp = np.linalg.solve((np.eye(A.shape[0]) - An).T, C.T).T
                except np.linalg.LinAlgError:
                    return np.full((C.shape[0], n), np.nan)
                R = self._impulse(A, B, Cp, n)
                R = np.concatenate([R, np.zeros((R.shape[0], 2, n - R.shape[2]))], axis=2)
                h2 = np.concatenate([R[:, :, -1:], R[:, :, :-1]], axis=2)  # Cp A^(k-1) B, k = 1 .. n (n -> 0)
            else:
                h2 = np.concatenate([np.zeros((C.shape[0], 2, 1)), self._impulse(A, B, C, n - 1)], axis=2)
            # the early input is the late one delayed by a sample: one response on the late input
            h = h2[:, 0].copy()
            h[:, 1:] += h2[:, 1, :-1]
            if self.periodic:
                h[:, 0] += h2[:, 1, -1]
            # a delay of whole samples: a direct feedthrough sees the held input at the sample itself
            h[:, 0 if not self.fit_delay and on_sample(par.fixed_f or 0.0, self.dt) else self.col] += D
            if not np.all(np.isfinite(h)):
                return np.full((C.shape[0], n), np.nan)
            nfft = n if self.periodic else next_fast_len(n + h.shape[1] - 1, real=True)
            Y = irfft(rfft(h, nfft, axis=1) * self._spectrum(par, nfft)[None, :], nfft, axis=1)[:, :n]
        if derivatives:
            self._last = (np.array(dec, float), par, Y)
        return Y

    def yhat_fn(self, dec: np.ndarray, par: _Inputs) -> np.ndarray:
        """Model output at the decision variables ``(xi, [f,] b)``."""
        dec = np.asarray(dec, float).ravel()
        return self._outputs(dec, par, False)[0] + dec[-1]

    def jac_fn(self, dec: np.ndarray, par: _Inputs) -> np.ndarray:
        """Jacobian of the model output in the decision variables: N x (p [+ 1] + 1)."""
        dec = np.asarray(dec, float).ravel()
        Y = self._outputs(dec, par, True)
        return np.column_stack([Y[1:].T, np.ones(self.n)])

    def _residual(self, dec: np.ndarray, par: _Inputs, jac: bool) -> tuple[np.ndarray, np.ndarray | None]:
        Y = self._outputs(dec, par, jac)
        r = self.y - Y[0] - dec[-1]
        J = np.column_stack([Y[1:].T, np.ones(self.n)]) if jac else None
        if self.mask is not None:
            r = r[self.mask]
            J = J[self.mask] if J is not None else None
        return r, J

    # --------------------------------------------------------------- solving

    def solve(self, x0: np.ndarray, par: _Inputs, nonnegative_f: bool = False,
              lower: np.ndarray | None = None, rtol: float = 0.0,
              within_sample: bool = False) -> tuple[np.ndarray, float, dict[str, Any]]:
        """Levenberg-Marquardt from ``x0``: the decision variables, the sum of squared residuals and a status.

        Converged when the Gauss-Newton decrease of the SSR still available is below ``1e-8`` of the noise
        variance ``SSR/dof``, or below ``rtol`` times the SSR (a caller that iterates fits to a looser tolerance
        of its own). The status strings are IPOPT's (``Solve_Succeeded``, ``Maximum_Iterations_Exceeded``,
        ``Diverging_Iterates``), so :func:`synth.ident.fit_failure.fit_failure` reads them alike. A variable at a
        bound (``lower``, the delay's fraction) that the gradient pushes further out is held there: the step and the
        convergence test are taken in the others, and a step is clipped at the bounds.
        """
        lb, ub = -np.inf * np.ones(x0.size), np.inf * np.ones(x0.size)
        if lower is not None:
            lb[:lower.size] = lower / self.scale
        if self.fit_delay and within_sample:  # the fractional delay kept in [0, dt]
            lb[self.p], ub[self.p] = 0.0, self.dt
        x = np.clip(np.asarray(x0, float).copy(), lb, ub)
        if self.fit_delay and nonnegative_f:
            lb[self.p] = 0.0
            x[self.p] = max(x[self.p], 0.1 * self.dt)
        r, J = self._residual(x, par, True)
        ssr = float(r @ r)
        if not np.isfinite(ssr):
            return x, float("inf"), {"status": "Diverging_Iterates", "iterations": 0, "success": False}
        lam, status, it = 1e-3, "Maximum_Iterations_Exceeded", 0
        dof = max(1, r.size - x.size)
        history = [ssr]
        while it < _MAX_ITER or (it < _MAX_ITER_PROGRESSING
                                 and history[-_PROGRESS_WINDOW - 1] - ssr > ssr / dof):
            it += 1
            g, H = J.T @ r, J.T @ J
            # a variable at a bound that the SSR pushes further out stays there: the step is taken in the others
            # (a clipped full step moved them to make up for a move the bound then refused, and crawled)
            free = ~(((x <= lb) & (g < 0)) | ((x >= ub) & (g > 0)))
            g_free, H_free = g[free], H[np.ix_(free, free)]
            d = np.maximum(np.diag(H_free), 1e-300)
            try:
                gn = np.linalg.lstsq(H_free, g_free, rcond=None)[0]
            except np.linalg.LinAlgError:
                gn = np.zeros_like(g_free)
            remaining = float(g_free @ gn)  # the Gauss-Newton decrease of the SSR still available
            if remaining <= 1e-8 * ssr / dof or remaining <= max(1e-15, rtol) * ssr:
                status = "Solve_Succeeded"
                break
            accepted = False
            step = np.zeros_like(x)
            while lam < 1e12:
                step[free] = np.linalg.solve(H_free + lam * np.diag(d), g_free)
                trial = np.clip(x + step, lb, ub)
                r_new = self._residual(trial, par, False)[0]
                with np.errstate(all="ignore"):
                    ssr_new = float(r_new @ r_new)
                if np.isfinite(ssr_new) and ssr_new < ssr:
                    r, J = self._residual(trial, par, True)
                    x, ssr, accepted = trial, float(r @ r), True
                    lam = max(lam / 5.0, 1e-12)
                    break
                lam *= 4.0
            history.append(ssr)
            if not accepted:  # no decrease along any damped step: at the optimum to machine precision
                status = "Solve_Succeeded"
                break
        return x, ssr, {"status": status, "iterations": it, "success": status == "Solve_Succeeded"}


def _build(st: Structure, sensor: Plant | None, dt: float, theta0: np.ndarray, scale: np.ndarray,
           fit_delay: bool) -> tuple[Any, int, int]:
    """The casadi function of the discrete matrices and their Jacobian, the model's order and the number of ``q``.

    Built in scaled parameters ``xi = theta / scale`` with the state balanced at ``theta0``: a function of the
    structure, the sensor, ``dt``, ``theta0`` and whether the delay is fitted alone, so a fit started where an
    earlier one was (a re-fit's every grid point starts at the nominal coefficients) reuses the earlier one's.
    """
    import casadi as ca

    p = len(st.parameters)
    xi, f = ca.SX.sym("xi", p), ca.SX.sym("f")
    num, den = with_sensor(*st.casadi_coefficients(xi * ca.DM(scale)), sensor)
    num0, den0 = with_sensor(*[list(c) for c in st.coefficients(theta0)], sensor)
    order = len(den) - 1
    if order == 0:
        raise ModelError(f"structure {st.formula!r}: a static gain needs no dynamic fit")
    A0 = np.asarray(companion_form(num0, den0)[0], float)
    _, (scl, _) = matrix_balance(A0, permute=False, separate=True)
    Tm, Ti = np.diag(scl), np.diag(1.0 / scl)
    A_l, C_l, D = companion_form(num, den)
    A = ca.DM(Ti) @ ca.vertcat(*[ca.horzcat(*row) for row in A_l]) @ ca.DM(Tm)
    C = ca.horzcat(*C_l) @ ca.DM(Tm)
    Mnum = np.zeros((order + 1, order + 1))
    Mnum[:order, :order] = Ti @ A0 @ Tm
    Mnum[:order, order] = Ti[:, -1]
    squarings = int(max(0, np.ceil(np.log2(max(float(np.linalg.norm(Mnum * dt, 1)), 1e-12)))) + 4)
    M = ca.vertcat(ca.horzcat(A, ca.DM(Ti[:, -1])), ca.SX.zeros(1, order + 1))
    E_dt, E_rest, E_f = (taylor_expm(M * step, squarings, symbolic="SX") for step in (dt, dt - f, f))
    B_late = E_rest[:order, order]
    B_early = E_rest[:order, :order] @ E_f[:order, order]
    mats = ca.vertcat(ca.vec(E_dt[:order, :order]), B_late, B_early, ca.vec(C), D)
    q = ca.vertcat(xi, f) if fit_delay else xi
    return ca.Function("mats", [xi, f], [mats, ca.jacobian(mats, q)]), order, int(q.numel())
