"""An exact first-order reference for identification tests, written apart from synth's simulation code."""

from __future__ import annotations

import numpy as np


def first_order_held(t: np.ndarray, u: np.ndarray, gain: float, tau: float, y0: float = 0.0) -> np.ndarray:
    """``gain / (tau s + 1)`` driven by ``u`` held from each time stamp to the next (zero-order hold), exact on the
    (possibly uneven) stamps ``t``, from ``y0``.

    Examples
    --------
    >>> y = first_order_held(np.array([0.0, 1.0, 3.0]), np.ones(3), 2.0, 1.0)
    >>> np.round(y, 6).tolist()
    [0.0, 1.264241, 1.900426]
    """
    y = np.empty(t.size)
    y[0] = y0
    decay = np.exp(-np.diff(t) / tau)
    for k in range(1, t.size):
        y[k] = decay[k - 1] * y[k - 1] + (1 - decay[k - 1]) * gain * u[k - 1]
    return y


def square_wave(half: float, edges: int, first: float, dt: float, low: float = 1.0,
                high: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """Time stamps ``dt`` apart and a square wave between ``low`` and ``high``: ``low`` until ``first``, then
    ``edges`` edges ``half`` apart.

    Examples
    --------
    >>> t, u = square_wave(0.2, 3, 0.1, 0.1)
    >>> u.tolist()
    [1.0, 2.0, 2.0, 1.0, 1.0, 2.0, 2.0]
    """
    t = np.arange(0.0, first + edges * half, dt)
    u = np.where(t < first - 1e-9, low, np.where(((t - first + 1e-9) // half) % 2 == 0, high, low))
    return t, u
