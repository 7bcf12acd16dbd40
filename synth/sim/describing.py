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
from scipy.optimize import brentq

from synth.errors import ModelError


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
    a_lo, a_hi = a_range

    def amplitude(w: float) -> float | None:
        target = 1.0 / abs(L(np.array([w]))[0])
        f = lambda a: abs(N(a, w)) - target  # noqa: E731
        f_lo, f_hi = f(a_lo), f(a_hi)
        if f_lo < 0 or f_hi > 0:
            return None
        if f_lo == 0:
            return a_lo
        return brentq(f, a_lo, a_hi, xtol=1e-12 * a_hi, rtol=1e-12)

    def residual(w: float) -> float | None:
        a = amplitude(w)
        if a is None:
            return None
        z = L(np.array([w]))[0] * N(a, w)
        return float(np.angle(-z))  # 0 at the balance, wrapped to (-pi, pi]

    ws = np.geomspace(*w_range, points)
    res = [residual(w) for w in ws]
    found: list[PredictedCycle] = []
    for i in range(points - 1):
        r0, r1 = res[i], res[i + 1]
        if r0 is None or r1 is None or np.sign(r0) == np.sign(r1) or abs(r0 - r1) > np.pi:
            continue
        w_star = brentq(lambda w: residual(w) or 0.0, ws[i], ws[i + 1], xtol=1e-12 * ws[i + 1], rtol=1e-12)
        a_star = amplitude(w_star)
        if a_star is None:
            continue
        found.append(PredictedCycle(float(a_star), float(w_star), float(2 * np.pi / w_star),
                                    _loeb_stable(L, N, a_star, w_star)))
    return found


def _loeb_stable(L: Callable[[np.ndarray], np.ndarray], N: Callable[[float, float], complex], a: float,
                 w: float) -> bool:
    def F(A: float, om: float) -> complex:
        return 1.0 + L(np.array([om]))[0] * N(A, om)

    da, dw = 1e-5 * a, 1e-5 * w
    FA = (F(a + da, w) - F(a - da, w)) / (2 * da)
    Fw = (F(a, w + dw) - F(a, w - dw)) / (2 * dw)
    return bool(FA.real * Fw.imag - Fw.real * FA.imag > 0)
