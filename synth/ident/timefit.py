"""Simulation-error fit of a parametric structure to a sampled record, with casadi (IPOPT).

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
``[0, dt]``. The whole-sample part ``m`` is searched outside: if ``f`` ends on
a bound, ``m`` moves by one sample and the fit is repeated (at ``f = dt`` the
models for ``m`` and ``m + 1`` coincide, so the cost is continuous in ``d``).

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

Deterministic initialization
----------------------------
1. A linear continuous-time model of the structure's orders is fitted by the
   simplified refined instrumental-variable method (SRIVC: the
   Sanathanan-Koerner / Steiglitz-McBride iteration with the prefilter
   ``1/A(s)`` and instruments from the simulated noise-free output), first
   with the state-variable filter ``1/(s + lambda)^n`` for a few ``lambda``,
   then on a grid of delays up to the first visible response.
2. That model is mapped onto the structure's parameters by a least-squares
   fit of the frequency responses (relative error on a log grid around its
   poles and zeros), from a fixed list of starting points.
3. IPOPT starts there. Only if it fails, or ends worse than the initial
   model, a fixed list of other starts is tried (multistart as a fallback).

Uncertainty
-----------
``cov = s^2 (J^T J)^{-1}`` with ``s^2 = SSR/(N - p)`` and ``J`` the Jacobian
of ``yhat`` in the parameters (delay and offset included); standard errors are
the square roots of its diagonal and the 95 % intervals ``theta +- t_{0.975,
N-p} std``. This assumes white noise. With coloured noise (drift, a
disturbance spectrum, or a model error) the residuals are correlated and these
standard errors are too small; averaging a step train and checking the
residual plot helps.

``fit_percent = 100 (1 - ||y - yhat|| / ||y - mean(y)||)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.linalg import matrix_balance
from scipy.optimize import least_squares
from scipy.stats import t as student_t

from synth.data.record import Record
from synth.errors import DataError, ModelError
from synth.ident.steps import StepAverage, average_steps, find_steps
from synth.ident.structure import Structure, parse_structure
from synth.plant import Plant

# ---------------------------------------------------------------- realization


def _companion(num: list[Any], den: list[Any]) -> tuple[list[list[Any]], list[Any], Any]:
    """Controllable canonical ``A`` (nested lists), ``C`` and ``D`` of ``num/den`` (any numeric type)."""
    n = len(den) - 1
    lead = den[0]
    a = [d / lead for d in den[1:]]
    b = [0.0] * (n + 1 - len(num)) + [c / lead for c in num]
    D = b[0]
    r = [b[i + 1] - D * a[i] for i in range(n)]
    A = [[0.0] * n for _ in range(n)]
    for i in range(n - 1):
        A[i][i + 1] = 1.0
    for j in range(n):
        A[n - 1][j] = -a[n - 1 - j]
    C = [r[n - 1 - j] for j in range(n)]
    return A, C, D


def _expm(M: Any, squarings: int, order: int = 12) -> Any:
    import casadi as ca

    n = M.shape[0]
    X = M / float(2**squarings)
    E = ca.MX.eye(n)
    for k in range(order, 0, -1):
        E = ca.MX.eye(n) + (X @ E) / k
    for _ in range(squarings):
        E = E @ E
    return E


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


def _series(num: list[Any], den: list[Any], sensor: Plant | None) -> tuple[list[Any], list[Any]]:
    if sensor is None:
        return list(num), list(den)

    def mul(p: list[Any], q: np.ndarray) -> list[Any]:
        out: list[Any] = [0.0] * (len(p) + q.size - 1)
        for i, x in enumerate(p):
            for j, y in enumerate(q):
                out[i + j] = out[i + j] + x * float(y)
        return out

    return mul(list(num), sensor.num), mul(list(den), sensor.den)


# ------------------------------------------------------------------- results


@dataclass(frozen=True, eq=False)
class TimeFitResult:
    """A fitted structure with its uncertainty.

    Attributes
    ----------
    structure : Structure
    parameters : dict
        Fitted values named as in the formula, plus the delay (under the
        formula's delay name, else ``"delay"``).
    std, ci95 : dict
        Standard errors and 95 % confidence intervals, same keys (a fixed delay has std 0).
    names : list of str
        Order of the rows and columns of ``covariance`` (parameters, delay if
        fitted, then ``"offset"``).
    covariance : numpy.ndarray
    delay : float
        Delay [s].
    delay_fitted : bool
    offset, offset_std : float
        Output level ``b`` at the reference input ``u_0`` and its standard error.
    fit_percent : float
    residual_std : float
        ``sqrt(SSR / (N - p))``.
    plant : Plant
        The fitted ``F`` with its delay.
    sensor : Plant or None
        The known sensor ``H``.
    measured : Plant
        ``F H`` with the delay: what the record's output responds with.
    initial : dict
        The deterministic initial values handed to IPOPT.
    solver : dict
        IPOPT status, iterations, starts tried, delay shifts.
    t, y, yhat : numpy.ndarray
        The fitted data and the model output (for figures; not in ``to_dict``).
    periodic : bool
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

    @property
    def residuals(self) -> np.ndarray:
        """``y - yhat``."""
        return self.y - self.yhat

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
        }


