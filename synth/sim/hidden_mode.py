"""Is a still output an equilibrium when the loop's linear part is not stable? A controller pole cancelled by a
plant zero (a PI's integrator on a plant with a zero at the origin, ``s/(s+1)^2``) is a closed-loop root the output
does not see: the output settles while the controller's command ramps or grows without bound. The exact linear
analysis (:func:`synth.sim.horizon.plan_horizon`) finds the root; :func:`hidden_drift` tells the step verdict when
the simulated command shows it, so that such a run is not called settled.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.sim.results import SimResult

__all__ = ["NOT_SHRINKING", "HiddenDrift", "hidden_drift", "unseen_root"]

NOT_SHRINKING = 0.98
"""Smallest ratio of the command's motion over the last eighth of a run to that over the eighth before for the
command to count as not dying out (a ramp: 1; a mode decaying with a time constant longer than six runs: above
0.98)."""


@dataclass(frozen=True)
class HiddenDrift:
    """The controller's command moving under a still output.

    Attributes
    ----------
    motion : float
        Peak-to-peak motion of the command over the last eighth of the run (input units).
    ratio : float
        That motion over the one of the eighth before.
    rate : float
        Mean rate of the command over the last eighth (input units per second).
    """

    motion: float
    ratio: float
    rate: float

    def text(self) -> str:
        """The verdict's criterion."""
        return (f"the output stands still but the controller's command moves at {self.rate:.3g} input units/s "
                f"({self.ratio:.3g} times its motion over the eighth before: not dying out) and the linear closed "
                "loop has a root on or right of the imaginary axis: a mode the output does not see (a controller "
                "pole cancelled by a plant zero), not an equilibrium")


def unseen_root(loop: Any, linear_stable: bool | None = None) -> bool:
    """Whether the loop has linear blocks only and its closed loop a root on or right of the imaginary axis
    (``linear_stable`` when known, else :func:`synth.sim.horizon.linear_loop_stable`). With a nonlinear block the
    linear analysis does not decide: a saturation or a relay's flat piece holds the output while an integrator
    winds (:mod:`synth.sim.holding`).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.loops import NonlinearLoop
    >>> from synth.sim.blocks import Saturation
    >>> pi, plant = Controller("PI", {"kp": 1, "ki": 1}), Plant.from_string("s/(s+1)^2")
    >>> unseen_root(NonlinearLoop(plant, pi)), unseen_root(NonlinearLoop(plant, pi, actuator=[Saturation(-5, 5)]))
    (True, False)
    """
    if any(not b.linear for b in (*loop.actuator, *loop.sensor)):
        return False
    if linear_stable is None:
        from synth.sim.horizon import linear_loop_stable

        linear_stable = linear_loop_stable(loop)
    return not linear_stable


def hidden_drift(result: SimResult, after: np.ndarray, span: float) -> HiddenDrift | None:
    """The command's drift over the last eighth of the run when it does not die out (its motion at least
    :data:`NOT_SHRINKING` times that over the eighth before, and above the numerical floor) with no actuator block
    active at the end (the command reaches the plant as it is); None otherwise. Called only where the linear loop
    is not stable and the output has passed the settled rules (:func:`unseen_root`).

    Examples
    --------
    A command ramping at 0.5 per second under a still output (the PI on ``s/(s+1)^2``):

    >>> t = np.linspace(0.0, 20.0, 2001)
    >>> r = SimResult(t, np.ones_like(t), np.full_like(t, 0.5), np.full_like(t, 0.5), 1 + 0.5 * t, 1 + 0.5 * t,
    ...               np.zeros(t.size, np.int32), 0.01, [], [], [], [])
    >>> d = hidden_drift(r, t >= 0, 20.0)
    >>> round(d.rate, 3), round(d.ratio, 3)
    (0.5, 1.0)
    >>> decaying = SimResult(t, np.ones_like(t), np.full_like(t, 0.5), np.full_like(t, 0.5), np.exp(-t / 5),
    ...                      np.exp(-t / 5), np.zeros(t.size, np.int32), 0.01, [], [], [], [])
    >>> hidden_drift(decaying, t >= 0, 20.0) is None  # dying out: 0.61 of the eighth before
    True
    """
    if result.command.shape != result.t.shape or (result.flags.size and int(result.flags[-1]) != 0):
        return None
    t, u = result.t[after], result.command[after]
    eighth = t >= t[-1] - span / 8
    before = (t >= t[-1] - span / 4) & ~eighth
    if eighth.sum() < 2 or before.sum() < 2:
        return None
    late, early = float(np.ptp(u[eighth])), float(np.ptp(u[before]))
    if late <= 1e-9 * (float(np.max(np.abs(u))) + 1e-300) or late < NOT_SHRINKING * early:
        return None
    te, ue = t[eighth], u[eighth]
    return HiddenDrift(late, late / max(early, 1e-300), float((ue[-1] - ue[0]) / max(te[-1] - te[0], 1e-300)))
