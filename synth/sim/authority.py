"""A settled output that does not reach the reference: the actuator rests on its saturation (or another block holds
it) for good.

A saturation holds for ever once the controller's command moves away from its limit (:mod:`synth.sim.holding`):
the output stands still and the step is settled, but where the limit is too low for the reference, it stands short
of it while an integrator winds the command up without end (``1/(s+1)``, saturation at 1, step to 2, PI: the output
rests at 1 and the command climbs at 2 units/s). The rise, overshoot and settling measured towards that final value
would call such a step fine; :func:`short_of_reference` says what it is.
"""

from __future__ import annotations

import numpy as np

from synth.requirements.base import fmt
from synth.sim.results import SimResult

__all__ = ["SHORT_SHARE", "STILL", "output_still", "short_of_reference"]

SHORT_SHARE = 0.02
"""A settled output on a saturation this far from the reference, as a share of the step, or farther, is short of it
(the settling band's default)."""


def short_of_reference(result: SimResult, t_step: float, step: tuple[float, float]) -> str | None:
    """Why a settled run does not reach the reference (None when it does, or when no actuator block holds it): the
    output rests at least :data:`SHORT_SHARE` of the step from the reference over the last quarter after the step
    while a saturation is active throughout, or while the actuator's output (behind its blocks) stands still (a
    relay's or table's flat end, a backlash gap or dead zone the command does not leave; an output that never
    moved says so).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.blocks import Saturation
    >>> from synth.sim.loops import NonlinearLoop
    >>> from synth.sim.simulator import simulate_step
    >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("PI", {"kp": 1, "ki": 2}),
    ...                      actuator=[Saturation(-1, 1)])
    >>> short_of_reference(simulate_step(loop, 0, 2, 20.0), 0.0, (0, 2))[:58]
    'the output rests 50 % of the step short of the reference 2'
    >>> short_of_reference(simulate_step(loop, 0, 0.5, 20.0), 0.0, (0, 0.5)) is None
    True
    """
    size = float(step[1] - step[0])
    after = np.flatnonzero(result.t >= t_step)
    if size == 0.0 or after.size < 8:
        return None
    tail = after[-max(2, after.size // 4):]
    reference, output = float(result.reference[-1]), float(np.mean(result.output[tail]))
    short = (reference - output) / size
    if abs(short) < SHORT_SHARE:
        return None
    rests = (f"the output rests {100 * abs(short):.3g} % of the step {'short of' if short > 0 else 'beyond'} the "
             f"reference {fmt(reference)} (at {fmt(output)})")
    def rate() -> float:  # how fast the controller's command winds over the tail (input units/s)
        return float(np.polyfit(result.t[tail], result.command[tail], 1)[0])

    if np.all(result.active("saturated")[tail]):
        return (f"{rests}: the actuator sits on its saturation ({fmt(float(result.actuator[-1]))}) for good, the "
                f"controller's command moving at {rate():.3g} input units/s")
    if not result.actuator_blocks or np.ptp(result.actuator[tail]) > 0.0:
        return None  # a loop that follows its command there: its own steady-state error, not a block's hold
    if output_still(result.output[after], float(result.output[after[0]]), size):
        return (f"{rests}: it did not move, the actuator's output stayed at {fmt(float(result.actuator[-1]))} (the "
                "controller's command stayed inside what the actuator's blocks hold)")
    if np.ptp(result.command[tail]) == 0.0:
        return None  # the command rests too (a P controller's own steady-state error under a still reading)
    return (f"{rests}: the actuator's output stands still at {fmt(float(result.actuator[-1]))} for good (an actuator "
            f"block holds it there, e.g. the flat end of a table), the controller's command moving at {rate():.3g} "
            "input units/s")


STILL = 1e-9
"""An output whose every value after the step is within this share of the larger of the step and its own size
from where it started did not move (what is left is rounding)."""


def output_still(y: np.ndarray, y0: float, size: float) -> bool:
    """Whether the output ``y`` after a step of ``size`` never left its value ``y0`` at the step (:data:`STILL`).

    Examples
    --------
    >>> output_still(np.array([0.3564, 0.3564 + 7e-14]), 0.3564, -0.22), output_still(np.array([0.0, 0.1]), 0.0, 1.0)
    (True, False)
    """
    scale = max(abs(size), abs(y0), float(np.max(np.abs(y))) if y.size else 0.0)
    return bool(np.all(np.abs(y - y0) <= STILL * scale))
