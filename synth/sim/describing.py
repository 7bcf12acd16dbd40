"""Describing functions and harmonic balance: predicted limit-cycle amplitude and frequency.

A nonlinearity driven by ``A sin(w t)`` is replaced by the complex gain
``N(A, w)`` of its output's fundamental. With the linear part ``L`` seen
from the nonlinearity's output back to its input (``x = -L(jw) y``), a limit
cycle is predicted where ``1 + L(jw) N(A, w) = 0``.

Closed forms:

* saturation at ``+-a``: ``N = 1`` for ``A <= a``, else
  ``N = (2/pi) (asin(a/A) + (a/A) sqrt(1 - (a/A)^2))``;
* dead zone of half-width ``d``: ``N = 1 - N_sat(A; a = d)``;
* rate limiter of rate ``R``: ``N = 1`` for ``A w <= R``;
  ``N = (4 R/(pi A w)) exp(-j arccos(pi R/(2 A w)))`` when the output is a triangle wave, which
  is exactly the case for ``A w >= R sqrt(1 + pi^2/4) = 1.862 R`` (the textbook bound
  ``pi R/2 = 1.571 R`` is where the formula is defined, not where it is exact). In between
  the output tracks the input part of the time; that ``N`` is computed exactly from the
  piecewise output (ramps at ``+-R`` joined to the sine).

Stability of a predicted cycle follows Loeb's criterion on
``F(A, w) = 1 + L N``: stable when ``dU/dA dV/dw - dU/dw dV/dA > 0``
(``F = U + jV``), i.e. a slightly larger amplitude decays back.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from synth.errors import ModelError

__all__ = [
    "TRIANGLE_RHO", "LoopCyclePrediction", "PredictedCycle", "dead_zone_df", "harmonic_balance", "numeric_df",
    "predict_loop_cycles", "rate_limiter_df", "sampled_loop_response", "saturation_df",
]


def saturation_df(A: Any, limit: float) -> np.ndarray:
    """Describing function of a symmetric saturation at ``+-limit`` (real, amplitude only).

    Examples
    --------
    >>> saturation_df([0.5, 1.0, 2.0], 1.0).round(4).tolist()
    [1.0, 1.0, 0.6090]
    """
    A = np.asarray(A, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.clip(limit / A, 0.0, 1.0)
        n = (2 / np.pi) * (np.arcsin(q) + q * np.sqrt(1 - q * q))
    return np.where(A <= limit, 1.0, n)


def dead_zone_df(A: Any, width: float) -> np.ndarray:
    """Describing function of a dead zone of half-width ``width`` (``1 - N_sat``).

    Examples
    --------
    >>> dead_zone_df([0.5, 2.0], 1.0).round(4).tolist()
    [0.0, 0.391]
    """
    return 1.0 - saturation_df(A, width)


TRIANGLE_RHO = 1.0 / np.sqrt(1.0 + np.pi**2 / 4)
"""``R/(A w)`` below which a rate limiter's output is a pure triangle wave (0.537)."""


def rate_limiter_df(A: float, w: float, rate: float, exact: bool = True) -> complex:
    """Describing function of a rate limiter (rate ``R``) for input ``A sin(w t)``.

    The textbook form ``(4R/(pi A w)) exp(-j arccos(pi R/(2 A w)))`` (``exact=False``, used for
    ``A w >= pi R/2``) assumes the output is a triangle wave. That holds exactly only for
    ``A w >= R sqrt(1 + pi^2/4) = 1.862 R``: the triangle must cross the sine with the sine
    falling faster than ``R``. Between ``R`` and ``1.862 R`` the output tracks the input part
    of each cycle, and ``exact=True`` (default) computes that ``N`` from the piecewise output;
    at ``A w = pi R/2`` it is ``0.762 - 0.261j`` against the textbook ``0.811``.

    Examples
    --------
    >>> rate_limiter_df(1.0, 1.0, 2.0)
    (1+0j)
    >>> n = rate_limiter_df(10.0, 1.0, 1.0)  # fully rate limited: 4R/(pi A w) at -arccos(pi R/(2 A w))
    >>> round(abs(n), 5), round(float(np.angle(n)), 5)
    (0.12732, -1.41306)
    >>> n = rate_limiter_df(1.0, 1.0, 2 / np.pi)
    >>> round(n.real, 3), round(n.imag, 3), round(rate_limiter_df(1.0, 1.0, 2 / np.pi, exact=False).real, 3)
    (0.762, -0.261, 0.811)
    """
    A, w, rate = float(A), float(w), float(rate)
    if A <= 0 or w <= 0:
        return complex(1.0)
    rho = rate / (A * w)
    if rho >= 1.0:
        return complex(1.0)
    if rho <= (TRIANGLE_RHO if exact else 2 / np.pi):
        return complex((4 * rate / (np.pi * A * w)) * np.exp(-1j * np.arccos(np.pi * rate / (2 * A * w))))
    if not exact:
        raise ModelError(f"the textbook rate-limiter describing function needs A w >= pi R/2; "
                         f"here A w = {A * w:g}, R = {rate:g}")
    return _rate_limiter_partial(rho)


