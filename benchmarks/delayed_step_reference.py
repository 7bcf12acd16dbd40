"""Independent numerical reference for unit-step responses of PI/PID loops with an exact input delay.

Loop: e = 1 - y, u = C(s) e, y = num/den exp(-delay s) u, at rest for t < 0, with C = kp + ki/s ("PI") or
C = kp + ki/s + kd s/(tf s + 1) ("PID") and num/den strictly proper. Only numpy and scipy are used (nothing from
synth). Loop state X = [x, z, w]: x the plant in observable canonical form (y = x[0]), z' = e and, for PID only,
w' = (e - w)/tf, so that u = kp e + ki z + (kd/tf)(e - w) is affine in X. Run this file for the self-check.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import integrate, signal

BLOW_UP = 1e6


def _gains(kind: str, params: dict) -> tuple[float, float, float, float]:
    """(kp, ki, kd, tf); kd = 0 and tf = 1 for PI."""
    if kind not in ("PI", "PID"):
        raise ValueError(f"kind must be 'PI' or 'PID', not {kind!r}")
    kd, tf = (params["kd"], params["tf"]) if kind == "PID" else (0.0, 1.0)
    return float(params["kp"]), float(params["ki"]), float(kd), float(tf)


def _loop(num, den, kind: str, kp, ki, kd, tf):
    """Loop matrices over N controllers: X' = M X + b v + c (v the delayed plant input) and u = g X + g0."""
    den = np.trim_zeros(np.atleast_1d(np.asarray(den, float)), "f")
    num = np.trim_zeros(np.atleast_1d(np.asarray(num, float)), "f")
    n = len(den) - 1
    if n < 1 or len(num) > n:
        raise ValueError("num/den must be strictly proper")
    kp, ki, kd, tf = (np.atleast_1d(np.asarray(a, float)) for a in (kp, ki, kd, tf))
    N, ns = len(kp), n + (2 if kind == "PID" else 1)
    M, b, c, g = np.zeros((N, ns, ns)), np.zeros(ns), np.zeros((N, ns)), np.zeros((N, ns))
    M[:, :n, 0] = -den[1:] / den[0]
    M[:, np.arange(n - 1), np.arange(1, n)] = 1.0
    b[n - len(num):n] = num / den[0]
    M[:, n, 0], c[:, n] = -1.0, 1.0
    g[:, 0], g[:, n], g0 = -(kp + kd / tf), ki, kp + kd / tf
    if kind == "PID":
        M[:, n + 1, 0] = M[:, n + 1, n + 1] = -1.0 / tf
        c[:, n + 1], g[:, n + 1] = 1.0 / tf, -kd / tf
    return M, b, c, g, g0


def final_value(num, den, kind: str, params: dict) -> float:
    """Closed-loop DC gain T(0): 1 with integral action (ki > 0), else C(0)G(0) / (1 + C(0)G(0)).

    Parameters
    ----------
    num, den : array_like
        Plant, descending powers of s.
    kind, params : str, dict
        "PI" or "PID"; kp, ki (and kd, tf for PID).

    Returns
    -------
    float
        Final value of the unit-step response of a stable loop.

    Examples
    --------
    >>> final_value([2.0], [1.0, 1.0], "PI", {"kp": 1.5, "ki": 0.0})
    0.75
    """
    kp, ki, _, _ = _gains(kind, params)
    loop = kp * np.polyval(num, 0.0) / np.polyval(den, 0.0)
    return 1.0 if ki != 0 else float(loop / (1.0 + loop))


