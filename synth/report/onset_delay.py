"""The in-loop delay at which a proportional gain reaches the onset of oscillation: interpolated in the onset
table of the nonlinear simulation, and exactly on the continuous linear model (its delay margin)."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["delay_for_gain", "exact_delay_for_gain"]


def exact_delay_for_gain(plant: Any, loop_delay: float, k: float) -> float | None:
    """The in-loop delay (beyond ``loop_delay``) at which P(``k``) on the continuous ``plant`` reaches the stability
    boundary: its exact delay margin, ``min PM/wc`` over the gain crossovers (None if that loop is not stable).
    Interpolated between the onset table's delays it was 14.54 ms for the X-4's K = 5, exactly 14.44 ms.

    Examples
    --------
    >>> from synth.plant import Plant
    >>> round(1000 * exact_delay_for_gain(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), 0.0, 5.0), 3)
    14.445
    """
    from synth.controllers import Controller
    from synth.loop import Loop

    loop = Loop(plant.with_delay(plant.delay + loop_delay), Controller("P", {"kp": float(k)}))
    return float(loop.margins().delay_margin) if loop.stability().stable else None


def delay_for_gain(delays: np.ndarray, gains: np.ndarray, k: float) -> float | None:
    """In-loop delay at which the onset gain falls to ``k`` (interpolated in log gain; None where it does not).

    Examples
    --------
    >>> round(delay_for_gain(np.array([0.0, 0.01]), np.array([10.0, 2.5]), 5.0), 4)
    0.005
    """
    for i in range(len(delays) - 1):
        a, b = gains[i], gains[i + 1]
        if a >= k >= b and np.isfinite(b):
            if not np.isfinite(a):
                return None
            if a == b:
                return float(delays[i])
            f = (np.log(a) - np.log(k)) / (np.log(a) - np.log(b))
            return float(delays[i] + f * (delays[i + 1] - delays[i]))
    return None
