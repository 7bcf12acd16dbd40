"""A note on a requirement met by a loop that barely follows the reference (``|T(0)|`` below -3 dB)."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from synth.requirements.base import RequirementResult, fmt

if TYPE_CHECKING:
    from synth.loop import Loop

__all__ = ["tracking_note"]


def tracking_note(result: RequirementResult, loop: Loop) -> RequirementResult:
    """``result`` with a note when the loop follows a slow reference to less than -3 dB (``|T(0)| < 0.708``): a
    bandwidth measured below ``|T(0)|``, or step limits relative to the final value, then say little of tracking
    (``P(kp=1e-05)`` on ``1/(s+1)`` met a bandwidth and an overshoot limit, with no word of it: a black-box test).

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.requirements import Bandwidth
    >>> loop = Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1e-5}))
    >>> Bandwidth(min=0.5).evaluate(loop).message.split("; ")[1][:44]
    'measured relative to |T(0)| = 1e-05 (-100 dB'
    """
    from synth.loop import BANDWIDTH_LEVEL

    t0 = abs(loop.T0())
    if not (np.isfinite(t0) and t0 < BANDWIDTH_LEVEL):
        return result
    return replace(result, message=f"{result.message}; measured relative to |T(0)| = {fmt(t0, 3)} "
                   f"({fmt(20 * np.log10(t0), 3) if t0 > 0 else '-inf'} dB): the loop follows a slow reference to "
                   f"{fmt(t0, 3)} of it; bound the static sensitivity or require integral action to exclude such "
                   "designs")