def _rate_limiter_partial(rho: float, n: int = 4096) -> complex:
    """Exact N for 0.537 < rho = R/(A w) < 1 (unit amplitude): one period of the piecewise output."""
    from scipy.optimize import brentq

    theta_s = np.pi - np.arccos(rho)  # the falling input's slope first exceeds the limit here

    def gap(th: float) -> float:
        return np.sin(th) - (np.sin(theta_s) - rho * (th - theta_s))

    theta_e = brentq(gap, theta_s + 1e-3, theta_s + np.pi, xtol=1e-14)
    th = theta_s + np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    half = np.where(th < theta_e, np.sin(theta_s) - rho * (th - theta_s), np.sin(th))
    second = th >= theta_s + np.pi
    ramp_up = second & (th < theta_e + np.pi)
    y = np.where(second, np.where(ramp_up, -(np.sin(theta_s) - rho * (th - np.pi - theta_s)), np.sin(th)), half)
    b1 = 2 * np.mean(y * np.sin(th))
    a1 = 2 * np.mean(y * np.cos(th))
    return complex(b1, a1)


def numeric_df(blocks: Sequence[Any], A: float, w: float, bias: float = 0.0, points: int = 2000,
               periods: int = 4) -> complex:
    """Describing function of any block chain about ``bias``, by simulation: the fundamental of
    the output over the last period for input ``bias + A sin(w t)``, divided by ``A``.

    Examples
    --------
    >>> from synth.sim.blocks import Saturation
    >>> round(abs(numeric_df([Saturation(-1, 1)], 2.0, 1.0)), 3), round(float(saturation_df(2.0, 1.0)), 3)
    (0.609, 0.609)
    """
    from synth.sim.blocks import apply_chain

    dt = 2 * np.pi / (w * points)
    k = np.arange(points * periods)
    x = bias + A * np.sin(w * dt * k)
    y = apply_chain(list(blocks), x, dt)[-points:]
    th = w * dt * k[-points:]
    return complex(2 * np.mean(y * np.sin(th)), 2 * np.mean(y * np.cos(th))) / A


