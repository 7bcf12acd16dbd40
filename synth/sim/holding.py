"""Is a still output an equilibrium? Behind an actuator block that holds its output while its input moves
(a dead zone, a backlash gap, a quantization step, the flat piece of a relay-like table, a saturation), an
output can stand still while the controller's integrator winds; the loop moves again once the command
leaves the held range. :func:`winding_behind` tells the step verdict when a still output is such a pause
rather than a settled state (the verdict then waits for more of the run).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from synth.sim.results import SimResult

__all__ = ["HOLDING_BLOCKS", "first_block_holds_for_a_while", "winding_behind"]


HOLDING_BLOCKS = ("dead_zone", "backlash", "quantizer")
"""Actuator blocks that hold their output while their input moves over a finite range only (inside a dead
zone, in the gap of a backlash, within a quantization step). Behind one, a still output is no equilibrium
while the controller's command keeps moving (an integrator winding up): the command leaves the held range
and the output moves again. A saturation, or a table on a flat piece, holds for ever when the command moves
away from where its output changes: winding up there, the output is settled."""


def first_block_holds_for_a_while(block: Any, u: float, du: float) -> bool | None:
    """Whether the first actuator block, seeing the command ``u`` drifting by ``du``, holds its output only
    until the command reaches a point where it changes (True), for ever (False), or does not hold (None).

    Examples
    --------
    >>> from synth.sim.blocks import Saturation, Static
    >>> relay = Static([(-1e3, -1.0), (-1e-3, -1.0), (1e-3, 1.0), (1e3, 1.0)])
    >>> first_block_holds_for_a_while(relay, 2.0, -0.1), first_block_holds_for_a_while(relay, 2.0, 0.1)
    (True, True)
    >>> sat = Saturation(-1, 1)
    >>> first_block_holds_for_a_while(sat, 2.0, 0.1), first_block_holds_for_a_while(sat, 2.0, -0.1)
    (False, True)
    """
    if block.kind == "saturation":
        if u > block.max:
            return du < 0
        if u < block.min:
            return du > 0
        return None
    if block.kind == "static":
        xs = np.array([a for a, _ in block.table])
        ys = np.array([b for _, b in block.table])
        k = int(np.clip(np.searchsorted(xs, u) - 1, 0, xs.size - 2))
        if ys[k + 1] != ys[k]:  # on a sloped piece (or its extension): the output follows the command
            return None
        ahead = xs[xs > u] if du > 0 else xs[xs < u]
        return bool(ahead.size)  # a breakpoint in the drift's way ends the flat piece
    return True if block.kind in HOLDING_BLOCKS else None


def winding_behind(result: SimResult, after: np.ndarray, span: float, actuator: Sequence[Any],
                   shrink: float = 0.75) -> str | None:
    """Why a still output is not settled: the controller's command keeps moving over the last eighth (at
    least ``shrink``, :data:`synth.sim.verdict.SHRINK`, times its motion over the eighth before: not dying
    out) while an actuator block holds the output only for a while: the first block on a flat piece with a breakpoint in the
    command's way (a relay-like table), or past a saturation limit drifting back, or a dead zone or backlash
    flagged active, or a quantizer, with no saturation active for ever. None otherwise.

    Examples
    --------
    A PI loop whose integrator winds in a dead zone (the output held, the command ramping):

    >>> from synth.sim.blocks import DeadZone
    >>> from synth.sim.results import SimResult
    >>> t = np.linspace(0.0, 8.0, 801)
    >>> r = SimResult(t, np.ones_like(t), np.zeros_like(t), np.zeros_like(t), 0.1 * t, np.zeros_like(t),
    ...               np.ones(t.size, np.int32), 0.01, ["dead_zone"], [], ["in_dead_zone"], [])
    >>> winding_behind(r, t >= 0, 8.0, [DeadZone(width=5.0)])[:40]
    'the output stands still but the controll'
    """
    if not actuator or result.command.shape != result.t.shape:
        return None
    t, u = result.t[after], result.command[after]
    eighth = t >= t[-1] - span / 8
    before = (t >= t[-1] - span / 4) & ~eighth
    late, early = float(np.ptp(u[eighth])), float(np.ptp(u[before]))
    if late <= 1e-9 * (float(np.max(np.abs(u))) + 1e-300) or late <= shrink * early:
        return None
    end = int(result.flags[-1]) if result.flags.size else 0
    du = float(u[-1] - u[eighth][0])
    first = first_block_holds_for_a_while(actuator[0], float(u[-1]), du)
    if first is False:
        return None
    flagged = actuator[0].kind not in ("dead_zone", "backlash") or bool(end & 1)  # inside its zone or gap
    held = [actuator[0].kind] if first and flagged else []
    for i, b in enumerate(actuator[1:], start=1):
        active = bool(end >> i & 1)
        if b.kind == "saturation" and active:
            return None  # a later saturation holds for ever (its input's direction is not known here)
        if b.kind == "quantizer" or (b.kind in HOLDING_BLOCKS and active):
            held.append(b.kind)
    if not held:
        return None
    return (f"the output stands still but the controller's command moved {late:.3g} over the last eighth "
            f"({late / max(early, 1e-300):.2g} times the eighth before, not dying out): it winds behind the "
            f"{held[0].replace('_', ' ')}, which holds the output only until the command reaches where it "
            "changes; not an equilibrium")
