"""A digital PI loop simulated by scipy, the truth of the diagnosis tests (not synth's simulator)."""

from __future__ import annotations

import numpy as np
from scipy.signal import cont2discrete, tf2ss


def digital_pi_loop(num, den, kp: float, ki: float, r: np.ndarray, noise: np.ndarray, dt: float,
                    lower: float = -np.inf, upper: float = np.inf,
                    delay_samples: int = 0, integrate_after: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """A PI at ``dt`` around the continuous plant ``num/den`` (exact zero-order hold), its measurement ``noise`` fed
    back, the plant driven by the command limited to ``[lower, upper]`` and ``delay_samples`` samples late (the
    integral updated before the command, or with ``integrate_after`` after it); returns the logged command (the
    controller's output, before the limits: a wound-up integrator) and the measured output."""
    A, B, C, D = tf2ss(num, den)
    Ad, Bd, Cd, _, _ = cont2discrete((A, B, C, D), dt, method="zoh")
    x, integral = np.zeros(A.shape[0]), 0.0
    u, y = np.zeros(r.size), np.zeros(r.size)
    for k in range(r.size):
        y[k] = (Cd @ x).item() + noise[k]
        e = r[k] - y[k]
        integral += 0.0 if integrate_after else ki * dt * e
        u[k] = kp * e + integral
        integral += ki * dt * e if integrate_after else 0.0
        late = u[k - delay_samples] if k >= delay_samples else 0.0
        x = Ad @ x + Bd.ravel() * min(max(late, lower), upper)
    return u, y
