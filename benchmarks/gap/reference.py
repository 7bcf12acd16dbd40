"""Independent reference simulation of a continuous plant with one effect: scipy ``solve_ivp``, not synth's kernels.

The generalizing benchmark (:mod:`benchmarks.gap.generalize`) simulates its truth records here, written
apart from synth's simulation code (:mod:`synth.ident.simulate`, :mod:`synth.sim`, the effects' own
``apply``): the plant is put in controllable canonical form from its polynomials, the command is held
between samples (a DAC), delayed exactly, and every effect is applied in continuous time:

* static maps of the held command (saturation, dead zone, backlash, quantization, static nonlinearity,
  the measured supply) are applied sample by sample before the hold;
* dynamic effects are extra states of the ODE: a rate limiter that ramps at ``rate`` until it reaches
  the command (the arrival time is a breakpoint of the integration), a supply filter
  ``tau f' + f = u`` with ``v = u (1 - sag max(0, u - f))``, a direction-dependent actuator (each
  command change arrives ``delay_up`` or ``delay_down`` later; the actuator follows with ``tau_up``
  below its target and ``tau_down`` above it);
* a lag or a resonance multiplies the transfer function; a delay adds to the plant's;
* feedback of the output into the plant input: a cubic spring ``-cubic y^3 / G(0)`` and a quadratic
  damping ``-drag y' |y'| / G(0)`` (``y'`` the exact output rate ``C x'``);
* an output drift ``slope (t - t0)`` is added to the samples.

The state is integrated piece by piece between breakpoints (sample times, delayed command changes,
rate-limit arrivals) with DOP853 at ``rtol = 1e-9``, so no discontinuity falls inside a step.

When the effect leaves the plant linear in what reaches it (no effect, a delay, a lag, a resonance, a
static map of the held command, a drift; :data:`LINEAR_EFFECTS`), the output is instead the
superposition of the held command's changes, each times the plant's step response from rest, delayed
exactly: ``y_k = G(0) w_0 + sum_j (w_j - w_j-1) s(t_k - t_j - delay)``. The step response ``s`` is
integrated by one ``solve_ivp`` call (same method, ``rtol = 1e-12``, evaluated at ``m dt - delay``; beyond 40
of the slowest time constants it is ``G(0)``, the transient below 4e-18 of it) and the sum is an FFT
convolution. Same truth, one smooth integration instead of one per command change: a 100,000-sample
noise record takes about a second instead of 20-40 s; the two agree within 1e-9 of the output's range
(``tests/test_gap_generalize.py``; ``method="piecewise"`` forces the piecewise integration).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.signal import fftconvolve

__all__ = ["TruePlant", "simulate_reference"]

METHOD = "DOP853"
RTOL = 1e-9
LINEAR_EFFECTS: frozenset[str | None] = frozenset({None, "delay", "lag", "resonance", "saturation", "deadzone",
                                                    "backlash", "quantization", "static_nonlinearity", "drift",
                                                    "measured_sag"})
"""Effects after which the plant is linear in the held (mapped) command: simulated by superposition."""
STEP_RTOL = 1e-12
"""The step response's tolerance: one integration serves every change, so it is held tighter than ``RTOL``."""
SETTLED = 40.0
"""Slowest time constants after which the step response's transient is taken as zero (``exp(-40)``)."""