def dde_step(num, den, delay: float, kind: str, params: dict, horizon: float, samples: int = 4001,
             method: str = "DOP853", rtol: float = 1e-11, max_intervals: int = 200_000,
             ) -> tuple[np.ndarray, np.ndarray] | None:
    """Accurate unit-step response by the method of steps with ``solve_ivp``, the delay exact.

    Each interval [k delay, (k + 1) delay] is a fresh ``solve_ivp`` call (so the jumps and kinks of the delayed
    input fall on restarts) whose plant input u(t - delay) = g X(t - delay) + g0 comes from the dense output of the
    previous interval. The absolute tolerance is ``rtol / 100`` times max(1, |final value|).

    Parameters
    ----------
    num, den : array_like
        Strictly proper plant, descending powers of s.
    delay, horizon : float
        Input delay (> 0) and end time.
    kind, params : str, dict
        "PI" or "PID"; kp, ki (and kd, tf > 0 for PID).
    samples, method, rtol, max_intervals : int, str, float, int
        Output on ``np.linspace(0, horizon, samples)``; ``solve_ivp`` method ("DOP853", or "Radau" for stiff
        loops) and relative tolerance; ValueError past ``max_intervals`` intervals (0.3 ms or more each).

    Returns
    -------
    tuple of ndarray or None
        (t, y), or None if the integration failed or |y| exceeded 1e6 (unstable loop).

    Examples
    --------
    >>> t, y = dde_step([1.0], [1.0, 1.0], 0.5, "PI", {"kp": 0.5, "ki": 0.5}, 20.0, samples=201)
    >>> float(np.abs(y[t < 0.5]).max()), round(float(y[-1]), 4)
    (0.0, 1.0)
    """
    n_int = int(np.ceil(horizon / delay - 1e-12)) if delay > 0 and horizon > 0 else -1
    if not 0 < n_int <= max_intervals:
        raise ValueError(f"need delay > 0, horizon > 0 and horizon / delay <= {max_intervals}")
    M, b, c, g, g0 = _loop(num, den, kind, *_gains(kind, params))
    M, c, g, g0 = M[0], c[0], g[0], float(g0[0])
    atol = rtol * 1e-2 * max(1.0, abs(final_value(num, den, kind, params)))
    t_out, y_out = np.linspace(0.0, horizon, samples), np.zeros(samples)
    k_of_t = np.minimum((t_out / delay).astype(int), n_int - 1)
    x0, prev = np.zeros(len(c)), None
    for k in range(n_int):
        t0, t1 = k * delay, min((k + 1) * delay, horizon)

        def rhs(t, x, prev=prev, lo=t0 - delay):
            v = 0.0 if prev is None else g @ prev(max(t - delay, lo)) + g0
            return M @ x + b * v + c

        sol = integrate.solve_ivp(rhs, (t0, t1), x0, method=method, rtol=rtol, atol=atol, dense_output=True)
        if sol.status < 0 or not np.all(np.isfinite(sol.y)) or np.abs(sol.y[0]).max() > BLOW_UP:
            return None
        idx = np.flatnonzero(k_of_t == k)
        if idx.size:
            y_out[idx] = sol.sol(np.clip(t_out[idx], t0, t1))[0]
        prev, x0 = sol.sol, sol.y[:, -1]
    return t_out, y_out


def _rk4_map(M, b, c, g, g0, h: float) -> np.ndarray:
    """One classical RK4 step of every loop as an affine map, shape (N, ns + 4, ns + 4).

    It maps [X(t), v(t), v(t + h/2), v(t + h), 1] (v the delayed input, as left/right limits) to
    [X(t + h), u(t + h), u(t + h/2), y'(t), y'(t + h)], u(t + h/2) from the cubic Hermite interpolant of X.
    """
    N, ns = c.shape
    unit = np.eye(ns + 4)
    X0 = np.zeros((N, ns, ns + 4))
    X0[:, :, :ns] = np.eye(ns)

    def f(S, col):
        return M @ S + b[None, :, None] * unit[col] + c[:, :, None] * unit[-1]

    def u(S):
        return g[:, None, :] @ S + g0[:, None, None] * unit[-1]

    k1 = f(X0, ns)
    k2 = f(X0 + 0.5 * h * k1, ns + 1)
    k3 = f(X0 + 0.5 * h * k2, ns + 1)
    X1 = X0 + (h / 6.0) * (k1 + 2.0 * (k2 + k3) + f(X0 + h * k3, ns + 2))
    f1 = f(X1, ns + 2)
    return np.concatenate([X1, u(X1), u(0.5 * (X0 + X1) + (h / 8.0) * (k1 - f1)), k1[:, :1], f1[:, :1]], axis=1)