@dataclass(frozen=True)
class PredictedCycle:
    """A limit cycle predicted by harmonic balance.

    Attributes
    ----------
    amplitude : float
        Amplitude ``A`` at the nonlinearity's input.
    frequency : float
        ``w`` (rad/s).
    period : float
        ``2 pi / w`` (s).
    stable : bool
        Loeb's criterion: a stable (observable) cycle, or the unstable threshold between a
        stable rest and a larger cycle.
    """

    amplitude: float
    frequency: float
    period: float
    stable: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict.

        Examples
        --------
        >>> PredictedCycle(1.0, 2.0, 3.14, True).to_dict()["stable"]
        True
        """
        return asdict(self)


def harmonic_balance(L: Callable[[np.ndarray], np.ndarray], N: Callable[[float, float], complex],
                     w_range: tuple[float, float], a_range: tuple[float, float],
                     points: int = 400) -> list[PredictedCycle]:
    """Solve ``1 + L(jw) N(A, w) = 0`` for every ``(A, w)`` in the ranges.

    For each ``w`` on a log grid the amplitude with ``|N(A, w)| = 1/|L(jw)|`` is found
    (``|N|`` must fall monotonically with ``A``, as for saturation and rate limit); the phase
    balance ``arg(L N) = -pi`` is then bracketed along ``w`` and refined with Brent's method.
    The grid's amplitudes are found to 1 % (each search starts next to the previous frequency's
    answer); every bracket is re-evaluated to full precision, with its neighbours where a sign
    moved, before it is refined (``tests/test_harmonic_balance_random.py`` holds this to a search
    at full precision everywhere).

    Parameters
    ----------
    L : callable
        Linear part's complex response at an array of frequencies (rad/s).
    N : callable
        ``N(A, w)`` complex.
    w_range, a_range : (float, float)
        Where to look (rad/s; amplitude units).

    Examples
    --------
    >>> L = lambda w: 20 / (1j * w * (1j * w + 1) * (1j * w + 2))
    >>> [c] = harmonic_balance(L, lambda A, w: saturation_df(A, 1.0), (0.1, 10), (1.0, 100))
    >>> round(c.frequency, 4), round(c.amplitude, 3), c.stable  # w = sqrt(2); N(A) = 6/20
    (1.4142, 4.204, True)
    """
    from scipy.optimize import brentq

    lo, hi = np.log(a_range[0]), np.log(a_range[1])

    seen: dict[tuple[float, float], complex] = {}  # N at the amplitudes the last root search tried

    def n_at(a: float, w: float) -> complex:
        if (a, w) not in seen:
            seen[(a, w)] = N(a, w)
        return seen[(a, w)]

    def amplitude(w: float, tol: float = 1e-10, guess: float | None = None) -> float | None:
        target = 1.0 / abs(L(np.array([w]))[0])
        seen.clear()
        f = lambda u: abs(n_at(float(np.exp(u)), w)) - target  # noqa: E731  (in log A: |N| ~ a power of A)
        if guess is not None:  # a neighbouring frequency's amplitude: a narrow bracket around it first
            g_lo, g_hi = max(lo, np.log(guess) - 0.7), min(hi, np.log(guess) + 0.7)
            f_lo, f_hi = f(g_lo), f(g_hi)
            if f_lo >= 0 >= f_hi:
                return float(np.exp(g_lo if f_lo == 0 else brentq(f, g_lo, g_hi, xtol=tol, rtol=1e-12)))
        f_lo, f_hi = f(lo), f(hi)
        if f_lo < 0 or f_hi > 0:
            return None
        return float(np.exp(lo if f_lo == 0 else brentq(f, lo, hi, xtol=tol, rtol=1e-12)))

    def residual(w: float, tol: float = 1e-10, guess: float | None = None) -> tuple[float | None, float | None]:
        a = amplitude(w, tol, guess)
        if a is None:
            return None, None
        z = L(np.array([w]))[0] * n_at(a, w)
        return float(np.angle(-z)), a  # 0 at the balance, wrapped to (-pi, pi]

    def crossing(r0: float | None, r1: float | None) -> bool:
        return r0 is not None and r1 is not None and np.sign(r0) != np.sign(r1) and abs(r0 - r1) <= np.pi

    # the grid locates sign changes with amplitudes to 1 % (the phase barely moves with A), each from its
    # neighbour's; every bracket is then re-evaluated to full precision (and its neighbours, should a sign
    # flip with the precision) before Brent's method refines it
    ws = np.geomspace(*w_range, points)
    coarse: list[float | None] = []
    last: float | None = None
    for w in ws:
        r, last = residual(w, 1e-2, last)
        coarse.append(r)
    tight: dict[int, float | None] = {}

    def fine(i: int) -> float | None:
        if i not in tight:
            tight[i] = residual(ws[i])[0]
        return tight[i]

    refined: set[int] = set()
    found: list[PredictedCycle] = []
    for i in range(points - 1):
        if not crossing(coarse[i], coarse[i + 1]):
            continue
        for j in (i, i - 1, i + 1):
            if j in refined or not 0 <= j < points - 1 or not crossing(fine(j), fine(j + 1)):
                continue
            refined.add(j)
            # full searches, as fine(): the ends then give Brent's method the very values that bracketed
            w_star = brentq(lambda w: residual(w)[0] or 0.0, ws[j], ws[j + 1], xtol=1e-12 * ws[j + 1], rtol=1e-12)
            a_star = amplitude(w_star)
            if a_star is None:
                continue
            found.append(PredictedCycle(float(a_star), float(w_star), float(2 * np.pi / w_star),
                                        _loeb_stable(L, N, a_star, w_star)))
    return sorted(found, key=lambda c: c.frequency)


def _loeb_stable(L: Callable[[np.ndarray], np.ndarray], N: Callable[[float, float], complex], a: float,
                 w: float) -> bool:
    def F(A: float, om: float) -> complex:
        return 1.0 + L(np.array([om]))[0] * N(A, om)

    da, dw = 1e-5 * a, 1e-5 * w
    FA = (F(a + da, w) - F(a - da, w)) / (2 * da)
    Fw = (F(a, w + dw) - F(a, w - dw)) / (2 * dw)
    return bool(FA.real * Fw.imag - Fw.real * FA.imag > 0)


def sampled_loop_response(loop: Any, w: Any) -> np.ndarray:
    """Frequency response of the linear part of a sampled loop as seen by its actuator chain.

    ``L(jw) = C(e^{jw Tc}) P(e^{jw dt}) S(jw)``: the discretized controller, the exact pulse
    transfer function of the plant core (zero-order hold, delays, folded linear blocks) from the
    actuator output to the sensed output, and the sensor chain's sample-and-holds approximated by
    their mean delay ``(T_s - dt)/2`` (quantizers and noise count as identity). With the actuator
    chain's input ``x`` and output ``y`` (deviations), ``x = -L y``: a limit cycle needs
    ``1 + L N = 0``.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.loops import NonlinearLoop
    >>> loop = NonlinearLoop(Plant.from_string("10/(s+10)"), Controller("P", {"kp": 2}), dt=0.001)
    >>> abs(sampled_loop_response(loop, [1e-3])[0]).round(6)  # K G(0)
    np.float64(2.0)
    """
    return np.prod(_loop_parts(loop, w), axis=0)


def _loop_parts(loop: Any, w: Any) -> np.ndarray:
    """Rows: controller, plant core (actuator output to sensed output), sensor chain."""
    return _loop_parts_of(loop)(w)


def _loop_parts_of(loop: Any) -> Callable[[Any], np.ndarray]:
    """:func:`_loop_parts` of ``loop`` as a function of the frequencies, with the discretizations done once (a
    harmonic balance asks for one frequency at a time, hundreds of times)."""
    from synth.sim.blocks import Delay, Dynamics, SampleHold
    from synth.sim.discretize import delayed_zoh, discretize_controller, zoh
    from synth.sim.folding import fold_counts, plant_core

    dt = loop.dt
    act = [b for b in loop.actuator if not isinstance(b, Delay)]
    sen = [b for b in loop.sensor if not isinstance(b, Delay)]
    na, ns = fold_counts(act, sen)
    core = plant_core(loop.plant, act[len(act) - na:], sen[:ns], loop.operating_point)
    dz = delayed_zoh(core.A, core.B[:, 0], dt, loop.total_delay)
    n = core.A.shape[0]
    num, den = loop.controller.tf()
    tc = loop.controller_period
    Ac, Bc, Cc, Dc = discretize_controller(num, den, tc, loop.discretization)
    sensors: list[tuple[str, Any]] = []
    for b in sen[ns:]:
        if isinstance(b, SampleHold):
            sensors.append(("hold", max(0.0, 1.0 / b.rate - dt)))
        elif isinstance(b, Dynamics):
            A_, B_, C_, D_ = b.state_space()
            Ad, Bd = zoh(A_, B_[:, None], dt)
            sensors.append(("dynamics", (Ad, Bd, C_, D_)))

    def resolvent(zs: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """``(z I - A)^-1 B`` at every ``z`` (``B`` one column, or one column per ``z``), batched."""
        M = zs[:, None, None] * np.eye(A.shape[0]) - A
        rhs = np.broadcast_to(B, (zs.size, A.shape[0])) if B.ndim == 1 else B
        return np.linalg.solve(M, rhs[..., None])[..., 0]

    def parts(w: Any) -> np.ndarray:
        w = np.atleast_1d(np.asarray(w, float))
        z = np.exp(1j * w * dt)
        zc = np.exp(1j * w * tc)
        shift = z ** (-dz.steps - 1)
        if n:
            X = resolvent(z, dz.Ad, dz.B_early[None, :] + dz.B_late[None, :] * z[:, None])
            P = (X @ core.C[1]) * shift + core.D[1, 0] * shift
        else:
            P = core.D[1, 0] * shift
        C = Dc + (resolvent(zc, Ac, Bc) @ Cc if Ac.size else 0.0)
        S = np.ones(w.size, complex)
        for kind, data in sensors:
            if kind == "hold":
                S = S * np.exp(-1j * w * data / 2)
            else:
                Ad, Bd, C_, D_ = data
                S = S * (D_ + (resolvent(z, Ad, Bd[:, 0]) @ C_ if Ad.size else 0.0))
        out = np.empty((3, w.size), complex)
        out[0], out[1], out[2] = C, P, S
        return out

    return parts


@dataclass(frozen=True)
class LoopCyclePrediction:
    """Harmonic-balance prediction for a sampled loop (see :func:`predict_loop_cycles`).

    Attributes
    ----------
    cycle : PredictedCycle
        Amplitude at the actuator chain's input, frequency, period, stability.
    output_amplitude : float
        Fundamental amplitude of the sensed output it implies: ``A |N| |P|``.
    bias : float
        Actuator chain input about which the describing function was taken.
    """

    cycle: PredictedCycle
    output_amplitude: float
    bias: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict.

        Examples
        --------
        >>> LoopCyclePrediction(PredictedCycle(1.0, 2.0, 3.1, True), 0.5, 200.0).to_dict()["bias"]
        200.0
        """
        return {**self.cycle.to_dict(), "output_amplitude": self.output_amplitude, "bias": self.bias}