# ------------------------------------------------------------ initialization


def _expm_np(M: np.ndarray) -> np.ndarray:
    """Matrix exponential of a small matrix (Taylor series, scaling and squaring).

    Used instead of :func:`scipy.linalg.expm` on the hot paths: for 2x2 to 6x6
    matrices scipy's BLAS calls can cost milliseconds each when the machine is
    busy (thread start-up), this costs microseconds.
    """
    norm = float(np.max(np.sum(np.abs(M), axis=0))) if M.size else 0.0
    k = max(0, int(np.ceil(np.log2(norm))) + 2) if norm > 0 else 0
    X = M / 2.0**k
    E = np.eye(M.shape[0])
    for j in range(16, 0, -1):
        E = np.eye(M.shape[0]) + (X @ E) / j
    for _ in range(k):
        E = E @ E
    return E


def _delayed_zoh(A: np.ndarray, B: np.ndarray, dt: float, delay: float) -> Any:
    """:func:`synth.sim.discretize.delayed_zoh` with :func:`_expm_np`."""
    from synth.sim.discretize import DelayedZOH

    n = A.shape[0]

    def zoh(h: float) -> tuple[np.ndarray, np.ndarray]:
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n] = A * h, B * h
        E = _expm_np(M)
        return E[:n, :n], E[:n, n]

    steps = int(np.floor(delay / dt + 1e-9))
    fraction = delay - steps * dt
    Ad, G = zoh(dt)
    if fraction < 1e-9 * dt:
        return DelayedZOH(Ad, np.zeros(n), G, steps, 0.0)
    A_rest, G_late = zoh(dt - fraction)
    _, G_f = zoh(fraction)
    return DelayedZOH(Ad, A_rest @ G_f, G_late, steps, fraction)


def _filter_bank(den: np.ndarray, dt: float, x: np.ndarray, count: int, delay: float = 0.0) -> list[np.ndarray]:
    """``s^k / den(s)`` applied to the held samples ``x`` (delayed), ``k = 0 .. count - 1``, zero initial state.

    One exact ZOH discretization of the companion form of ``1/den`` serves every ``k``
    (its states are ``s^k/den x``); ``k = deg(den)`` follows from ``den`` itself.
    """
    from scipy.signal import lfilter, ss2tf

    den = np.asarray(den, float) / den[0]
    n = den.size - 1
    A = np.zeros((n, n))
    A[:-1, 1:] = np.eye(n - 1)
    A[-1, :] = -den[1:][::-1]
    B = np.zeros(n)
    B[-1] = 1.0
    z = _delayed_zoh(A, B, dt, delay)

    def shift(v: np.ndarray, k: int) -> np.ndarray:
        out = np.zeros_like(v)
        if k < v.size:
            out[k:] = v[:v.size - k]
        return out

    late, early = shift(x, z.steps), shift(x, z.steps + 1)
    out = []
    for k in range(min(count, n)):
        C = np.zeros((1, n))
        C[0, k] = 1.0
        y = np.zeros_like(x)
        for Bk, xin in ((z.B_late, late), (z.B_early, early)):
            if np.any(Bk):
                num, dd = ss2tf(z.Ad, Bk[:, None], C, np.zeros((1, 1)))
                y = y + lfilter(num[0], dd, xin)
        out.append(y)
    if count > n:
        direct = shift(x, z.steps + (1 if z.fraction > 0 else 0))
        out.append(direct - sum(den[n - k] * out[k] for k in range(n)))
    return out