def _fastest_rate(M, b, g) -> float:
    """Largest |eigenvalue| over the open loops (plant, 1/tf) and the undelayed closed loops (u fed back at once)."""
    return float(np.abs(np.linalg.eigvals(np.concatenate([M, M + b[None, :, None] * g[:, None, :]]))).max())


def grid_steps(num, den, delay: float, kind: str, params_list: list[dict], horizon: float, samples: int = 2001,
               h_rate: float = 0.2, m_min: int = 20, max_steps: int = 400_000) -> np.ndarray:
    """Unit-step responses of many controllers at once: fixed-step RK4 vectorized over the controllers.

    The step is h = delay/m with m >= m_min and h * rate <= h_rate, rate the largest |eigenvalue| over the open
    loops (plant poles, 1/tf) and every undelayed closed loop. Since delay = m h, the delayed input at the RK4
    stages sits on steps and half steps, read from a ring buffer of u (half steps from the Hermite interpolant of
    the state): no interpolation in the delay, and the jump of u at t = 0 is taken as a left/right limit. Outputs
    between steps come from the cubic Hermite interpolant of y. If ``horizon / h`` would exceed ``max_steps``,
    m is lowered to fit: the accuracy is then not guaranteed, and rows whose fast modes leave the RK4 stability
    region blow up and come out NaN (ValueError if even m = 1, one step per delay, does not fit). With the
    defaults the self-check finds max |y - dde_step| below 2e-5 max(1, |final value|) on stable loops.

    Parameters
    ----------
    num, den : array_like
        Strictly proper plant, descending powers of s.
    delay, horizon : float
        Input delay (> 0) and end time.
    kind, params_list : str, list of dict
        "PI" or "PID" (shared); the controllers, each with kp, ki (and kd, tf > 0 for PID).
    samples, h_rate, m_min, max_steps : int, float, int, int
        Output on ``np.linspace(0, horizon, samples)``; step-size controls, see above.

    Returns
    -------
    ndarray
        Shape (len(params_list), samples); a row is all NaN if its response became non-finite or exceeded 1e6.

    Examples
    --------
    >>> ps = [{"kp": 0.5, "ki": 0.5}, {"kp": 5.0, "ki": 5.0}]
    >>> y = grid_steps([1.0], [1.0, 1.0], 0.5, "PI", ps, 40.0, samples=101)
    >>> round(float(y[0, -1]), 4), bool(np.isnan(y[1]).all())
    (1.0, True)
    """
    gains = np.array([_gains(kind, p) for p in params_list]).T
    M, b, c, g, g0 = _loop(num, den, kind, *gains)
    if not 0 < horizon <= max_steps * delay:
        raise ValueError("need 0 < horizon <= max_steps * delay")
    m = min(max(m_min, int(np.ceil(delay * _fastest_rate(M, b, g) / h_rate))), int(max_steps * delay / horizon))
    h = delay / m
    n_steps = int(np.ceil(horizon / h - 1e-9))
    T = _rk4_map(M, b, c, g, g0, h)
    (N, ns), R = c.shape, m + 2
    t_out = np.linspace(0.0, horizon, samples)
    j_of_t = np.minimum((t_out / h).astype(int), n_steps - 1)
    theta, bounds = t_out / h - j_of_t, np.searchsorted(j_of_t, np.arange(n_steps + 1))
    Ug, Uh = np.zeros((R, N)), np.zeros((R, N))
    Ug[0] = g0  # u(0+), while u = 0 for t < 0
    vec, Y, dead = np.zeros((N, ns + 4, 1)), np.empty((N, samples)), np.zeros(N, bool)
    vec[:, -1] = 1.0
    with np.errstate(all="ignore"):
        for j in range(n_steps):
            y0 = vec[:, 0, 0].copy()
            vec[:, ns, 0] = Ug[(j - m) % R] if j >= m else 0.0
            vec[:, ns + 1, 0] = Uh[(j - m) % R] if j >= m else 0.0
            vec[:, ns + 2, 0] = Ug[(j + 1 - m) % R] if j + 1 > m else 0.0
            out = np.matmul(T, vec)[:, :, 0]
            vec[:, :ns, 0], Ug[(j + 1) % R], Uh[j % R] = out[:, :ns], out[:, ns], out[:, ns + 1]
            lo, hi = bounds[j], bounds[j + 1]
            if hi > lo:
                th = theta[lo:hi]
                Y[:, lo:hi] = (np.outer(y0, (1 + 2 * th) * (1 - th) ** 2) + np.outer(h * out[:, ns + 2], th * (1 - th) ** 2)
                               + np.outer(out[:, 0], th**2 * (3 - 2 * th)) - np.outer(h * out[:, ns + 3], th**2 * (1 - th)))
            if j % 64 == 0:
                bad = ~(np.abs(out[:, 0]) <= BLOW_UP)
                dead |= bad
                vec[bad, :ns], Ug[:, bad], Uh[:, bad] = 0.0, 0.0, 0.0
        dead |= ~np.all(np.abs(Y) <= BLOW_UP, axis=1)
    Y[dead] = np.nan
    return Y


