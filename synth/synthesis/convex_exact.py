"""The convex stage's designs on the exact check, between its grid points.

The convex stage meets every requirement on its design grid only. After each optimum the exact check (peaks and
crossings refined, at least 160 points per decade) looks between the grid points: its violated requirements'
binding frequencies join the grid (:func:`violated_frequencies`). When the last refinement still leaves a
violation, the best earlier iterate the exact check passes is kept instead (:func:`best_passing`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from synth.check import evaluate_all
from synth.controllers import Controller
from synth.plant import Plant
from synth.requirements.base import Requirement

__all__ = ["EXACT_PER_DECADE", "best_passing", "violated_frequencies"]

EXACT_PER_DECADE = 160
"""The exact check's least density (points per decade; four times the design grid's when that is higher)."""


def violated_frequencies(requirements: Sequence[Requirement], plants: Sequence[Plant], controller: Controller,
                         per_decade: int) -> list[float]:
    """Binding frequencies (rad/s) of the requirements the exact check finds violated on any plant.

    Parameters
    ----------
    requirements, plants : sequence
        The spec's requirements and plants.
    controller : Controller
        The design.
    per_decade : int
        The design grid's density; the check uses four times it, at least :data:`EXACT_PER_DECADE`.

    Returns
    -------
    list of float
        Empty when every requirement holds.

    Examples
    --------
    >>> from synth.requirements.margins import MarginsRequirement
    >>> plant = Plant.from_string("1/(s*(s+1)*(s+2))")
    >>> req = MarginsRequirement(type="margins", gain_margin_db=6.0, phase_margin_deg=30.0)
    >>> violated_frequencies([req], [plant], Controller("P", {"kp": 1.0}), 40)
    []
    >>> [round(w, 3) for w in violated_frequencies([req], [plant], Controller("P", {"kp": 5.0}), 40)]
    [1.414]
    """
    _, per_plant = evaluate_all(list(requirements), list(plants), controller,
                                per_decade=max(EXACT_PER_DECADE, 4 * per_decade))
    return [r.binding_frequency for results in per_plant.values() for r in results[1:]
            if r.slack < 0 and r.binding_frequency and r.binding_frequency > 0]


def best_passing(iterates: Sequence[tuple[float, np.ndarray]], maximize: bool,
                 passes: Callable[[np.ndarray], bool]) -> tuple[float, np.ndarray] | None:
    """The iterate with the best objective among those ``passes`` accepts (None when none does).

    Parameters
    ----------
    iterates : sequence of (float, ndarray)
        Objective value and parameter vector of each feasible iterate, in any order; those with a value that is not
        finite are left out.
    maximize : bool
        The objective's sense.
    passes : callable
        The exact check of one parameter vector; called best first, until one passes.

    Returns
    -------
    tuple or None

    Examples
    --------
    >>> its = [(0.3, np.array([1.0])), (0.9, np.array([2.0])), (0.5, np.array([3.0]))]
    >>> best_passing(its, True, lambda rho: rho[0] != 2.0)
    (0.5, array([3.]))
    >>> best_passing(its, False, lambda rho: False) is None
    True
    """
    finite = [(value, rho) for value, rho in iterates if np.isfinite(value)]  # a NaN would leave sorted() unordered
    for value, rho in sorted(finite, key=lambda t: -t[0] if maximize else t[0]):
        if passes(rho):
            return value, rho
    return None
