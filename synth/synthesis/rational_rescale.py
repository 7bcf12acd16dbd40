"""A rational controller's convex stage again, scaled at the bandwidth floor, when it found no feasible point.

The convex stage writes a rational controller's coefficients in powers of ``s / w0``, ``w0`` at the nominal
plant's corners (:func:`synth.synthesis.parametrization.reference_frequency`). Where the requirements force
the loop far above those corners (an unstable pole at 0.42 rad/s, a bandwidth floor of 3.6 rad/s and a
controller whose poles must lie near 10-30 rad/s: seed 23 #5 of the design benchmark), the scaled
coefficients span five decades, Clarabel fails on the linearized problem and phase 1 never leaves its start.
This second run scales at the bandwidth floor and starts from the exact stabilizing gain of drawn pole and
zero patterns (:func:`synth.synthesis.rational_slices.rational_slices`), phase 1 from each in turn (at most
:data:`SCREEN_ITERATIONS` convex iterations) until one reaches every requirement.
"""

from __future__ import annotations

from dataclasses import replace

from synth.controllers import RATIONAL
from synth.progress import announce
from synth.requirements.bandwidth import Bandwidth
from synth.requirements.base import Requirement
from synth.spec import Spec
from synth.synthesis.convex import ConvexDesigner
from synth.synthesis.convex_results import ConvexResult
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.parametrization import parametrize, reference_frequency
from synth.synthesis.rational_slices import rational_slices

__all__ = ["RESCALE_FACTOR", "SCREEN_ITERATIONS", "bandwidth_floor", "rescaled_run"]

SCREEN_ITERATIONS = 12
"""Phase 1 from each start is cut after this many convex iterations (the full run continues from the best): on
seed 23 #5 the starts that reach every requirement do in one iteration, and the others' elastic totals
oscillate for the 60 a full phase 1 allows, 1.7 s each."""

RESCALE_FACTOR = 3.0
"""The second run is made only when the bandwidth floor and the plant's scale differ by more than this factor."""


def bandwidth_floor(requirements: list[Requirement]) -> float | None:
    """The highest closed-loop bandwidth the requirements ask for (None without a floor).

    Examples
    --------
    >>> bandwidth_floor([Bandwidth(type="bandwidth", min=3.6)]), bandwidth_floor([])
    (3.6, None)
    """
    floors = [float(r.min) for r in requirements if isinstance(r, Bandwidth) and r.min]
    return max(floors) if floors else None


def rescaled_run(spec: Spec, settings: ConvexSettings, names: list[str],
                 objective: tuple[str, str]) -> tuple[ConvexDesigner, ConvexResult] | None:
    """For a rational controller with a bandwidth floor more than :data:`RESCALE_FACTOR` from the plant's
    scale: the convex design scaled at the floor from the first exact stabilizing start whose phase 1 meets
    every requirement (else from the start that came closest), its result's ``note`` saying what was run; None
    when the rescaled run does not apply (or no pole pattern in the bounds has a stabilizing gain).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "r", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "P"},
    ...                    "requirements": [{"type": "bandwidth", "min": 100.0}]})
    >>> rescaled_run(spec, ConvexSettings(), ["bw"], ("bandwidth", "maximize")) is None  # not rational
    True
    """
    requirements = list(spec.requirements)
    floor = bandwidth_floor(requirements)
    if spec.controller.type != RATIONAL or floor is None:
        return None
    w0 = reference_frequency(spec)
    if max(floor / w0, w0 / floor) <= RESCALE_FACTOR:
        return None
    announce(f"convex stage scaled at the bandwidth floor ({floor:.4g} rad/s)")
    par = parametrize(RATIONAL, spec.controller.all_bounds(), spec.controller.order, floor)
    plants = spec.plants()
    designer = ConvexDesigner(requirements, names, plants, par, objective, settings)
    tried, best = 0, None
    designer.settings = replace(settings, max_iterations=SCREEN_ITERATIONS)
    for rho0 in rational_slices(par, plants):
        tried += 1
        rho, total = designer.feasible(rho0, [])
        if best is None or total < best[0]:
            best = (total, rho)
        if total == 0.0:
            break
    designer.settings = settings
    if best is None:
        return None
    result = designer.run(best[1], restarts=0)
    result.note = (f"the convex stage again with the coefficients scaled at the bandwidth floor {floor:.4g} rad/s "
                   f"instead of the plant's {w0:.4g} rad/s, phase 1 from {tried} exact stabilizing start(s) "
                   + ("until one met every requirement" if best[0] == 0.0 else "(none met every requirement)"))
    return designer, result