def _loop_polys(num, den, kind: str, params: dict) -> tuple[np.ndarray, np.ndarray]:
    """(dc den, nc num) for C = nc/dc, the factor s cancelled when ki = 0."""
    kp, ki, kd, tf = _gains(kind, params)
    if kind == "PI":
        nc, dc = ([kp, ki], [1.0, 0.0]) if ki else ([kp], [1.0])
    else:
        nc, dc = ([kp * tf + kd, kp + ki * tf, ki], [tf, 1.0, 0.0]) if ki else ([kp * tf + kd, kp], [tf, 1.0])
    return np.polymul(dc, den), np.polymul(nc, num)


def stable(num, den, delay: float, kind: str, params: dict) -> bool:
    """Asymptotic stability of the delayed loop by the argument principle along the imaginary axis.

    D(s) = dc(s) den(s) + nc(s) num(s) exp(-delay s) (C = nc/dc) is entire and of retarded type, so
    F = D / (s + a)^N (N = deg dc den, a > 0) tends to the leading coefficient of dc den on the right half-plane,
    and its number of zeros with Re s >= 0 is -1/pi times the phase change of F(jw) over w from 0 to infinity.
    The phase is tracked on a grid (dense below the frequency past which |C G| < 1/2) refined until every
    increment is below 0.3 rad. The integrator pole of C never enters (D(0) = ki num(0)).

    Parameters
    ----------
    num, den : array_like
        Strictly proper plant, descending powers of s (open-loop unstable poles allowed).
    delay : float
        Input delay, >= 0.
    kind, params : str, dict
        "PI" or "PID"; kp, ki (and kd, tf for PID).

    Returns
    -------
    bool
        True if no closed-loop root has Re s >= 0; False for unstable or marginal (|D(jw)| ~ 0) loops.

    Examples
    --------
    >>> [stable([1.0], [1.0, 1.0], 0.5, "PI", {"kp": k, "ki": k}) for k in (0.5, 5.0)]
    [True, False]
    """
    P1, P2 = _loop_polys(num, den, kind, params)
    N, r = len(P1) - 1, len(P1) - len(P2)
    a = float(np.abs(np.concatenate([np.roots(P1), np.roots(P2), [1.0]])).max())
    w_asym = (4.0 * abs(P2[0] / P1[0])) ** (1.0 / r) if P2.any() else 0.0
    w_log = np.geomspace(1e-8 * a, 1e4 * max(a, w_asym), 3000)
    loud = w_log[np.abs(np.polyval(P2, 1j * w_log)) >= 0.5 * np.abs(np.polyval(P1, 1j * w_log))]
    w_c = 2.0 * loud.max() if loud.size else 0.0
    w = np.union1d(np.r_[0.0, w_log], np.linspace(0.0, w_c, 2 + int(w_c * delay / 0.05)))
    for _ in range(12):
        s = 1j * w
        p1, p2 = np.polyval(P1, s), np.polyval(P2, s) * np.exp(-delay * s)
        if (np.abs(p1 + p2) <= 1e-10 * (np.abs(p1) + np.abs(p2))).any():
            return False
        F = (p1 + p2) / (s + a) ** N
        dphi = np.angle(F[1:] / F[:-1])
        bad = np.flatnonzero(np.abs(dphi) > 0.3)
        if not bad.size:
            zeros = -(dphi.sum() + np.angle(P1[0] / F[-1])) / np.pi
            return bool(abs(zeros) < 0.05)
        w = np.union1d(w, (w[bad, None] + np.linspace(0, 1, 10)[1:-1] * (w[bad + 1] - w[bad])[:, None]).ravel())
    return False