def _bank(den: np.ndarray, t: np.ndarray, x: np.ndarray, count: int, delay: float, periodic: bool,
          reps: int) -> list[np.ndarray]:
    dt = float(t[1] - t[0])
    if not periodic:
        return _filter_bank(den, dt, x, count, delay)
    n = x.size
    return [v[-n:] for v in _filter_bank(den, dt, np.tile(x, reps), count, delay)]


def _tile_filter(plant: Plant, t: np.ndarray, x: np.ndarray, periodic: bool, reps: int) -> np.ndarray:
    """``plant`` applied to ``x`` from zero state (or its periodic response), through :func:`_filter_bank`."""
    num = plant.num[::-1]
    bank = _bank(plant.den, t, x, num.size, plant.delay, periodic, reps)
    return sum(c * b for c, b in zip(num, bank))


def _reps(den: np.ndarray, duration: float) -> int:
    """Periods to simulate so the transient of ``1/den`` has decayed below 1e-6."""
    slowest = float(np.min(np.abs(np.real(np.roots(den))))) if den.size > 1 else 1e9
    if slowest <= 0:
        return 10
    return int(min(20, max(2, np.ceil(14.0 / (slowest * duration)) + 1)))


def _stable(den: np.ndarray) -> np.ndarray:
    roots = np.roots(den)
    if roots.size == 0:
        return den
    roots = np.where(roots.real > 0, -roots.real + 1j * roots.imag, roots)
    roots = np.where(np.abs(roots.real) < 1e-9, roots - 1e-6, roots)
    return np.real(np.poly(roots)) * den[0]


def _srivc(t: np.ndarray, v: np.ndarray, y: np.ndarray, na: int, nb: int, delay: float, lam: float,
           periodic: bool, iterations: int = 8) -> tuple[np.ndarray, np.ndarray, float]:
    """SRIVC estimate of ``B(s)/A(s) exp(-delay s)`` from ``v`` to ``y`` (deviation signals)."""
    duration = t[-1] - t[0] + (t[1] - t[0])
    den = np.poly(-lam * np.ones(na)) if na else np.array([1.0])
    num = None
    for it in range(iterations + 1):
        reps = _reps(den, duration) if periodic else 1
        yf = _bank(den, t, y, na + 1, 0.0, periodic, reps)
        vf = _bank(den, t, v, nb + 1, delay, periodic, reps)
        phi = np.column_stack([-yf[k] for k in range(na)] + vf)
        if num is None:
            zeta = phi
        else:
            xhat = _tile_filter(Plant(num, den, delay), t, v, periodic, reps)
            xf = _bank(den, t, xhat, na, 0.0, periodic, reps)
            zeta = np.column_stack([-xf[k] for k in range(na)] + vf)
        try:
            est = np.linalg.solve(zeta.T @ phi, zeta.T @ yf[na])
        except np.linalg.LinAlgError:
            est = np.linalg.lstsq(phi, yf[na], rcond=None)[0]
        a = est[:na][::-1]
        new_den = _stable(np.r_[1.0, a]) if na else np.array([1.0])
        new_num = est[na:][::-1]
        converged = num is not None and np.allclose(new_den, den, rtol=1e-7) and np.allclose(new_num, num, rtol=1e-7)
        den, num = new_den, new_num
        if converged and it > 0:
            break
    reps = _reps(den, duration) if periodic else 1
    sim = _tile_filter(Plant(num, den, delay), t, v, periodic, reps)
    return num, den, float(np.sum((y - sim) ** 2))


