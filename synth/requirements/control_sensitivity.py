"""Peak control sensitivity |KS| = |C/(1 + L)|: actuator activity per unit disturbance or noise."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np

from synth.requirements.base import register
from synth.requirements.sensitivity import PeakRequirement

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = ["PeakControlSensitivity"]


@register
class PeakControlSensitivity(PeakRequirement):
    """Peak ``|C S|`` at most ``max_db`` (dB of plant-input units per output unit).

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 9.0}))
    >>> r = PeakControlSensitivity(type="peak_control_sensitivity", max_db=20).evaluate(loop)
    >>> round(r.value, 2), r.met  # |9/(1 + 9/(jw+1))| tends to 9 (19.08 dB) as w -> inf
    (19.08, True)
    """

    type: Literal["peak_control_sensitivity"] = "peak_control_sensitivity"
    symbol: ClassVar[str] = "|KS|"
    title: ClassVar[str] = "peak control sensitivity"
    example: ClassVar[dict[str, Any]] = {"type": "peak_control_sensitivity", "max_db": 20.0}

    def curve(self, loop: Loop) -> Callable[[np.ndarray], np.ndarray]:
        """``|C S|`` as a function of ``w``."""
        return lambda w: np.abs(loop.KS(w))

    def batch_curve(self, batch: LoopBatch) -> Callable[[np.ndarray], np.ndarray]:
        """``|C S|`` of every loop."""
        return lambda w: np.abs(batch.KS(w))