def step_metrics_from_samples(t: np.ndarray, y: np.ndarray, final: float, band: float = 0.02) -> dict:
    """Overshoot [%], settling time and 10-90 % rise time of a sampled step response.

    Parameters
    ----------
    t, y : ndarray
        Increasing sample times and the response.
    final : float
        Exact final value T(0), nonzero (see ``final_value``).
    band : float
        Relative settling band.

    Returns
    -------
    dict
        "max_overshoot": max(0, 100 (max(y/final) - 1)); "max_settling_time": time of the first sample after the
        last one with |y/final - 1| > band (0 if none, inf if that is the last sample); "max_rise_time": from the
        first sample >= 10 % to the first >= 90 % of final (inf if 90 % is never reached).

    Examples
    --------
    >>> t = np.linspace(0.0, 10.0, 1001)
    >>> m = step_metrics_from_samples(t, 1.0 - np.exp(-t), 1.0)
    >>> round(m["max_overshoot"], 3), round(m["max_settling_time"], 2), round(m["max_rise_time"], 2)
    (0.0, 3.92, 2.2)
    """
    t, r = np.asarray(t, float), np.asarray(y, float) / final
    out = np.flatnonzero(np.abs(r - 1.0) > band)
    settling = 0.0 if not out.size else float(t[out[-1] + 1]) if out[-1] + 1 < len(t) else np.inf
    i10, i90 = np.flatnonzero(r >= 0.1), np.flatnonzero(r >= 0.9)
    return {"max_overshoot": max(0.0, 100.0 * (float(r.max()) - 1.0)), "max_settling_time": settling,
            "max_rise_time": float(t[i90[0]] - t[i10[0]]) if i90.size else np.inf}


def _random_case(rng: np.random.Generator, gain_scale: float = 1.0):
    """Plant of order 1-3 (poles in [-10, -0.2] or a damped pair, DC gain 0.5-5), delay, kind, controller drawer."""
    order = int(rng.integers(1, 4))
    poles = -rng.uniform(0.2, 10.0, order).astype(complex)
    if order >= 2 and rng.random() < 0.3:
        wn, zeta = rng.uniform(0.3, 5.0), rng.uniform(0.3, 0.9)
        poles[:2] = wn * (-zeta + np.array([1j, -1j]) * np.sqrt(1 - zeta**2))
    den = np.real(np.poly(poles))
    num = np.poly([-rng.uniform(0.5, 10.0)]) if order >= 2 and rng.random() < 0.3 else np.ones(1)
    dc = rng.uniform(0.5, 5.0)
    num, slow = num * dc * den[-1] / num[-1], float(np.abs(poles).min())
    kind = "PID" if rng.random() < 0.5 else "PI"

    def draw() -> dict:
        p = {"kp": gain_scale * rng.uniform(0.05, 1.0) / dc, "ki": gain_scale * rng.uniform(0.02, 0.6) * slow / dc}
        return p | ({"kd": gain_scale * rng.uniform(0.0, 2.0) / (dc * slow), "tf": 0.01 / slow} if kind == "PID" else {})

    return num, den, rng.uniform(0.01, 1.0) / slow, kind, slow, draw


