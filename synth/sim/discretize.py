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

from synth.errors import ModelError
from synth.statespace import generalized_bilinear, tf_to_ss, zoh

__all__ = ["DISCRETIZATIONS", "DelayedZOH", "delayed_zoh", "discretize_controller", "tf_to_ss", "zoh"]

DISCRETIZATIONS = {
    "tustin": 0.5,
    "zoh": None,
    "backward_euler": 1.0,
    "forward_euler": 0.0,
}
"""Controller discretization methods: spec name -> the ``alpha`` of the generalized bilinear transform
(:func:`synth.statespace.generalized_bilinear`; ``None``: zero-order hold, exact for a held input)."""


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
    alpha = DISCRETIZATIONS[method]
    if alpha is None:
        Ad, Bd = zoh(A, B, period)
        return Ad, Bd[:, 0], C, D
    return generalized_bilinear(A, B, C, D, period, alpha)
