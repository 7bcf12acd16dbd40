"""Has a limit cycle reached its own steady state? Its centre and the controller's command over whole cycles.

:func:`synth.sim.verdict.judge` calls a regular oscillation a limit cycle only when, besides its amplitude and
period, the output's centre and the controller's command stopped moving one way (:func:`centre_drift`).
"""

from __future__ import annotations

import numpy as np

from synth.sim.limitcycle import cycle_table

__all__ = ["STEADY", "centre_drift"]

STEADY = 0.01
"""Largest relative change of amplitude and period between the last three quarters of a limit cycle, and of its
centre and the controller's command over whole cycles (as a share of their half range)."""


def centre_drift(ta: np.ndarray, ya: np.ndarray, signal: np.ndarray, name: str) -> str | None:
    """Why the cycle over the last three quarters of ``ta`` has not reached its own steady state, or None.

    The mean of ``signal`` over each quarter's whole cycles of the output ``ya`` (delimited as
    :func:`synth.sim.limitcycle.cycle_table` delimits them) moves one way by more than :data:`STEADY` of the
    signal's half range over the last quarter, and not so geometrically that the rest of the way is within that. A
    periodic state repeats the controller's command and the output's centre; a command still winding towards a
    block's threshold ends the cycle there (a relay-and-backlash loop chattered for 6.6 s, then rested), and a
    centre still settling put a cycle's centre at 3.7 instead of 4.1.

    Examples
    --------
    >>> t = np.arange(0.0, 30.0, 0.01)
    >>> centre_drift(t, np.sin(2 * np.pi * t), np.sin(2 * np.pi * t), "output") is None
    True
    >>> y = np.sin(2 * np.pi * t) + 0.02 * t  # a centre that keeps moving
    >>> centre_drift(t, y, y, "output")[:55]
    "the output's mean over whole cycles still moves one way"
    """
    span = ta[-1] - ta[0]
    keep = ta >= ta[-1] - 0.75 * span
    starts, _ = cycle_table(ta[keep], ya[keep])
    means = []
    for k in (3, 2, 1):
        lo, hi = ta[-1] - k * span / 4, ta[-1] - (k - 1) * span / 4 + 1e-12
        inside = starts[(starts >= lo) & (starts <= hi)]
        if inside.size < 2:
            return None
        means.append(float(np.mean(signal[(ta >= inside[0]) & (ta < inside[-1])])))
    last = ta >= ta[-1] - span / 4
    half = 0.5 * float(np.ptp(signal[last]))
    d1, d2 = means[1] - means[0], means[2] - means[1]
    if not (half > 0 and d1 * d2 > 0 and abs(d2) > STEADY * half):
        return None
    r = d2 / d1
    rest = abs(d2) * r / (1.0 - r) if r < 0.8 else float("inf")
    if rest <= STEADY * half:
        return None
    return (f"the {name}'s mean over whole cycles still moves one way ({means[0]:.4g}, {means[1]:.4g}, "
            f"{means[2]:.4g} over the last three quarters: {100 * abs(d2) / half:.2g} % of its half range in the "
            f"last), so the cycle has not reached its own steady state")
