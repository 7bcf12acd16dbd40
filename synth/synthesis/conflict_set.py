"""Which requirements conflict: the deletion filter behind an infeasible design's verdict."""

from __future__ import annotations

import numpy as np

from synth.errors import NoStabilizingStartError
from synth.requirements.base import unique_names
from synth.spec import Spec
from synth.synthesis.convex import ConvexDesigner
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.parametrization import STRUCTURAL, parametrize, reference_frequency

__all__ = ["conflict_set"]


def conflict_set(spec: Spec, settings: ConvexSettings) -> list[str] | None:
    """A minimal set of requirements that cannot be met together (deletion filter).

    Each requirement is dropped in turn; if the others are still infeasible it
    is left out for good, else it is kept. Feasibility is tested by the convex
    phase 1 from several stabilizing starts (a local method: a kept requirement
    is one whose removal let it find a design). None when no stabilizing start
    is found for the filter's fixed structure (a lead-lag's pole held at the
    middle of its range: seed 12 #184 of the design benchmark ended in a
    traceback): the diagnosis then names the requirements by their elastic prices.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "PI", "bounds":
    ...                    {"kp": [0, 1], "ki": [0, 1]}}, "requirements": [{"type": "bandwidth", "min": 100.0},
    ...                    {"type": "peak_sensitivity", "max_db": 3}]})
    >>> conflict_set(spec, ConvexSettings())  # a bandwidth of 100 rad/s needs gains far above 1
    ['bandwidth']
    """
    requirements = list(spec.requirements)
    names = unique_names(requirements)
    keep = list(range(len(requirements)))
    key = STRUCTURAL.get(spec.controller.type)
    bounds = spec.controller.all_bounds()
    if key and bounds[key][0] < bounds[key][1]:
        lo, hi = bounds[key]
        bounds = {**bounds, key: (float(np.sqrt(lo * hi)) if lo > 0 else 0.5 * (lo + hi),) * 2}
    par = parametrize(spec.controller.type, bounds, spec.controller.order, reference_frequency(spec))
    for i in list(keep):
        trial = [k for k in keep if k != i]
        if not trial:
            continue
        designer = ConvexDesigner([requirements[k] for k in trial], [names[k] for k in trial], spec.plants(),
                                  par, None, settings)
        try:
            if not designer.is_feasible():
                keep = trial
        except NoStabilizingStartError:
            return None
    return [names[k] for k in keep]
