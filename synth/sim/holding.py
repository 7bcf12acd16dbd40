"""Is a still output an equilibrium? Behind an actuator block that holds its output while its input moves
(a dead zone, a backlash gap, a quantization step, the flat piece of a relay-like table, a saturation), an
output can stand still while the controller's integrator winds; the loop moves again once the command
leaves the held range. :func:`winding_behind` tells the step verdict when a still output is such a pause
rather than a settled state (the verdict then waits for more of the run).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.sim.results import SimResult

__all__ = ["HOLDING_BLOCKS", "Winding", "first_block_holds_for_a_while", "held_range", "memoryless_output",
           "winding_behind"]


HOLDING_BLOCKS = ("dead_zone", "backlash", "quantizer")
"""Actuator blocks that hold their output while their input moves over a finite range only (inside a dead
zone, in the gap of a backlash, within a quantization step). Behind one, a still output is no equilibrium
while the controller's command keeps moving (an integrator winding up): the command leaves the held range
and the output moves again. A saturation, or a table on a flat piece, holds for ever when the command moves
away from where its output changes: winding up there, the output is settled."""


def first_block_holds_for_a_while(block: Any, u: float, du: float) -> bool | None:
    """Whether the first actuator block, seeing the command ``u`` drifting by ``du``, holds its output only
    until the command reaches a point where it changes (True: :func:`held_range` is finite), for ever (False), or
    does not hold (None).

    Examples
    --------
    >>> from synth.sim.blocks import Saturation, Static
    >>> relay = Static([(-1e3, -1.0), (-1e-3, -1.0), (1e-3, 1.0), (1e3, 1.0)])
    >>> first_block_holds_for_a_while(relay, 2.0, -0.1), first_block_holds_for_a_while(relay, 2.0, 0.1)
    (True, False)
    >>> sat = Saturation(-1, 1)
    >>> first_block_holds_for_a_while(sat, 2.0, 0.1), first_block_holds_for_a_while(sat, 2.0, -0.1)
    (False, True)
    """
    if block.kind == "saturation" and block.min <= u <= block.max:
        return None  # within its limits: the output follows the command
    if block.kind == "static":
        xs, ys = _table(block)
        k = int(np.clip(np.searchsorted(xs, u) - 1, 0, xs.size - 2))
        if ys[k + 1] != ys[k]:  # on a sloped piece (or its extension): the output follows the command
            return None
    elif block.kind not in (*HOLDING_BLOCKS, "saturation"):
        return None
    return bool(np.isfinite(held_range(block, u, du)))


def _table(block: Any) -> tuple[np.ndarray, np.ndarray]:
    """A static block's table as its ``x`` and ``y`` columns."""
    return np.array([a for a, _ in block.table]), np.array([b for _, b in block.table])


def memoryless_output(block: Any, x: np.ndarray) -> np.ndarray | None:
    """A memoryless actuator block's output for the input samples ``x`` (a quantizer, a saturation, a dead zone, a
    table); None for a block with a state (a backlash, a rate limit, dynamics). The block equations in numpy, for
    the whole window at once: the simulator's own are compiled per sample, and loading them for ``Block.apply``
    costs a process about half a second.

    Examples
    --------
    >>> from synth.sim.blocks import DeadZone, Quantizer, RateLimit
    >>> memoryless_output(Quantizer(0.5), np.array([0.2, 0.3, 1.1])).tolist()
    [0.0, 0.5, 1.0]
    >>> memoryless_output(DeadZone(width=1.0), np.array([-3.0, 0.5, 3.0])).tolist()
    [-2.0, 0.0, 2.0]
    >>> memoryless_output(RateLimit(1.0), np.zeros(3)) is None
    True
    """
    if block.kind == "quantizer":
        q = (x - block.offset) / block.step
        return block.offset + block.step * (np.floor(q + 0.5) if block.mode == "round" else np.floor(q))
    if block.kind == "saturation":
        return np.clip(x, block.min, block.max)
    if block.kind == "dead_zone":
        c, w = block.center, block.width
        return np.where(x > c + w, x - w, np.where(x < c - w, x + w, c))
    if block.kind == "static":
        xs, ys = _table(block)
        inside = np.interp(x, xs, ys)
        low = ys[0] + (x - xs[0]) * (ys[1] - ys[0]) / (xs[1] - xs[0])  # the end pieces extend for ever
        high = ys[-1] + (x - xs[-1]) * (ys[-1] - ys[-2]) / (xs[-1] - xs[-2])
        return np.where(x < xs[0], low, np.where(x > xs[-1], high, inside))
    return None