def _self_check(n_cases: int = 40, n_limit: int = 10, seed: int = 7) -> None:
    rng = np.random.default_rng(seed)
    e_grid, e_tol, e_lim, count = [], [], [], 0
    print("case kind n delay*slow | grid-dde  dde(rtol)-dde(rtol/100) | no-delay limit: eps/4 raw, extrapolated")
    while count < n_cases:
        num, den, delay, kind, slow, draw = _random_case(rng)
        params = draw()
        if not stable(num, den, delay, kind, params):
            continue
        horizon, scale = 20.0 / slow + 10.0 * delay, max(1.0, abs(final_value(num, den, kind, params)))
        y = dde_step(num, den, delay, kind, params, horizon, samples=2001)[1]
        Y = grid_steps(num, den, delay, kind, [params] + [draw() for _ in range(7)], horizon)
        e_grid.append(np.abs(Y[0] - y).max() / scale)
        e_tol.append(np.abs(dde_step(num, den, delay, kind, params, horizon, 2001, rtol=1e-13)[1] - y).max() / scale)
        line = f"{count:4d} {kind:4s} {len(den) - 1} {delay * slow:10.3f} | {e_grid[-1]:8.1e}  {e_tol[-1]:8.1e}"
        if count < n_limit:  # delays eps, eps/2, eps/4 and Richardson extrapolation to delay 0, compared for t >= 3 eps
            M, b, _, g, _ = _loop(num, den, kind, *_gains(kind, params))
            eps = 0.05 / _fastest_rate(M, b, g)
            tb = np.linspace(0.0, min(10.0 / slow, 2000 * eps), 1001)
            ys = [dde_step(num, den, eps / 2**i, kind, params, tb[-1], len(tb))[1] for i in range(3)]
            P1, P2 = _loop_polys(num, den, kind, params)
            y0, keep = signal.step(signal.TransferFunction(P2, np.polyadd(P1, P2)), T=tb)[1], tb >= 3 * eps
            raw, extra = ys[2] - y0, (8 * ys[2] - 6 * ys[1] + ys[0]) / 3 - y0
            e_lim.append((np.abs(raw[keep]).max() / scale, np.abs(extra[keep]).max() / scale))
            line += f" | {e_lim[-1][0]:8.1e} {e_lim[-1][1]:8.1e} (t*slow <= {tb[-1] * slow:.2f}, eps*slow {eps * slow:.0e})"
        print(line)
        count += 1
    print(f"worst grid vs dde {max(e_grid):.2e} (target 1e-4); dde tolerance effect {max(e_tol):.2e}")
    print(f"worst no-delay limit: raw {max(e[0] for e in e_lim):.2e}, extrapolated {max(e[1] for e in e_lim):.2e}")
    agree, n_unstable = 0, 0
    for _ in range(n_cases):
        num, den, delay, kind, slow, draw = _random_case(rng, gain_scale=2.0)
        params = draw()
        claim = stable(num, den, delay, kind, params)
        res = dde_step(num, den, delay, kind, params, 60.0 / slow + 60.0 * delay, samples=3001)
        dev = None if res is None else np.abs(res[1] - final_value(num, den, kind, params))
        sim = dev is not None and bool(dev[-600:].max() < max(1e-7, 0.5 * dev[1200:1800].max()))
        agree, n_unstable = agree + (claim == sim), n_unstable + (not sim)
        if claim != sim:
            print(f"disagreement: {kind} num={num} den={den} delay={delay} {params} stable()={claim}")
    print(f"stable() vs long dde_step simulation: {agree}/{n_cases} agree ({n_unstable} unstable by simulation)")
    num, den, delay = [2.0], np.poly([-1.0, -3.0]), 0.2
    for kind in ("PI", "PID"):
        ps = [{"kp": k, "ki": 0.5 * k, "kd": 0.2 * k, "tf": 0.01} for k in np.linspace(0.05, 1.5, 1000)]
        t0 = time.perf_counter()
        dde_step(num, den, delay, kind, ps[500], 100 * delay)
        t1 = time.perf_counter()
        Y = grid_steps(num, den, delay, kind, ps, 100 * delay)
        print(f"{kind}: dde_step 100 delays {t1 - t0:.3f} s; grid_steps 1000 controllers, 100 delays "
              f"{time.perf_counter() - t1:.3f} s ({np.isnan(Y[:, 0]).sum()} NaN rows)")


if __name__ == "__main__":
    _self_check()