def _first_response(t: np.ndarray, w: np.ndarray, y: np.ndarray) -> float:
    """Time from the first input change to the first output change above the noise."""
    k0 = int(np.flatnonzero(np.abs(np.diff(w)) > 0)[0]) + 1 if np.any(np.diff(w)) else 0
    sigma = float(np.std(np.diff(y)) / np.sqrt(2.0)) + 1e-12 * (np.ptp(y) + 1.0)
    base = float(np.mean(y[max(0, k0 - 20):k0 + 1]))
    after = np.flatnonzero(np.abs(y[k0:] - base) > max(5 * sigma, 0.05 * np.ptp(y)))
    return float(after[0] * (t[1] - t[0])) if after.size else 0.1 * float(t[-1] - t[0])


def _linear_init(t: np.ndarray, w: np.ndarray, yd: np.ndarray, st: Structure, sensor: Plant | None, periodic: bool,
                 delay: float | None) -> tuple[np.ndarray, np.ndarray, float]:
    """Deterministic linear model (num, den of F) and delay from SRIVC on a delay grid."""
    dt = t[1] - t[0]
    duration = t[-1] - t[0] + dt
    reps = _reps(sensor.den, duration) if (periodic and sensor is not None) else 1
    v = _tile_filter(sensor.with_delay(0.0), t, w, periodic, reps) if sensor is not None else w
    na, nb = st.den_degree, st.num_degree
    if delay is None:
        d_vis = max(_first_response(t, w, yd), 2 * dt)
        grid = np.linspace(0.0, d_vis, 9)
    else:
        grid = np.array([delay])
    lams = np.geomspace(20.0 / duration, 0.05 / dt, 5)
    mid = grid[len(grid) // 2]
    best_lam = min(lams, key=lambda lam: _srivc(t, v, yd, na, nb, mid, lam, periodic, 4)[2])
    fits = [(_srivc(t, v, yd, na, nb, d, best_lam, periodic), d) for d in grid]
    (num, den, ssr), d0 = min(fits, key=lambda f: f[0][2])
    if grid.size > 1:  # refine the delay between the neighbouring grid points
        from scipy.optimize import minimize_scalar

        step = grid[1] - grid[0]
        sol = minimize_scalar(lambda d: _srivc(t, v, yd, na, nb, d, best_lam, periodic, 4)[2],
                              bounds=(max(0.0, d0 - step), d0 + step), method="bounded",
                              options={"xatol": 0.1 * dt})
        if sol.fun < ssr:
            d0 = float(sol.x)
            num, den, _ = _srivc(t, v, yd, na, nb, d0, best_lam, periodic)
    return num, den, float(d0)


def _map_to_structure(st: Structure, num: np.ndarray, den: np.ndarray) -> np.ndarray:
    """Structure parameters whose frequency response best matches ``num/den`` (relative error)."""
    roots = np.r_[np.roots(den), np.roots(num) if num.size > 1 else []]
    mags = np.abs(roots[np.abs(roots) > 1e-9])
    lo, hi = (float(mags.min()) / 10, float(mags.max()) * 10) if mags.size else (0.01, 100.0)
    w = np.geomspace(lo, hi, 80)
    s = 1j * w
    target = np.polyval(num, s) / np.polyval(den, s)
    weight = 1.0 / np.maximum(np.abs(target), 1e-300)

    def resid(theta: np.ndarray) -> np.ndarray:
        n_, d_ = st.coefficients(theta)
        with np.errstate(all="ignore"):
            g = np.polyval(n_, s) / np.polyval(d_, s)
        r = (g - target) * weight
        r = np.r_[r.real, r.imag]
        return np.where(np.isfinite(r), r, 1e6)

    num_t = np.r_[np.zeros(st.num_degree + 1 - num.size), num] / den[0]
    den_t = den / den[0]
    target_c = np.r_[num_t, den_t]
    cscale = np.maximum(np.abs(target_c), 1e-9 * np.max(np.abs(target_c)))

    def resid_coef(theta: np.ndarray) -> np.ndarray:
        n_, d_ = st.coefficients(theta)
        with np.errstate(all="ignore"):
            r = (np.r_[n_, d_] / d_[0] - target_c) / cscale
        return np.where(np.isfinite(r), r, 1e6)

    p = len(st.parameters)
    best: tuple[float, np.ndarray] | None = None
    for c in (1.0, 0.1, 10.0, 0.01, 100.0, 1000.0):
        x0 = c * (1.0 + 0.15 * np.arange(p))
        try:  # coefficient matching first (polynomial equations, few local minima), then the frequency fit
            sol = least_squares(resid_coef, x0, method="lm", max_nfev=400 * (p + 1))
            sol = least_squares(resid, sol.x, method="lm", max_nfev=400 * (p + 1))
        except (ValueError, np.linalg.LinAlgError):
            continue
        cost = float(np.sum(sol.fun**2))
        if best is None or cost < best[0]:
            best = (cost, sol.x)
        if cost < 1e-16 * w.size:
            break
    if best is None:
        raise ModelError(f"structure {st.formula!r}: could not map an initial linear model onto its parameters")
    return best[1]


# ------------------------------------------------------------------ the NLP


class _Problem:
    """The casadi simulation-error problem for fixed data length; the delayed inputs are NLP parameters."""

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
        num, den = _series(*st.casadi_coefficients(theta), sensor)
        num0, den0 = _series(*[list(c) for c in st.coefficients(theta0)], sensor)
        A0, _, _ = _companion(num0, den0)
        order = len(den) - 1
        if order == 0:
            raise ModelError(f"structure {st.formula!r}: a static gain needs no dynamic fit")
        A0 = np.asarray(A0, float)
        _, (scl, _) = matrix_balance(A0, permute=False, separate=True)
        Tm, Ti = np.diag(scl), np.diag(1.0 / scl)
        A_l, C_l, D = _companion(num, den)
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
        E_dt = _expm(M * dt, squarings)
        E_rest = _expm(M * (dt - f), squarings)
        E_f = _expm(M * f, squarings)
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
        opts = {"print_time": False, "hess_lag": hess, "show_eval_warnings": False,  # diverging trial points: IPOPT recovers
                "ipopt": {"print_level": 0, "sb": "yes", "tol": 1e-12, "acceptable_tol": 1e-9, "max_iter": 300}}
        self.solver = ca.nlpsol("timefit", "ipopt", {"x": dec, "p": params, "f": obj}, opts)
        self.p = p

    def inputs(self, w: np.ndarray, m: int, fixed_f: float | None = None) -> np.ndarray:
        n = self.n
        if self.periodic:
            late, early = np.roll(w, m), np.roll(w, m + 1)
        else:
            late = np.r_[np.zeros(min(m, n)), w[:max(0, n - m)]]
            early = np.r_[np.zeros(min(m + 1, n)), w[:max(0, n - m - 1)]]
        vec = np.column_stack([late, early]).ravel()  # column-major vec of the 2 x n matrix
        return vec if fixed_f is None else np.r_[vec, fixed_f]

    def solve(self, x0: np.ndarray, par: np.ndarray, nonnegative_f: bool = False,
              lower: np.ndarray | None = None) -> tuple[np.ndarray, float, dict[str, Any]]:
        lbx = -np.inf * np.ones(x0.size)
        if lower is not None:  # bounds on the structure's parameters (scaled like them)
            p = lower.size
            lbx[:p] = lower / self.scale
            x0 = x0.copy()
            x0[:p] = np.maximum(x0[:p], lbx[:p])
        if self.fit_delay and nonnegative_f:  # no delay below 0 (a predictor)
            lbx[self.p] = 0.0
            x0 = x0.copy()
            x0[self.p] = max(x0[self.p], 0.1 * self.dt)
        sol = self.solver(x0=x0, p=par, lbx=lbx)
        stats = self.solver.stats()
        return (np.asarray(sol["x"]).ravel(), float(sol["f"]) * 2 * self.obj_scale,
                {"status": stats.get("return_status"), "iterations": int(stats.get("iter_count", 0)),
                 "success": bool(stats.get("success"))})


# ----------------------------------------------------------------- interface


def _resolve_delay(st: Structure, delay: str | float | None) -> tuple[bool, float | None, str]:
    name = st.delay_parameter or "delay"
    if isinstance(st.delay, float):
        if delay is not None:
            raise ModelError(f"structure {st.formula!r} fixes the delay at {st.delay:g} s; do not give a delay too")
        return False, st.delay, name
    if delay is None:
        return (True, None, name) if st.delay_parameter else (False, 0.0, name)
    if isinstance(delay, str):
        if delay.strip().lower() == "fit":
            return True, None, name
        try:
            delay = float(delay)
        except ValueError:
            raise ModelError(f"delay must be 'fit' or a number of seconds, got {delay!r}") from None
    if not np.isfinite(delay) or delay < 0:
        raise ModelError(f"delay must be 'fit' or a number >= 0 s, got {delay!r}")
    return False, float(delay), name


def _as_sensor(sensor: Plant | str | None) -> Plant | None:
    if sensor is None or isinstance(sensor, Plant):
        return sensor
    try:
        return Plant.from_string(sensor)
    except ModelError as exc:
        raise exc.located("sensor") from None


def fit_structure(record: Record, structure: Structure | str, delay: str | float | None = None,
                  sensor: Plant | str | None = None, periodic: bool = False,
                  initial: dict[str, float] | None = None,
                  lower: dict[str, float] | None = None,
                  weights: np.ndarray | None = None) -> TimeFitResult:
    """Fit a structure to a record by simulation error (casadi + IPOPT).

    Parameters
    ----------
    record : Record
        Uniformly sampled input and output (for a step train, the averaged
        period from :func:`synth.ident.steps.average_steps`).
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
        Starting values (structure names, optionally ``delay``) instead of the
        deterministic initialization.
    lower : dict, optional
        Lower bounds of structure parameters (e.g. ``{"p": 0.0}`` keeps a pole in the
        left half-plane); the others are free.
    weights : numpy.ndarray, optional
        Per-sample 0/1 weights of the cost (0: simulated but not fitted, e.g. held-out
        segments or a start-up transient from an unknown initial state); the residual
        statistics use the weighted samples only.

    Returns
    -------
    TimeFitResult

    Raises
    ------
    ModelError
        Bad structure, sensor or delay option.
    DataError
        Fewer samples than parameters, or a periodic fit of a model with an integrator.

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
    sensor = _as_sensor(sensor)
    fit_delay, fixed_delay, delay_name = _resolve_delay(st, delay)
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
    if initial is None:
        lin_num, lin_den, d0 = _linear_init(t, wd, yd, st, sensor, periodic, None if fit_delay else fixed_delay)
        theta0 = _map_to_structure(st, lin_num, lin_den)
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
        raise DataError("a periodic fit needs a model without an integrator (its periodic state is not unique)")
    has_d = (st.num_degree == st.den_degree) and sensor is None
    mask = None
    if weights is not None:
        weights = np.asarray(weights, float)
        if weights.shape != (n,) or not np.all((weights == 0) | (weights == 1)):
            raise ModelError(f"weights must be {n} values of 0 or 1", where="weights")
        mask = weights > 0
        if int(mask.sum()) <= p_total + 1:
            raise DataError(f"{int(mask.sum())} weighted samples cannot determine {p_total} parameters",
                            where=record.source)
    prob = _Problem(st, sensor, n, dt, periodic, theta0, fit_delay, y, has_d, weights)
    b0 = y_ref if not periodic else y_ref - float(Plant(num_chk, den_chk).dc_gain()) * w_mean * (
        sensor.dc_gain() if sensor is not None else 1.0)
    initial_out = {**dict(zip(st.parameters, theta0.tolist())), delay_name: d0}
    unknown = sorted(set(lower or {}) - set(st.parameters))
    if unknown:
        raise ModelError(f"bounds for parameters not in the structure: {', '.join(unknown)}", where="lower")
    lb = None if not lower else np.array([float(lower.get(k, -np.inf)) for k in st.parameters])

    def run(theta_start: np.ndarray, d_start: float) -> tuple[np.ndarray, float, int, dict[str, Any], int]:
        m = int(np.floor(d_start / dt + 1e-9))
        f = d_start - m * dt
        xi = theta_start / prob.scale
        shifts, seen, b_start, iters = 0, set(), b0, 0
        while True:
            if fit_delay:
                x0 = np.r_[xi, f, b_start]
                xs, ssr, st_info = prob.solve(x0, prob.inputs(w, m), nonnegative_f=(m == 0), lower=lb)
                iters += st_info["iterations"]
                fx = float(xs[len(xi)])
                seen.add(m)
                move = int(np.floor(fx / dt))  # f left [0, dt): the delay is in another sample interval
                if move and (m + move) not in seen and m + move >= 0 and shifts < 20:
                    m, f, xi, b_start = m + move, fx - move * dt, xs[:len(xi)], xs[-1]
                    shifts += 1
                    continue
            else:
                fixed_f = d_start - m * dt
                xs, ssr, st_info = prob.solve(np.r_[xi, b_start], prob.inputs(w, m, fixed_f), lower=lb)
                iters += st_info["iterations"]
            st_info["iterations"] = iters
            return xs, ssr, m, st_info, shifts

    xs, ssr, m, st_info, shifts = run(theta0, d0)
    info["starts"] = 1
    yd_fit = yd if mask is None else yd[mask]
    init_ssr = float(np.sum((yd_fit - np.mean(yd_fit)) ** 2))
    if not st_info["success"] or not np.isfinite(ssr) or ssr > init_ssr:
        for factor in (0.5, 2.0, 0.2, 5.0):
            cand = run(theta0 * factor, d0)
            info["starts"] += 1
            if cand[3]["success"] and cand[1] < ssr:
                xs, ssr, m, st_info, shifts = cand
                if st_info["success"] and ssr <= init_ssr:
                    break
    info.update(st_info)
    info["delay_shifts"] = shifts
    p = len(st.parameters)
    theta = xs[:p] * prob.scale
    if fit_delay:
        f_hat, b_hat = float(xs[p]), float(xs[p + 1])
        par = prob.inputs(w, m)
    else:
        f_hat, b_hat = float(d0 - m * dt), float(xs[p])
        par = prob.inputs(w, m, f_hat)
    d_hat = m * dt + f_hat
    yhat = np.asarray(prob.yhat_fn(xs, par)).ravel()
    J = np.asarray(prob.jac_fn(xs, par))
    scale_vec = np.r_[prob.scale, 1.0, 1.0] if fit_delay else np.r_[prob.scale, 1.0]
    J = J / scale_vec[None, :]
    resid = y - yhat
    y_fit = y
    if mask is not None:
        J, resid, y_fit = J[mask], resid[mask], y[mask]
    dof = resid.size - J.shape[1]
    s2 = float(np.sum(resid**2) / dof)
    JtJ = J.T @ J
    try:
        cov = s2 * np.linalg.inv(JtJ)
    except np.linalg.LinAlgError:
        cov = s2 * np.linalg.pinv(JtJ)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    tq = float(student_t.ppf(0.975, dof))
    names = [*st.parameters, *([delay_name] if fit_delay else []), "offset"]
    values = [*theta.tolist(), *([d_hat] if fit_delay else []), b_hat]
    params = {k: float(v) for k, v in zip(names[:-1], values[:-1])}
    std = {k: float(s) for k, s in zip(names[:-1], sd[:-1])}
    if not fit_delay:
        params[delay_name], std[delay_name] = float(d_hat), 0.0
    ci = {k: (params[k] - tq * std[k], params[k] + tq * std[k]) for k in params}
    fit_pct = float(100.0 * (1.0 - np.linalg.norm(resid) / np.linalg.norm(y_fit - np.mean(y_fit))))
    plant = st.plant(theta, delay=d_hat, input=record.input, output=record.output, label="identified")
    measured = plant.series(sensor) if sensor is not None else plant
    if sensor is not None:
        measured = Plant(measured.num, measured.den, d_hat, record.input, record.output, "identified with sensor")
    return TimeFitResult(st, params, std, ci, names, cov, float(d_hat), fit_delay, b_hat, float(sd[-1]),
                         fit_pct, float(np.sqrt(s2)), plant, sensor, measured, initial_out, info, t.copy(), y.copy(),
                         yhat, u0, periodic)


# ------------------------------------------------------------------ identify


@dataclass(frozen=True, eq=False)
class IdentifyResult:
    """Identification of a record: the step averaging (if any) and the fit.

    Examples
    --------
    >>> from synth.ident.x4_record import x4_step_train, SENSOR
    >>> clean = x4_step_train(periods=1, noise_std=0.0)  # noise-free, fitted as it is (no averaging)
    >>> res = identify(clean, "k*(s+z)/((s+p1)*(s+p2))", delay="fit", sensor=SENSOR, average="none")
    >>> sorted(round(v, 5) for v in res.fit.parameters.values())
    [0.02, 0.43, 0.54, 9.6, 23.0]
    """

    record: Record
    fit: TimeFitResult
    average: StepAverage | None

    @property
    def plant(self) -> Plant:
        """The identified plant ``F`` (with its delay)."""
        return self.fit.plant

    def to_dict(self) -> dict[str, Any]:
        """The fit's JSON plus ``record`` and ``averaging``."""
        return {**self.fit.to_dict(), "record": self.record.to_dict(),
                "averaging": self.average.to_dict() if self.average is not None else None}


def _two_level(u: np.ndarray) -> bool:
    lo, hi = float(np.min(u)), float(np.max(u))
    near = (np.abs(u - lo) <= 0.05 * (hi - lo)) | (np.abs(u - hi) <= 0.05 * (hi - lo))
    return bool(np.mean(near) >= 0.98)


def identify(record: Record, structure: Structure | str, delay: str | float | None = None,
             sensor: Plant | str | None = None, average: str = "auto") -> IdentifyResult:
    """Identify a structure from a record: average a step train if there is one, then fit.

    Parameters
    ----------
    record : Record
    structure : Structure or str
    delay : {"fit", float, None}
        See :func:`fit_structure`.
    sensor : Plant or str, optional
        Known sensor in series.
    average : {"auto", "cycle", "edge", "none"}
        ``"auto"``: a two-level input with at least two steps is averaged
        (:func:`synth.ident.steps.average_steps`), anything else is fitted as it is.

    Returns
    -------
    IdentifyResult
    """
    if average not in ("auto", "cycle", "edge", "none"):
        raise ModelError(f"average must be 'auto', 'cycle', 'edge' or 'none', got {average!r}")
    avg = None
    data, periodic = record, False
    if average != "none" and _two_level(record.u):
        steps = find_steps(record)
        if steps.count >= 2 or average in ("cycle", "edge"):
            avg = average_steps(record, steps, "auto" if average == "auto" else average)
            data, periodic = avg.record(), avg.periodic
    fit = fit_structure(data, structure, delay, sensor, periodic)
    return IdentifyResult(record, fit, avg)