@dataclass(frozen=True)
class TruePlant:
    """A continuous plant ``num(s)/den(s) exp(-delay s)`` (coefficients in descending powers).

    Examples
    --------
    >>> TruePlant((2.0,), (0.5, 1.0)).gain
    2.0
    """

    num: tuple[float, ...]
    den: tuple[float, ...]
    delay: float = 0.0

    @property
    def gain(self) -> float:
        """Static gain ``num(0)/den(0)``."""
        return float(self.num[-1] / self.den[-1])

    def with_factor(self, num: tuple[float, ...], den: tuple[float, ...]) -> TruePlant:
        """The plant times ``num(s)/den(s)``."""
        return TruePlant(tuple(np.polymul(self.num, num)), tuple(np.polymul(self.den, den)), self.delay)

    def state_space(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Controllable canonical form ``(A, B, C, D)`` (``den`` made monic).

        Examples
        --------
        >>> A, B, C, D = TruePlant((3.0,), (1.0, 2.0)).state_space()
        >>> A.tolist(), B.tolist(), C.tolist(), D
        ([[-2.0]], [1.0], [3.0], 0.0)
        """
        den = np.trim_zeros(np.asarray(self.den, float), "f")
        num = np.trim_zeros(np.asarray(self.num, float), "f")
        num, den = num / den[0], den / den[0]
        n = den.size - 1
        alpha = den[::-1][:n]  # ascending: alpha_0 .. alpha_{n-1}
        beta = np.zeros(n + 1)
        beta[:num.size] = num[::-1]
        A = np.zeros((n, n))
        A[:-1, 1:] = np.eye(n - 1)
        A[-1, :] = -alpha
        B = np.zeros(n)
        B[-1] = 1.0
        C = beta[:n] - beta[n] * alpha
        return A, B, C, float(beta[n])


def _static_map(effect: str | None, params: dict[str, float], u: np.ndarray, aux: np.ndarray | None) -> np.ndarray:
    """The held command after a static (or hysteretic) input effect, sample by sample."""
    u = np.asarray(u, float).copy()
    p = params
    if effect == "saturation":
        return np.clip(u, p.get("lower", -np.inf), p.get("upper", np.inf))
    if effect == "deadzone":
        c, w = p.get("center", 0.0), p["width"]
        x = u - c
        return c + np.sign(x) * np.maximum(np.abs(x) - w, 0.0)
    if effect == "backlash":
        half = 0.5 * p["width"]
        out = np.empty_like(u)
        b = u[0]
        for i, x in enumerate(u):
            b = min(max(b, x - half), x + half)
            out[i] = b
        return out
    if effect == "quantization":
        off, q = p.get("offset", 0.0), p["step"]
        return off + q * np.round((u - off) / q)
    if effect == "static_nonlinearity":
        h = p["scale"]
        x = (u - p["center"]) / h
        return u + h * (p["a2"] * x**2 + p["a3"] * x**3)
    if effect == "measured_sag":
        assert aux is not None
        return u + p["sag"] * (u - p["u_rest"]) * (aux / p["v_nominal"] - 1.0)
    return u


def step_response(plant: TruePlant, tau: np.ndarray) -> np.ndarray:
    """The unit step response from rest, without the delay, at the increasing times ``tau > 0`` (``solve_ivp``).

    Examples
    --------
    >>> s = step_response(TruePlant((2.0,), (0.5, 1.0)), np.array([0.5, 1.0]))
    >>> bool(np.allclose(s, 2.0 * (1.0 - np.exp(-np.array([1.0, 2.0]))), rtol=1e-9))
    True
    """
    A, B, C, D = plant.state_space()
    out = np.full(tau.size, plant.gain)
    slowest = float(np.min(-np.linalg.eigvals(A).real))
    live = tau <= SETTLED / slowest
    if not np.any(live):
        return out
    x_end = -np.linalg.solve(A, B)
    sol = solve_ivp(lambda _, x: A @ x + B, (0.0, float(tau[live][-1])), np.zeros(A.shape[0]), method=METHOD,
                    rtol=STEP_RTOL, atol=1e-14 * (1.0 + float(np.max(np.abs(x_end)))), t_eval=tau[live])
    if not sol.success:
        raise RuntimeError(f"reference step response failed: {sol.message}")
    out[live] = C @ sol.y + D
    return out


def _superposed(plant: TruePlant, t: np.ndarray, w: np.ndarray, delay: float) -> np.ndarray:
    """Output of the linear ``plant`` to the held ``w`` (from rest at ``w[0]``), by superposition of its changes."""
    dt = float(t[1] - t[0])
    lag = np.arange(t.size) * dt - delay  # time since a change at lag m reached the plant
    on = lag > 1e-9 * dt  # a change arriving at a sample time acts after it, as in the piecewise integration
    h = np.zeros(t.size)
    h[on] = step_response(plant, lag[on])
    dw = np.diff(w, prepend=w[0])
    return plant.gain * w[0] + fftconvolve(dw, h)[:t.size]


def simulate_reference(plant: TruePlant, t: np.ndarray, u: np.ndarray, effect: str | None = None,
                       params: dict[str, float] | None = None, aux: np.ndarray | None = None,
                       method: str = "auto") -> np.ndarray:
    """Output samples ``y(t_k)`` of ``plant`` with ``effect`` driven by the held command ``u``, from rest at ``u[0]``.

    Parameters
    ----------
    plant : TruePlant
        Strictly proper or not; stable.
    t, u : numpy.ndarray
        Uniform sample times and the command held on ``[t_k, t_k+1)``.
    effect : str, optional
        ``delay, lag, resonance, rate_limit, saturation, deadzone, backlash, quantization, supply_sag,
        static_nonlinearity, drift, direction, duffing, amplitude_damping, measured_sag`` (see the module text).
    params : dict
        The effect's parameters (names as in :mod:`synth.gap.effects`; ``measured_sag`` also takes
        ``v_nominal`` and ``u_rest``).
    aux : numpy.ndarray, optional
        The supply voltage sample by sample (``measured_sag``).
    method : str
        ``"auto"``: superposition for :data:`LINEAR_EFFECTS`, piecewise integration otherwise;
        ``"piecewise"``: piecewise integration always.

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> t = np.arange(0, 1, 0.1); u = (t >= 0.2).astype(float)
    >>> y = simulate_reference(TruePlant((1.0,), (0.1, 1.0)), t, u)
    >>> round(float(y[3]), 4), float(y[2])  # 1 - exp(-1) one sample after the step
    (0.6321, 0.0)
    """
    p = dict(params or {})
    t = np.asarray(t, float)
    dt = float(t[1] - t[0])
    G = plant
    delay = plant.delay
    if effect == "delay":
        delay += p["delay"]
    elif effect == "lag":
        G = G.with_factor((1.0,), (p["tau"], 1.0))
    elif effect == "resonance":
        wn, z = p["wn"], p["zeta"]
        G = G.with_factor((wn**2,), (1.0, 2 * z * wn, wn**2))
    A, B, C, D = G.state_space()
    k0 = G.gain
    n = A.shape[0]
    v = _static_map(effect, p, np.asarray(u, float), aux)
    if method == "auto" and effect in LINEAR_EFFECTS:
        out = _superposed(G, t, v, delay)
        return out + p["slope"] * (t - t[0]) if effect == "drift" else out
    times = t + delay  # when each held value reaches the plant (or the dynamic effect)
    extra = 1 if effect in ("rate_limit", "supply_sag", "direction") else 0
    if effect == "direction":  # each change arrives by its direction's latency
        du = np.diff(v, prepend=v[0])
        when = times + np.where(du > 0, p.get("delay_up", 0.0), p.get("delay_down", 0.0))
        order = np.argsort(when, kind="stable")
        change_t, change_v = when[order], v[0] + np.cumsum(du[order])
    else:
        change_t, change_v = times, v
    keep = np.r_[True, np.diff(change_v) != 0]  # only where the held value changes
    change_t, change_v = change_t[keep], change_v[keep]
    c3, cd = p.get("cubic", 0.0) / k0, p.get("drag", 0.0) / k0
    CB, CA = float(C @ B), C @ A

    def plant_input(x: np.ndarray, w: float) -> float:
        if effect == "duffing":
            y = float(C @ x) + D * w
            return w - c3 * y**3
        if effect == "amplitude_damping":  # ydot = CA x + CB f, f = w - cd ydot |ydot|: solve for ydot
            r = float(CA @ x) + CB * w
            q = cd * CB
            yd = np.sign(r) * 2 * abs(r) / (1 + np.sqrt(1 + 4 * q * abs(r))) if q > 0 else r
            return w - cd * yd * abs(yd)
        return w

    def rhs(_: float, z: np.ndarray, target: float, slope: float) -> np.ndarray:
        x = z[:n]
        if effect == "rate_limit":
            w, de = z[n], slope
        elif effect == "supply_sag":
            w = target * (1.0 - p["sag"] * max(0.0, target - z[n]))
            de = (target - z[n]) / p["tau"]
        elif effect == "direction":
            tau = p["tau_up"] if target > z[n] else p["tau_down"]
            w, de = z[n], (target - z[n]) / tau
        else:
            w, de = target, 0.0
        dx = A @ x + B * plant_input(x, w)
        return np.r_[dx, de] if extra else dx

    # rest at the first held value
    w0 = v[0]
    if effect == "duffing" and c3 != 0.0:  # y + cubic y^3 = k0 u0: the real root nearest the linear one
        roots = np.roots([p["cubic"], 0.0, 1.0, -k0 * w0])
        y0 = float(min(roots[np.abs(roots.imag) < 1e-9].real, key=lambda r: abs(r - k0 * w0)))
        w0 = w0 - c3 * y0**3
    x0 = -np.linalg.solve(A, B * w0)
    z = np.r_[x0, v[0]] if extra else x0
    breaks = np.r_[t[0], np.unique(change_t[(change_t > t[0]) & (change_t < t[-1])]), t[-1]]
    states = np.empty((t.size, z.size))
    states[0] = z
    k_change = int(np.searchsorted(change_t, t[0], side="right"))
    target = change_v[k_change - 1] if k_change > 0 else v[0]
    targets = np.full(t.size, target)
    scale = 1.0 + float(np.max(np.abs(z)))
    for a, b in itertools.pairwise(breaks):
        while k_change < change_t.size and change_t[k_change] <= a + 1e-12 * dt:
            target = change_v[k_change]
            k_change += 1
        pieces = [(a, b, 0.0)]
        if effect == "rate_limit":  # ramp at the rate until the command is reached, then hold
            gap = target - z[n]
            t_hit = a + abs(gap) / p["rate"]
            slope = np.sign(gap) * p["rate"]
            pieces = [(a, b, slope)] if t_hit >= b else [(a, t_hit, slope), (t_hit, b, 0.0)]
        for i_piece, (a1, b1, slope) in enumerate(pieces):
            if b1 - a1 > 1e-12 * dt:
                lo, hi = np.searchsorted(t, a1, side="right"), np.searchsorted(t, b1, side="right")
                m = hi - lo
                t_eval = t[lo:hi] if m and t[hi - 1] == b1 else np.r_[t[lo:hi], b1]
                sol = solve_ivp(rhs, (a1, b1), z, method=METHOD, rtol=RTOL, atol=1e-11 * scale, t_eval=t_eval,
                                args=(target, slope))
                if not sol.success:
                    raise RuntimeError(f"reference integration failed at t = {a1}: {sol.message}")
                states[lo:hi] = sol.y[:, :m].T
                targets[lo:hi] = target
                z = sol.y[:, -1].copy()
            if i_piece == 0 and len(pieces) == 2:
                z[n] = target  # the rate limiter has arrived
    out = np.empty(t.size)
    for j in range(t.size):
        x, target = states[j, :n], targets[j]
        if effect in ("rate_limit", "direction"):
            w = states[j, n]
        elif effect == "supply_sag":
            w = target * (1.0 - p["sag"] * max(0.0, target - states[j, n]))
        else:
            w = target
        out[j] = float(C @ x) + D * plant_input(x, w)
    out[0] = float(C @ x0) + D * w0
    if effect == "drift":
        out = out + p["slope"] * (t - t[0])
    return out
