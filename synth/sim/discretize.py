"""Exact zero-order-hold discretization with a fractional input delay, and controller discretization.

For ``x' = A x + B w`` with ``w`` piecewise constant on steps of ``dt`` and
delayed by ``d = m dt + f`` (``0 <= f < dt``), the input over
``[k dt, k dt + f)`` is ``w_{k-m-1}`` and over ``[k dt + f, (k+1) dt)`` it is
``w_{k-m}``, so exactly

``x_{k+1} = e^{A dt} x_k + e^{A (dt - f)} G(f) w_{k-m-1} + G(dt - f) w_{k-m}``,
``G(h) = int_0^h e^{A s} ds B``.

Both matrices come from one matrix exponential of ``[[A, B], [0, 0]] h``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm
from scipy.signal import cont2discrete, tf2ss

from synth.errors import ModelError

__all__ = ["DISCRETIZATIONS", "DelayedZOH", "delayed_zoh", "discretize_controller", "tf_to_ss", "zoh"]

DISCRETIZATIONS = {
    "tustin": "bilinear",
    "zoh": "zoh",
    "backward_euler": "backward_diff",
    "forward_euler": "euler",
}
"""Controller discretization methods (spec name -> scipy ``cont2discrete`` method)."""


def tf_to_ss(num: np.ndarray, den: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """State space ``(A, B, C, D)`` of a proper SISO transfer function; ``B`` is a vector.

    Examples
    --------
    >>> A, B, C, D = tf_to_ss(np.array([2.0]), np.array([1.0, 3.0]))
    >>> A.tolist(), B.tolist(), C.tolist(), D
    ([[-3.0]], [1.0], [2.0], 0.0)
    """
    num = np.atleast_1d(np.asarray(num, float))
    den = np.atleast_1d(np.asarray(den, float))
    if den.size == 1:
        return np.zeros((0, 0)), np.zeros(0), np.zeros(0), float(num[-1] / den[0])
    A, B, C, D = tf2ss(num, den)
    return A, B[:, 0], C[0], float(D[0, 0])


def zoh(A: np.ndarray, B: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """``(e^{A h}, int_0^h e^{A s} ds B)`` for ``B`` with one column per input.

    Examples
    --------
    >>> Ad, Gd = zoh(np.array([[-1.0]]), np.array([[1.0]]), np.log(2.0))
    >>> float(Ad[0, 0]), round(float(Gd[0, 0]), 12)
    (0.5, 0.5)
    """
    n = A.shape[0]
    B = np.asarray(B, float).reshape(n, -1)
    if n == 0:
        return np.zeros((0, 0)), np.zeros((0, B.shape[1]))
    if h == 0.0:
        return np.eye(n), np.zeros_like(B)
    M = np.zeros((n + B.shape[1], n + B.shape[1]))
    M[:n, :n] = A * h
    M[:n, n:] = B * h
    E = expm(M)
    return E[:n, :n], E[:n, n:]


@dataclass(frozen=True)
class DelayedZOH:
    """Discrete model of ``x' = A x + B w`` with ``w`` delayed by ``steps * dt + fraction``.

    Attributes
    ----------
    Ad : ndarray
        ``e^{A dt}``.
    B_early : ndarray
        Multiplies ``w_{k-m-1}`` (zero when the delay is a whole number of steps).
    B_late : ndarray
        Multiplies ``w_{k-m}``.
    steps : int
        ``m``, the whole steps of delay.
    fraction : float
        ``f`` in seconds, ``0 <= f < dt``.
    """

    Ad: np.ndarray
    B_early: np.ndarray
    B_late: np.ndarray
    steps: int
    fraction: float


def delayed_zoh(A: np.ndarray, B: np.ndarray, dt: float, delay: float) -> DelayedZOH:
    """Exact ZOH discretization of one input delayed by ``delay`` seconds (any real value >= 0).

    Examples
    --------
    >>> d = delayed_zoh(np.array([[-1.0]]), np.array([1.0]), 0.1, 0.25)
    >>> d.steps, round(d.fraction, 12)
    (2, 0.05)
    """
    if delay < 0 or not np.isfinite(delay):
        raise ModelError(f"delay must be a finite number >= 0 s, got {delay!r}")
    steps = int(np.floor(delay / dt + 1e-9))
    fraction = delay - steps * dt
    if fraction < 1e-9 * dt:
        fraction = 0.0
    Ad, G = zoh(A, B, dt)
    if fraction == 0.0:
        return DelayedZOH(Ad, np.zeros_like(G[:, 0]), G[:, 0], steps, 0.0)
    A_rest, G_late = zoh(A, B, dt - fraction)
    _, G_f = zoh(A, B, fraction)
    return DelayedZOH(Ad, (A_rest @ G_f)[:, 0], G_late[:, 0], steps, fraction)


def discretize_controller(num: np.ndarray, den: np.ndarray, period: float,
                          method: str = "tustin") -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Discrete state space ``(Ac, Bc, Cc, Dc)`` of a controller sampled every ``period`` s.

    ``method``: ``tustin`` (bilinear), ``zoh``, ``backward_euler`` or ``forward_euler``.

    Examples
    --------
    >>> Ac, Bc, Cc, Dc = discretize_controller(np.array([2.0, 10.0]), np.array([1.0, 0.0]), 0.01,
    ...                                        "backward_euler")
    >>> float(Ac[0, 0]), round(Dc, 6)  # PI(kp=2, ki=10): integrator, kp + ki T
    (1.0, 2.1)
    """
    if method not in DISCRETIZATIONS:
        raise ModelError(f"unknown controller discretization {method!r}; expected one of: "
                         f"{', '.join(DISCRETIZATIONS)}")
    A, B, C, D = tf_to_ss(num, den)
    if A.size == 0:
        return A, B, C, D
    Ad, Bd, Cd, Dd, _ = cont2discrete((A, B[:, None], C[None, :], np.array([[D]])), period,
                                      method=DISCRETIZATIONS[method])
    return np.asarray(Ad), np.asarray(Bd)[:, 0], np.asarray(Cd)[0], float(np.asarray(Dd)[0, 0])
