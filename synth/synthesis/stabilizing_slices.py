"""Where the stabilizing set lies around a design: each gain's exact stabilizing values with the others fixed.

On an open-loop unstable plant the stabilizing set of a P, PI or PID controller can be a small part of the
bounds, and an engineer tuning by hand wants to know how far each gain may move. For each free gain of the
design, the values in its bounds that keep the closed loop stable on every plant, the other parameters at the
design's values, are computed exactly (D-decomposition with the delay, :func:`synth.synthesis.gainset.stability_set`).
These are slices through the design point, not the whole set: moving two gains at once can leave it sooner.
"""

from __future__ import annotations

import numpy as np

from synth.controllers import Controller
from synth.plant import Plant
from synth.requirements.base import fmt
from synth.spec import Spec
from synth.stability import stability_floor
from synth.synthesis.axis_starts import SCANNED_TYPES
from synth.synthesis.gainset import ScalarFamily, stability_set

__all__ = ["open_loop_unstable", "slices_text", "stabilizing_slices"]


def open_loop_unstable(spec: Spec) -> bool:
    """Whether any of the spec's plants has a pole in the open right half-plane.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> open_loop_unstable(parse_spec({"name": "u", "plant": {"tf": "10/((s-1)*(s+5))"}, "controller": {"type": "P"},
    ...     "requirements": [{"type": "peak_sensitivity", "max_db": 10}]}))
    True
    """
    return any(np.any(np.real(p.poles()) > 0) for p in spec.plants())


def stabilizing_slices(spec: Spec, controller: Controller) -> dict[str, list[tuple[float, float]]]:
    """Each free gain's stabilizing intervals in its bounds, the other parameters at ``controller``'s values
    (empty for controller types other than P, PI and PID; a gain whose set cannot be computed is left out).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "u", "plant": {"tf": "10/((s-1)*(s+5))"}, "controller": {"type": "PI",
    ...     "bounds": {"kp": [0, 5], "ki": [0, 5]}}, "requirements": [{"type": "peak_sensitivity", "max_db": 10}]})
    >>> slices = stabilizing_slices(spec, Controller("PI", {"kp": 2.0, "ki": 1.0}))
    >>> [(round(a, 6), round(b, 6)) for a, b in slices["kp"]], [(round(a, 6), round(b, 6)) for a, b in slices["ki"]]
    ([(0.75, 5.0)], [(0.0, 5.0)])
    """
    if controller.type not in SCANNED_TYPES:
        return {}
    bounds = spec.controller.all_bounds()
    plants = spec.plants()
    out: dict[str, list[tuple[float, float]]] = {}
    for name in spec.controller.free_parameters():
        if name not in ("kp", "ki", "kd"):
            continue
        lo, hi = bounds[name]
        fixed = {k: v for k, v in controller.parameters.items() if k != name}
        try:
            out[name] = [(float(a), float(b)) for a, b in
                         stability_set(ScalarFamily(controller.type, name, fixed), plants, float(lo), float(hi))]
        except (ArithmeticError, ValueError, RuntimeError):
            continue
    return out


def slices_text(slices: dict[str, list[tuple[float, float]]], plants: list[Plant] | None = None) -> str:
    """The verdict's sentence on :func:`stabilizing_slices` ("" when there are none); with the ``plants``, it names
    the stability floor the intervals keep every closed-loop root left of (the largest of the plants'
    :func:`synth.stability.stability_floor`): an end the floor sets is no root crossing the axis (a PI whose ki
    is tiny leaves a root near ``-ki/kp``, which a larger kp brings within the floor).

    Examples
    --------
    >>> slices_text({"kp": [(0.75, 5.0)], "ki": [(0.0, 6.0)]})[-52:]
    'the others fixed) for kp in [0.75, 5], ki in [0, 6].'
    >>> print(slices_text({"kp": [(4.0, 31.28)]}, [Plant.from_string("5/((s-2)*(s+10))")])[-99:])
    or kp in [4, 31.28] (stable: every closed-loop root left of -2e-06 rad/s, synth's stability floor).
    """
    if not slices:
        return ""
    parts = []
    for name, intervals in slices.items():
        ranges = " or ".join(f"[{fmt(a)}, {fmt(b)}]" for a, b in intervals) or "no value"
        parts.append(f"{name} in {ranges}")
    floor = max((stability_floor(p.num, p.den, p.delay) for p in plants), default=0.0) if plants else 0.0
    note = f" (stable: every closed-loop root left of -{fmt(floor)} rad/s, synth's stability floor)" if floor else ""
    return (" Around this design the loop stays stable (exact, D-decomposition, one gain moved at a time, the others "
            "fixed) for " + ", ".join(parts) + note + ".")
