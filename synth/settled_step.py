"""A closed loop's unit step over a horizon long enough to show it settle, for the reports' step numbers and figure.

:func:`synth.timeresp.default_horizon` (12 time constants of the fastest dominant pole, at least 20 delays) cuts a
loop whose slow pole or lightly damped mode outlasts it: a PID on a lightly damped plant behind 20 ms was drawn and
measured over 0.4 s, still rising at 0.27 (overshoot 0, no rise time; the loop overshoots 39 % and rises in 0.61 s).
"""

from __future__ import annotations

import numpy as np

from synth.loop import Loop
from synth.timeresp import default_horizon, step_metrics, step_response

__all__ = ["MAX_DOUBLINGS", "MAX_SAMPLES", "settled_step"]

MAX_DOUBLINGS = 8
"""Most doublings of the default horizon (256 times it)."""
MAX_SAMPLES = 32001
"""Most output samples of the longer runs (which keep the first run's 2001 samples' spacing up to this)."""


def settled_step(loop: Loop, settle_band: float = 0.02) -> tuple[np.ndarray, np.ndarray, float]:
    """``(t, y, dt)`` of :func:`synth.timeresp.step_response` over the default horizon doubled until the response
    settles (its settling time within the first three quarters of the horizon), at most :data:`MAX_DOUBLINGS` times;
    a loop that does not settle (unstable, or marginal) keeps the default horizon.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("50/((s^2+0.5*s+25)*(s+1))", delay=0.02),
    ...             Controller("PID", {"kp": 0.108773, "ki": 1.86075, "kd": 0.0856148, "tf": 0.01}))
    >>> default_horizon(loop), float(settled_step(loop)[0][-1])  # s
    (0.4, 12.8)
    >>> t, y, _ = settled_step(loop)
    >>> m = step_metrics(t, y, y_final=loop.dc_gain()); round(m.overshoot, 1), round(m.rise_time, 3)
    (39.3, 0.613)
    """
    horizon = default_horizon(loop)
    first = step_response(loop, horizon)
    if not loop.stability().stable:
        return first
    run = first
    for _ in range(MAX_DOUBLINGS):
        t, y, _ = run
        settling = step_metrics(t, y, y_final=loop.dc_gain(), settle_band=settle_band).settling_time
        if np.isfinite(settling) and settling <= 0.75 * t[-1]:
            return run
        horizon *= 2.0
        samples = min(2000 * round(horizon / float(first[0][-1])), MAX_SAMPLES - 1) + 1  # the first's spacing, at most
        run = step_response(loop, horizon, samples)
    return run
