"""A note on a requirement met by a loop that does not follow a slow reference: ``|T(0)|`` below -3 dB (it barely
follows), above +3 dB (it settles far beyond the reference), or ``T(0) < 0`` (it moves the other way)."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from synth.requirements.base import RequirementResult, fmt

if TYPE_CHECKING:
    from synth.loop import Loop

__all__ = ["tracking_caveat", "tracking_note"]


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
    slow = _slow_reference(loop)
    if slow is None:
        return result
    t0, db = slow
    return replace(result, message=f"{result.message}; measured relative to |T(0)| = {t0} ({db} dB): the loop "
                   f"{_follows(loop, t0)}; {_EXCLUDE}")


def tracking_caveat(loop: Loop) -> str:
    """What a design's headline verdict adds when its loop barely follows the reference (``|T(0)|`` below -3 dB,
    as :func:`tracking_note`), else ``""``. A spec that minimizes control effort and asks for no tracking is met
    best by a controller that does almost nothing (``PI(kp=5e-06, ki=0)``: "meets all 2 requirements"); the
    requirement notes said so in the list below the verdict, the verdict did not.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> tracking_caveat(Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1e-5})))[:59]
    '; but its loop follows a slow reference to only 1e-05 of it'
    >>> tracking_caveat(Loop(Plant.from_string("1/(s+1)"), Controller("PI", {"kp": 1e-5, "ki": 1e-5})))
    ''
    """
    slow = _slow_reference(loop)
    if slow is None:
        return ""
    t0, db = slow
    only = "only " if abs(loop.dc_gain()) < 1 and loop.dc_gain() >= 0 else ""
    return f"; but its loop {_follows(loop, t0, only)} (|T(0)| = {db} dB): no requirement asks for " \
           f"better; {_EXCLUDE}"


_EXCLUDE = "bound the static sensitivity or require integral action to exclude such designs"


def _follows(loop: Loop, t0: str, only: str = "") -> str:
    """How the loop follows a slow reference, in words."""
    if loop.dc_gain() < 0:
        return f"moves against a slow reference, to {t0} of it with the opposite sign (T(0) < 0)"
    return f"follows a slow reference to {only}{t0} of it" + (
        f", settling {fmt(100 * (loop.dc_gain() - 1), 3)} % beyond it" if loop.dc_gain() > 1 else "")


def _slow_reference(loop: Loop) -> tuple[str, str] | None:
    """``|T(0)|`` and its dB value as text where it lies below -3 dB (the bandwidth's level) or above +3 dB, or
    where ``T(0)`` is negative; else None.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> _slow_reference(Loop(Plant.from_string("2.4/((s-0.5)*(s+3))"), Controller("P", {"kp": 1.47361})))
    ('1.74', '4.79')
    """
    from synth.loop import BANDWIDTH_LEVEL

    t0 = abs(loop.T0())
    if not np.isfinite(t0) or (BANDWIDTH_LEVEL <= t0 <= 1.0 / BANDWIDTH_LEVEL and loop.dc_gain() >= 0):
        return None
    return fmt(t0, 3), fmt(20 * np.log10(t0), 3) if t0 > 0 else "-inf"