def held_range(block: Any, u: float, du: float) -> float:
    """How far the input of ``block``, at ``u`` and drifting by ``du``, moves at most before the block's output
    changes: a dead zone's whole width (``2 width``), a backlash's gap, a quantizer's step, the distance to
    where a table's flat piece ends or back to a saturation's limit; ``inf`` when it holds for ever.

    Examples
    --------
    >>> from synth.sim.blocks import Backlash, DeadZone, Saturation
    >>> held_range(DeadZone(width=0.5), 0.1, 1e-3), held_range(Backlash(width=0.3), 2.0, -1e-3)
    (1.0, 0.3)
    >>> held_range(Saturation(-1, 1), 1.5, -0.01), held_range(Saturation(-1, 1), 1.5, 0.01)
    (0.5, inf)
    """
    if block.kind == "dead_zone":
        return 2.0 * block.width
    if block.kind == "backlash":
        return float(block.width)
    if block.kind == "quantizer":
        return float(block.step)
    if block.kind == "saturation":
        edge = block.max if u > block.max else block.min
        return abs(u - edge) if (u - edge) * du < 0 else np.inf
    if block.kind == "static":
        xs, ys = _table(block)
        now = memoryless_output(block, np.array([u]))[0]
        ahead = np.flatnonzero((xs > u) & (ys != now)) if du > 0 else np.flatnonzero((xs < u) & (ys != now))
        if ahead.size:
            return float(abs(xs[ahead[0] if du > 0 else ahead[-1]] - u))
        end_slopes = ys[-1] != ys[-2] if du > 0 else ys[0] != ys[1]
        return float(abs((xs[-1] if du > 0 else xs[0]) - u)) if end_slopes else np.inf
    return np.inf


@dataclass(frozen=True)
class Winding:
    """A still output behind an actuator block that holds it only while the controller's command winds
    (:func:`winding_behind`).

    Attributes
    ----------
    text : str
        Why the output is not settled, for the verdict.
    wait : float
        Seconds within which the command, at its drift over the last eighth, leaves the block's held range
        at most (:func:`held_range` over the drift's rate): a run this much longer sees the block let go.
    """

    text: str
    wait: float


def winding_behind(result: SimResult, after: np.ndarray, span: float, actuator: Sequence[Any],
                   shrink: float = 0.75) -> Winding | None:
    """Why a still output is not settled: the controller's command keeps moving over the last eighth (at
    least ``shrink``, :data:`synth.sim.verdict.SHRINK`, times its motion over the eighth before: not dying
    out) while an actuator block holds the output only for a while: the first block on a flat piece with a
    breakpoint in the command's way (a relay-like table), or past a saturation limit drifting back, or a dead
    zone or backlash flagged active, or a quantizer, with no saturation active for ever. Leading memoryless
    blocks whose output moves with the command (a quantizer stepping through its levels before a relay) hold
    nothing: the block after them sees their output. None otherwise.

    Examples
    --------
    A PI loop whose integrator winds in a dead zone (the output held, the command ramping by 0.1 per second):

    >>> from synth.sim.blocks import DeadZone
    >>> from synth.sim.results import SimResult
    >>> t = np.linspace(0.0, 8.0, 801)
    >>> r = SimResult(t, np.ones_like(t), np.zeros_like(t), np.zeros_like(t), 0.1 * t, np.zeros_like(t),
    ...               np.ones(t.size, np.int32), 0.01, ["dead_zone"], [], ["in_dead_zone"], [])
    >>> w = winding_behind(r, t >= 0, 8.0, [DeadZone(width=5.0)])
    >>> w.text[:40], round(w.wait, 6)  # the zone's whole width, 10, at 0.1 per second
    ('the output stands still but the controll', 100.0)
    """
    if not actuator or result.command.shape != result.t.shape:
        return None
    t, u = result.t[after], result.command[after]
    eighth = t >= t[-1] - span / 8
    before = (t >= t[-1] - span / 4) & ~eighth
    passed = 0  # leading memoryless blocks whose output moves with the command hold nothing: the next one sees it
    while passed < len(actuator) - 1 and (out := memoryless_output(actuator[passed], u)) is not None \
            and float(np.ptp(out[eighth])) > 1e-12 * (float(np.max(np.abs(out))) + 1e-300):
        u, passed = out, passed + 1
    actuator = actuator[passed:]
    late, early = float(np.ptp(u[eighth])), float(np.ptp(u[before]))
    if late <= 1e-9 * (float(np.max(np.abs(u))) + 1e-300) or late <= shrink * early:
        return None
    end = (int(result.flags[-1]) if result.flags.size else 0) >> passed
    du = float(u[-1] - u[eighth][0])
    first = first_block_holds_for_a_while(actuator[0], float(u[-1]), du)
    if first is False:
        return None
    flagged = actuator[0].kind not in ("dead_zone", "backlash") or bool(end & 1)  # inside its zone or gap
    held = [actuator[0]] if first and flagged else []
    for i, b in enumerate(actuator[1:], start=1):
        active = bool(end >> i & 1)
        if b.kind == "saturation" and active:
            return None  # a later saturation holds for ever (its input's direction is not known here)
        if b.kind == "quantizer" or (b.kind in HOLDING_BLOCKS and active):
            held.append(b)
    if not held:
        return None
    # a later block (a dead zone, backlash or quantizer: ranges that do not depend on where its input is) sees the
    # command's drift (a rate limit passes a slow one)
    wait = held_range(held[0], float(u[-1]), du) / (late / (span / 8))
    name = held[0].kind.replace("_", " ")
    return Winding(f"the output stands still but the controller's command moved {late:.3g} over the last eighth "
                   f"({late / max(early, 1e-300):.2g} times the eighth before, not dying out): it winds behind the "
                   f"{name}, which holds the output only until the command reaches where it changes (at this "
                   f"drift within {wait:.3g} s); not an equilibrium", wait)
