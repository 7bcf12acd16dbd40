"""A derivative-free fallback: pattern search on the exact check, from a design the NLP could not polish.

The NLP polish moves a design by gradients of requirements on a grid. Where every polish from the screen's
starts failed (each answer left the stabilizing set, or IPOPT stalled), the screen's own point was the best
certified design: a random point of the box, not optimized. Pattern search improves it using only what the
certificate itself trusts: :func:`synth.check.check` (every requirement, exact closed-loop stability with
the delay) and the objective's score, by Hooke and Jeeves' pattern search (:func:`synth.search.hooke_jeeves`)
in each parameter's scale: a move is kept when the moved design passes the check and scores better (or as
well, with more slack: a parameter the objective does not read still makes room). It is slow (one check per
trial) and finds only a local improvement, which is why it runs only there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from synth.check import quick_check
from synth.controllers import Controller
from synth.errors import SynthError
from synth.loop import Loop
from synth.objectives import score
from synth.results import SEARCH_PER_DECADE
from synth.search import hooke_jeeves
from synth.spec import Spec
from synth.synthesis.convex_settings import ConvexSettings, design_grid
from synth.synthesis.delay_grid import controller_gain_bound
from synth.synthesis.parametrization import parametrize

__all__ = ["PATTERN_CHECKS", "PatternResult", "pattern_search"]

PATTERN_CHECKS = 160
"""Most checks a pattern search makes."""


@dataclass(frozen=True)
class PatternResult:
    """Outcome of :func:`pattern_search`.

    Attributes
    ----------
    controller : Controller
        The best design found (the start when nothing improved it).
    improved : bool
        Whether a move improved the start.
    checks : int
        Checks made.
    final_step : float
        The largest remaining step, relative to each parameter's scale, when the search ended.
    """

    controller: Controller
    improved: bool
    checks: int
    final_step: float


def pattern_search(spec: Spec, start: Controller, terms: list[tuple[str, str, float]],
                   max_checks: int = PATTERN_CHECKS, first_step: float = 0.1, min_step: float = 1e-4,
                   per_decade: int = SEARCH_PER_DECADE, keeping: float = 0.0) -> PatternResult:
    """Improve ``start`` (which should pass the check) by pattern search over the spec's free parameters.

    Parameters
    ----------
    spec : Spec
    start : Controller
    terms : list of (name, sense, weight)
        The objective (:func:`synth.synthesis.integral_action.objective_terms`).
    max_checks : int
        Budget of checks.
    first_step, min_step : float
        Initial and smallest step, relative to each parameter's scale (its value plus 1 % of its range).
    per_decade : int
        Density of the checks (the caller certifies the answer at its own density).
    keeping : float
        Smallest ``|1 + L|`` a move may leave on every plant (on the design grid at ``per_decade``): the
        stability keeping of the convex and NLP stages (:class:`~synth.synthesis.convex_settings.ConvexSettings`'
        ``stability_level``), so that the search does not walk a design to the edge of stability. A start that
        comes closer to -1 on this grid (the stages keep ``|1 + L|`` only on their own grid) sets the floor
        instead: no move comes closer than the start.

    Returns
    -------
    PatternResult

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))"}, "requirements": [{"type":
    ...                    "peak_sensitivity", "max_db": 6}], "controller": {"type": "PI", "bounds": {"kp": [0, 5],
    ...                    "ki": [0, 20]}}, "objective": {"maximize": "integral_gain"}})
    >>> r = pattern_search(spec, Controller("PI", {"kp": 1.0, "ki": 2.0}), [("integral_gain", "maximize", 1.0)])
    >>> r.improved, r.controller.parameters["ki"] > 5.0
    (True, True)
    """
    bounds = spec.controller.all_bounds()
    free = [k for k in sorted(bounds) if bounds[k][0] < bounds[k][1]]
    nominal = spec.nominal_plant()
    x = {k: float(v) for k, v in start.parameters.items()}
    checks = 0
    grid = design_grid(spec.plants(), list(spec.requirements), ConvexSettings(per_decade=per_decade),
                       _gain_bound(spec))

    def closest(c: Controller) -> float:
        """Smallest ``|1 + L|`` on the grid over the plants."""
        with np.errstate(all="ignore"):
            return min(float(np.min(np.abs(1.0 + Loop(p, c).L(grid)))) for p in spec.plants())

    if keeping > 0:  # a start closer to -1 than that (between the stage's own grid points): no move comes closer
        keeping = min(keeping, closest(start))

    def value(params: dict[str, float]) -> tuple[float, float]:
        """(objective score, smallest requirement slack); (-inf, -inf) when the check fails or cannot be made
        (e.g. a Nyquist count that does not converge)."""
        nonlocal checks
        checks += 1
        c = Controller(start.type, params)
        try:
            with np.errstate(all="ignore"):
                result = quick_check(spec, c, per_decade)
                if not result.feasible or (keeping > 0 and closest(c) < keeping):
                    return -np.inf, -np.inf
                return float(score(Loop(nominal, c), terms)), result.min_slack
        except (ArithmeticError, ValueError, RuntimeError, SynthError):  # a count that failed: not certified
            return -np.inf, -np.inf

    def better(a: tuple[float, float], b: tuple[float, float]) -> bool:
        """A better score, or the same score with more slack (a move along a parameter the objective does not
        read, e.g. kp when maximizing ki, makes room for the next move of the one it reads)."""
        tie = 1e-12 * max(abs(a[0]), abs(b[0]), 1.0)
        return a[0] > b[0] + tie or (abs(a[0] - b[0]) <= tie and a[1] > b[1])

    first = value(x)
    if not np.isfinite(first[0]) or not free:
        return PatternResult(start, False, checks, 0.0)
    scale = np.array([abs(x[k]) + 0.01 * (bounds[k][1] - bounds[k][0]) for k in free])
    lo = np.array([bounds[k][0] for k in free]) / scale
    hi = np.array([bounds[k][1] for k in free]) / scale

    def at(z: np.ndarray) -> dict[str, float]:
        return {**x, **{k: float(np.clip(zi * si, *bounds[k])) for k, zi, si in zip(free, z, scale)}}

    z0 = np.array([x[k] for k in free]) / scale
    found = hooke_jeeves(lambda z: value(at(z)), z0, lo, hi, better, first_step, min_step, max_checks - 2,
                         start_value=first)  # the start is checked once, above
    improved = found.value[0] > first[0] and better(found.value, first)
    return PatternResult(Controller(start.type, at(found.z)) if improved else start, improved, checks, found.step)


def _gain_bound(spec: Spec) -> Callable[[np.ndarray], np.ndarray] | None:
    """The controller's gain bound for the delay points of the grid (None when its type has none)."""
    try:
        return controller_gain_bound(parametrize(spec.controller.type, spec.controller.all_bounds()))
    except (SynthError, KeyError):  # a free PID filter or lead-lag pole: no linear parametrization
        return None