def predict_loop_cycles(loop: Any, bias: float, w_range: tuple[float, float] | None = None,
                        a_range: tuple[float, float] = (1e-2, 1e4),
                        points: int = 120) -> list[LoopCyclePrediction]:
    """Limit cycles of a sampled loop predicted with the describing function of its actuator chain.

    The actuator chain's describing function is computed by simulation about ``bias`` (its
    input at rest, e.g. the trim plus the controller's steady output), so asymmetric limits such
    as 0-255 PWM around 222 PWM are handled in the fundamental (not the bias shift).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.loops import NonlinearLoop
    >>> from synth.sim.blocks import Saturation
    >>> loop = NonlinearLoop(Plant.from_string("1/(s*(s+1)*(s+2))"), Controller("P", {"kp": 20}),
    ...                      actuator=[Saturation(-1, 1)], dt=0.001)
    >>> [p] = predict_loop_cycles(loop, 0.0, (0.5, 5.0), points=40)
    >>> round(p.cycle.frequency, 2), round(p.cycle.amplitude, 1)  # continuous: 1.41 rad/s, 4.2
    (1.41, 4.2)
    """
    from synth.sim.blocks import Delay

    chain = [b for b in loop.actuator if not isinstance(b, Delay) and not b.linear]
    if not chain:
        return []
    hi = np.pi / loop.dt
    w_range = w_range or (1e-2 * hi, 0.999 * hi)

    def N(a: float, w: float) -> complex:
        return numeric_df(chain, a, w, bias=bias, points=160, periods=8)

    parts = _loop_parts_of(loop)

    def L(w: np.ndarray) -> np.ndarray:
        return np.prod(parts(w), axis=0)

    out = []
    for c in harmonic_balance(L, N, w_range, a_range, points):
        _, P, S = parts([c.frequency])[:, 0]
        gain = abs(N(c.amplitude, c.frequency)) * abs(P * S)
        out.append(LoopCyclePrediction(c, float(c.amplitude * gain), bias))
    return out
