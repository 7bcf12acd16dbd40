"""A direct search on the exact check for the few free parameters of a fixed structure (PI, PID, lead-lag): the
certified outer loop's last resort (:mod:`synth.synthesis.surrogate`) when requirements with no solver form (a
step-response limit, "no limit cycle") failed every design under the surrogate and the plain design met them
only by dropping the integral action, or not at all.

Every candidate is judged by :func:`synth.check.check` itself, so whatever the search returns met every
requirement on every plant as the certificate evaluates them; the search only decides where to look:

1. a scrambled Sobol sample of the parameter box on scales that resolve small values (a parameter's
   logarithm where its bounds span a decade or more, ``lo + (hi - lo)(10^(4u) - 1)/(10^4 - 1)`` from a bound
   of zero), another on the plain box, a third around a given design, and that design scaled down towards
   zero gain (the controller's parameters times ``2^-k``);
2. the pattern search on the exact check (:func:`synth.synthesis.pattern.pattern_search`, which keeps
   ``|1 + L|`` as far from zero as the solver stages do) from the best feasible samples a few sample
   spacings apart, and a longer one (:data:`FINISH_CHECKS`) from the best of their ends.

The search says what it rests on (checks, samples, starts, final step); it finds a design or none, never a
verdict of infeasibility.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from synth.check import quick_check
from synth.controllers import Controller
from synth.errors import SynthError
from synth.forked import run_beside
from synth.loop import Loop
from synth.objectives import score
from synth.spec import Spec
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.integral_action import objective_terms
from synth.synthesis.pattern import PATTERN_CHECKS, pattern_search

__all__ = ["FINISH_CHECKS", "MAX_PARAMETERS", "WALK_CHECKS", "WALK_SAMPLES", "ExactSearchResult", "exact_search",
           "parameter_scales"]

MAX_PARAMETERS = 4
"""The search runs for at most this many free parameters (its sample and its moves grow as ``2^n``)."""

FINISH_CHECKS = 400
"""Most checks of the pattern search that continues from the best of the starts' searches (each stops at
:data:`~synth.synthesis.pattern.PATTERN_CHECKS`): a PID under a 2 % overshoot limit (the step benchmark's seed 1,
#53) ended at ki 7.60 with 1 % of overshoot to spare, still crawling along the limit's ridge; 400 more checks
reach 8.74 at the limit (the benchmark grid's best 8.77)."""

WALK_SAMPLES = 48
"""Samples whose worst slack is evaluated to pick the walk's start (:func:`_walk_to_feasible`)."""

WALK_CHECKS = 120
"""Most evaluations of the walk towards a feasible point."""

_DECADES = 4.0  # a range from zero is resolved over this many decades below its upper bound


@dataclass
class ExactSearchResult:
    """What :func:`exact_search` found and what it rests on.

    Attributes
    ----------
    controller : Controller or None
        The best design that passed the exact check (None: no sampled point passed).
    score : float or None
        Its objective score (larger is better; :func:`synth.objectives.score`).
    checks : int
        Exact checks made (every requirement on every plant).
    samples : int
        Points of the initial sample.
    checked_samples : int
        Of those, the ones checked: in order of score, until the starts were found (a sample a few spacings
        from a start already taken is not checked: it would not be one).
    starts : int
        Pattern searches run: one from each checked sample that passed.
    final_step : float
        The smallest step a pattern search ended with (relative to each parameter's scale).
    walked : bool
        One start was reached by the walk on the worst slack (:func:`_walk_to_feasible`), not sampled.
    """

    controller: Controller | None
    score: float | None
    checks: int
    samples: int
    checked_samples: int
    starts: int
    final_step: float
    walked: bool = False

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict.

        Examples
        --------
        >>> ExactSearchResult(None, None, 3, 3, 3, 0, 1.0).to_dict()["checks"]
        3
        """
        out = asdict(self)
        out["controller"] = None if self.controller is None else str(self.controller)
        return out


def parameter_scales(bounds: dict[str, tuple[float, float]]) -> dict[str, str]:
    """How each parameter is searched: ``"log"`` (positive bounds a decade or more apart), ``"from_zero"``
    (from a lower bound of zero, resolved over four decades below the upper) or ``"linear"``.

    Examples
    --------
    >>> parameter_scales({"kp": (0.0, 10.0), "ki": (0.1, 100.0), "z": (-1.0, 1.0), "p": (2.0, 3.0)})
    {'kp': 'from_zero', 'ki': 'log', 'z': 'linear', 'p': 'linear'}
    """
    out = {}
    for p, (lo, hi) in bounds.items():
        if lo > 0 and hi / lo >= 10:
            out[p] = "log"
        elif lo == 0 and hi > 0:
            out[p] = "from_zero"
        else:
            out[p] = "linear"
    return out


class _Box:
    """The free parameters' box and the map from the unit cube ``u`` to parameter values and back."""

    def __init__(self, spec: Spec) -> None:
        bounds = spec.controller.all_bounds()
        self.free = spec.controller.free_parameters()
        self.bounds = {p: bounds[p] for p in self.free}
        self.fixed = {p: float(lo) for p, (lo, hi) in bounds.items() if lo >= hi}
        self.scales = parameter_scales(self.bounds)
        self.type = spec.controller.type

    def value(self, p: str, u: float) -> float:
        lo, hi = self.bounds[p]
        u = min(max(u, 0.0), 1.0)
        kind = self.scales[p]
        if kind == "log":
            return float(lo * (hi / lo) ** u)
        if kind == "from_zero":
            return float(hi * (10.0 ** (_DECADES * u) - 1.0) / (10.0**_DECADES - 1.0))
        return float(lo + (hi - lo) * u)

    def coordinate(self, p: str, v: float) -> float:
        lo, hi = self.bounds[p]
        v = min(max(v, lo), hi)
        kind = self.scales[p]
        if kind == "log":
            return float(np.log(v / lo) / np.log(hi / lo))
        if kind == "from_zero":
            return float(np.log10(1.0 + v / hi * (10.0**_DECADES - 1.0)) / _DECADES)
        return float((v - lo) / (hi - lo))

    def controller(self, u: np.ndarray) -> Controller:
        values = {p: self.value(p, float(x)) for p, x in zip(self.free, u)}
        return Controller(self.type, {**self.fixed, **values})

    def point(self, c: Controller) -> np.ndarray:
        return np.array([self.coordinate(p, float(c.parameters[p])) for p in self.free])


def exact_search(spec: Spec, near: Controller | None = None, samples: int | None = None,
                 starts: int = 3, seed: int = 0) -> ExactSearchResult:
    """Search the spec's parameter box for the best-scoring controller that passes :func:`synth.check.check`.

    Parameters
    ----------
    spec : Spec
        The spec, every requirement included.
    near : Controller, optional
        A design to sample around (the design made without the requirements that have no solver form).
    samples : int, optional
        Points of each of the box's two Sobol samples (default ``64 * 2^n`` for ``n`` free parameters, at most
        512).
    starts : int
        Pattern searches, from the best feasible samples (distinct points).
    seed : int
        Seed of the scrambled Sobol sequences.

    Returns
    -------
    ExactSearchResult

    Examples
    --------
    A PI with at most 10 % overshoot, maximum integral gain:

    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "os", "plant": {"tf": "2/((s+1)*(s+2))"},
    ...     "controller": {"type": "PI", "bounds": {"kp": [0.01, 5], "ki": [0, 10]}},
    ...     "requirements": [{"type": "step_response", "max_overshoot": 10}],
    ...     "objective": {"maximize": "integral_gain"}})
    >>> from synth.check import check
    >>> found = exact_search(spec)
    >>> check(spec, found.controller).feasible, round(found.controller.parameters["ki"], 2)
    (True, 1.76)
    """
    from synth.stats_stand_in import sobol_points

    box = _Box(spec)
    n = len(box.free)
    if n == 0 or n > MAX_PARAMETERS or not all(np.isfinite(v) for b in box.bounds.values() for v in b):
        return ExactSearchResult(None, None, 0, 0, 0, 0, 1.0)
    terms = objective_terms(spec)
    keeping = ConvexSettings().stability_level
    nominal = spec.nominal_plant()
    counter = {"checks": 0}

    def passes(c: Controller) -> bool:
        counter["checks"] += 1
        try:
            with np.errstate(all="ignore"):
                return quick_check(spec, c).feasible
        except (ArithmeticError, ValueError, RuntimeError, SynthError):  # a check that cannot be made: not passed
            return False

    def scored(c: Controller) -> float:
        try:
            with np.errstate(all="ignore"):
                value = score(Loop(nominal, c), terms)
        except (ArithmeticError, ValueError, RuntimeError, SynthError):
            return -np.inf
        return value if np.isfinite(value) else -np.inf

    size = samples or min(512, 64 * 2**n)
    points = list(sobol_points(n, size, seed))
    # as many again spread evenly over the plain box: a feasible set in the middle of a long range (kp 0.3-0.4
    # of [0, 2]) is thin on the scales that resolve small values
    points += [np.array([box.coordinate(p, box.bounds[p][0] + (box.bounds[p][1] - box.bounds[p][0]) * x)
                         for p, x in zip(box.free, u)]) for u in sobol_points(n, size, seed + 2)]
    if near is not None and all(p in near.parameters for p in box.free):
        centre = box.point(near)
        around = sobol_points(n, max(16, size // 4), seed + 1)
        points += [np.clip(centre + 0.5 * (u - 0.5), 0.0, 1.0) for u in around]
        for k in range(8):  # the design scaled down towards zero gain
            points.append(box.point(near.with_parameters(**{p: near.parameters[p] * 2.0**-k for p in box.free
                                                            if box.scales[p] != "linear"})))
    candidates = []
    for u in points:
        c = box.controller(u)
        s = scored(c)
        if np.isfinite(s):
            candidates.append((s, u, c))
    candidates.sort(key=lambda e: -e[0])  # stable: ties in sample order
    # the starts are the best-scoring passing samples a few sample spacings apart, so the samples are checked
    # best first until there are enough of them, and one within a spacing of a start is not checked at all
    spacing = 2.0 / size ** (1.0 / n)
    chosen: list[tuple[float, np.ndarray]] = []
    checked = 0
    screen = _BatchScreen(spec, [c for _, _, c in candidates])
    for k, (s, u, c) in enumerate(candidates):
        if len(chosen) == starts:
            break
        if any(np.max(np.abs(u - v)) <= spacing for _, v in chosen):
            continue
        checked += 1
        if not screen.may_pass(k):  # failed the same exact evaluation, made for many samples at once
            counter["checks"] += 1
        elif passes(c):
            chosen.append((s, u))
    # a feasible set thinner than the sample's spacing (a PI behind 1 s under a 2 % overshoot and a 12 s settling
    # limit: a sliver of 0.06 % of the box) is missed by the sample, and the starts that pass may all score low
    # (ki = 0 at a vanishing kp, a black-box test): a walk from the least violating of the samples that would score
    # better, on the requirements' worst slack, may reach it, and is then a start too
    best_score = max((s for s, _ in chosen), default=-np.inf)
    walked = _walk_to_feasible(spec, box, [u for s, u, _ in candidates if s > best_score], counter)
    reached = walked is not None and passes(box.controller(walked))
    if reached:
        chosen.append((scored(box.controller(walked)), walked))
    if not chosen:
        return ExactSearchResult(None, None, counter["checks"], len(points), checked, 0, 1.0)
    best: tuple[float, Controller] | None = None
    final_step = 1.0
    searches = [lambda u=u: pattern_search(spec, box.controller(u), terms, max_checks=PATTERN_CHECKS,
                                           keeping=keeping) for _, u in chosen]
    rest, first = run_beside(searches[1:], searches[0], nested=True)  # independent: on both cores when free
    for found in [first, *rest]:
        counter["checks"] += found.checks
        final_step = min(final_step, found.final_step)
        s = scored(found.controller)
        if best is None or s > best[0]:
            best = (s, found.controller)
    assert best is not None
    finish = pattern_search(spec, best[1], terms, max_checks=FINISH_CHECKS, keeping=keeping)
    counter["checks"] += finish.checks
    final_step = min(final_step, finish.final_step)
    finished = scored(finish.controller) if finish.improved else -np.inf
    if finished > best[0]:
        best = (finished, finish.controller)
    return ExactSearchResult(best[1], float(best[0]), counter["checks"], len(points), checked, len(chosen),
                             final_step, reached)


def _walk_to_feasible(spec: Spec, box: _Box, above: list[np.ndarray], counter: dict[str, int]) -> np.ndarray | None:
    """A point of the unit cube that meets every requirement, reached by a pattern search on the worst slack (the
    requirements' smallest, any closed-loop instability infinitely bad) from the least violating of
    :data:`WALK_SAMPLES` of ``above`` (spread over their order), in at most :data:`WALK_CHECKS` evaluations; None
    when the walk ends short of it."""
    from synth.search import hooke_jeeves

    if not above:
        return None
    plants = spec.plants()

    def violation(u: np.ndarray) -> float:
        counter["checks"] += 1
        c = box.controller(u)
        try:
            with np.errstate(all="ignore"):
                loops = [Loop(p, c) for p in plants]
                if not all(loop.stability().stable for loop in loops):
                    return np.inf
                worst = max(-r.stable_slack(loop) for r in spec.requirements for loop in loops)  # counted above
        except (ArithmeticError, ValueError, RuntimeError, SynthError):
            return np.inf
        return float(worst) if np.isfinite(worst) else np.inf

    picks = above[:: max(1, len(above) // WALK_SAMPLES)][:WALK_SAMPLES]
    values = [violation(u) for u in picks]
    first = int(np.argmin(values))
    if not np.isfinite(values[first]):
        return None
    n = len(box.free)
    walk = hooke_jeeves(violation, picks[first], np.zeros(n), np.ones(n), lambda a, b: a < b - 1e-12, 0.05, 1e-4,
                        WALK_CHECKS, start_value=values[first])
    return walk.z if walk.value <= 0 else None


class _BatchScreen:
    """The costly requirements that have a vectorized form on every plant (a step limit without a delay:
    :meth:`~synth.requirements.base.Requirement.vectorized_on`), with the closed-loop root counts, evaluated for
    the samples in order, :attr:`CHUNK` at a time as they are asked for (the search stops after a few passing
    samples): a sample they fail fails :func:`synth.check.quick_check` too (the same evaluations), so only the
    others are checked one by one."""

    CHUNK = 64

    def __init__(self, spec: Spec, controllers: list[Controller]) -> None:
        plants = spec.plants()
        self._requirements = [r for r in spec.requirements if r.costly and r.vectorized_on(plants)]
        self._plants, self._controllers = plants, controllers
        self._fails = np.zeros(len(controllers), dtype=bool)
        self._done = 0 if self._requirements else len(controllers)

    def may_pass(self, k: int) -> bool:
        """Whether sample ``k`` may pass the exact check (False: it fails it)."""
        from synth.loop_batch import LoopBatch

        while self._done <= k:
            rows = slice(self._done, self._done + self.CHUNK)
            fails = np.zeros(len(self._controllers[rows]), dtype=bool)
            for plant in self._plants:
                batch = LoopBatch(plant, self._controllers[rows])
                with np.errstate(all="ignore"):
                    fails |= batch.unstable_root_counts() > 0
                    loops = batch.loops()
                    for req in self._requirements:  # a cheap proof of failure first, the full slack on the rest
                        left = np.flatnonzero(~fails)
                        fails[left] |= req.fails_surely([loops[i] for i in left])
                        left = np.flatnonzero(~fails)
                        if left.size:
                            rest = LoopBatch(plant, [self._controllers[rows][i] for i in left]).with_root_counts(
                                np.zeros(left.size, dtype=int))  # stable: counted above
                            fails[left] |= ~(np.asarray(req.batch_slack(rest), float) >= 0)
            self._fails[rows] = fails
            self._done += self.CHUNK
        return not self._fails[k]

