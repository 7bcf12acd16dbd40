"""Closed-loop bandwidth requirement."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import PositiveFloat, model_validator

from synth.batch_bandwidth import batch_bandwidths
from synth.requirements.base import Bound, Requirement, RequirementResult, fmt, register
from synth.requirements.margins import closed_loop_unstable, unstable_result, with_unstable_rows
from synth.requirements.tracking import tracking_note

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = ["Bandwidth"]


@register
class Bandwidth(Requirement):
    """Closed-loop -3 dB bandwidth of T (relative to ``|T(0)|``) at least ``min`` (and at most ``max``).

    The loop's crossover frequency is reported alongside. The bandwidth of a closed loop that is not
    stable is not a bandwidth: the requirement is then not met, with the reason.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3.0}))
    >>> r = Bandwidth(type="bandwidth", min=60).evaluate(loop)
    >>> round(r.value, 2), round(r.details["crossover"], 2), r.met
    (83.16, 68.33, True)
    >>> r = Bandwidth(min=5).evaluate(Loop(Plant.from_string("10/((s-1)*(s+5))"), Controller("P", {"kp": 0.4})))
    >>> r.met, r.message.split(":")[0]
    (False, 'closed loop UNSTABLE (1 root(s) in the closed right half-plane)')
    """

    type: Literal["bandwidth"] = "bandwidth"
    min: PositiveFloat | None = None
    max: PositiveFloat | None = None
    title: ClassVar[str] = "closed-loop bandwidth"
    bounds: ClassVar[dict[str, Bound]] = {"min": Bound("lower", "rad/s"), "max": Bound("upper", "rad/s")}
    example: ClassVar[dict[str, Any]] = {"type": "bandwidth", "min": 60.0}

    @model_validator(mode="after")
    def _one_bound(self) -> Bandwidth:
        if self.min is None and self.max is None:
            raise ValueError("give 'min' and/or 'max' (rad/s)")
        if self.min is not None and self.max is not None and self.max < self.min:
            raise ValueError(f"max ({self.max:g}) is below min ({self.min:g})")
        return self

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        if closed_loop_unstable(loop):
            return unstable_result(self, loop, "bandwidth", crossover=loop.crossover())
        wb = loop.bandwidth(per_decade)
        wc = loop.crossover()
        slacks = []
        if self.min is not None:
            slacks.append((np.log(wb / self.min) if wb > 0 else -np.inf, self.min, wb - self.min, ">="))
        if self.max is not None:
            slacks.append((np.log(self.max / wb) if wb > 0 else np.inf, self.max, self.max - wb, "<="))
        slack, bound, margin, rel = min(slacks, key=lambda t: t[0])
        if np.isnan(wb):
            slack, margin = -np.inf, -np.inf
        met = slack >= 0
        t0 = loop.T0()
        level = "" if not np.isfinite(t0) or abs(t0 - 1.0) < 1e-9 else f" (|T| 3 dB below |T(0)| = {fmt(t0, 3)})"
        msg = (f"closed-loop bandwidth {fmt(wb)} rad/s{level} {rel} {fmt(bound)} rad/s: "
               f"{'met' if met else 'NOT met'} (loop crossover {fmt(wc)} rad/s)")
        return tracking_note(self.result(value=wb, bound=bound, unit="rad/s", slack=slack, margin=margin,
                                         binding_frequency=wb if np.isfinite(wb) else None, message=msg,
                                         crossover=wc, T0=loop.T0()), loop)

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack: every loop's first -3 dB crossing of ``|T|`` at once (as ``Loop.bandwidth``)."""
        wb = batch_bandwidths(batch, per_decade)
        slack = np.full(wb.shape, np.inf)
        with np.errstate(divide="ignore", invalid="ignore"):
            if self.min is not None:
                slack = np.minimum(slack, np.where(wb > 0, np.log(wb / self.min), -np.inf))
            if self.max is not None:
                slack = np.minimum(slack, np.where(wb > 0, np.log(self.max / wb), np.inf))
        return with_unstable_rows(self, batch, np.where(np.isnan(wb), -np.inf, slack))
