"""The first-order test of a converged stage's claim of a local optimum, on the exact requirements.

IPOPT's convergence makes a design a KKT point of the NLP on the design grid, whose margins are held at crossings
followed from the start design and whose helper variables have boxes of their own. That NLP can stop where the
exact requirements still leave a way up: on a type-3 loop (a PID on a double integrator) with the downward gain
margin and the phase margin both binding, a PID with ``ki`` 0.0221 was called a local optimum while every point on
the segment to ``ki`` 0.0263 passes the check (a black-box test of ``synth design``). Coordinate moves of the
pattern search cannot follow the two limits at once.

:func:`ascent_probe` differentiates the objective and every part of every requirement (each margin on its own:
:meth:`~synth.requirements.base.Requirement.part_slacks`) by forward differences on each plant, and solves a
small linear program for a direction that raises the objective and every nearly active slack at first order
(scaled to each parameter's size, inside the bounds). Where such a direction exists it steps along it, largest
step first, to the first point that passes the exact check and scores better: the design was not a local optimum
of the spec's problem, and the caller searches on from that point.
"""

from __future__ import annotations

import numpy as np

from synth.check import quick_check
from synth.controllers import Controller
from synth.loop import Loop
from synth.objectives import score
from synth.results import SEARCH_PER_DECADE
from synth.spec import Spec
from synth.synthesis.pattern import closest_approach, parameter_scales

__all__ = ["ACTIVE", "CLIMB_ROUNDS", "MIN_GAIN", "STEPS", "ascent_probe", "climb"]

ACTIVE = 0.02
"""A part whose slack is below this (nepers or radians: 0.17 dB, 1.1 deg) constrains the direction."""

STEPS = (0.3, 0.1, 0.03, 0.01, 0.003, 0.001)
"""Steps along the direction, relative to each parameter's scale, largest first."""

_DIFF = 1e-5
"""Forward-difference step, relative to each parameter's scale."""

MIN_GAIN = 1e-3
"""Smallest relative improvement of the objective a step must make: the stages tighten every bound by about 1e-4
(:data:`~synth.synthesis.nlp_problem.BACKOFF`), which leaves them that much below the spec's optimum."""

CLIMB_ROUNDS = 20
"""Most probes :func:`climb` makes."""


def _parts(spec: Spec, c: Controller) -> np.ndarray | None:
    """Every requirement part's slack on every plant, or None where a closed loop is not stable."""
    out: list[float] = []
    for plant in spec.plants():
        loop = Loop(plant, c)
        if not loop.stability().stable:
            return None
        for req in spec.requirements:
            out.extend(req.part_slacks(loop, SEARCH_PER_DECADE))
    return np.array(out, dtype=float)


def ascent_probe(spec: Spec, controller: Controller, terms: list[tuple[str, str, float]],
                 keeping: float = 0.0) -> Controller | None:
    """A controller that passes the exact check and scores better than ``controller``, along a direction that
    raises the objective and every nearly active requirement part at first order; None where no such direction
    exists (first-order stationary on the exact requirements) or no step along it passes and improves the
    objective by :data:`MIN_GAIN` at least.

    Parameters
    ----------
    spec : Spec
    controller : Controller
        A design that passes the check (a converged stage's).
    terms : list of (name, sense, weight)
        The objective (:func:`synth.synthesis.integral_action.objective_terms`).
    keeping : float
        Smallest ``|1 + L|`` a step may leave (the stages' stability keeping), or the design's own if smaller.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))"}, "requirements": [{"type":
    ...                    "peak_sensitivity", "max_db": 6}], "controller": {"type": "PI", "bounds": {"kp": [0, 5],
    ...                    "ki": [0, 20]}}, "objective": {"maximize": "integral_gain"}})
    >>> better = ascent_probe(spec, Controller("PI", {"kp": 1.0, "ki": 2.0}), [("integral_gain", "maximize", 1.0)])
    >>> better.parameters["ki"] > 2.0
    True
    """
    bounds = spec.controller.all_bounds()
    free = [k for k in sorted(bounds) if bounds[k][0] < bounds[k][1]]
    x = {k: float(v) for k, v in controller.parameters.items()}
    base = _parts(spec, controller)
    if not free or base is None or not np.all(np.isfinite(base[base < ACTIVE])):
        return None
    nominal = spec.nominal_plant()
    f0 = score(Loop(nominal, controller), terms)
    if not np.isfinite(f0):
        return None
    scales = parameter_scales(x, bounds, free)
    grad_f = np.zeros(len(free))
    active = base < ACTIVE
    grad_g = np.zeros((int(active.sum()), len(free)))
    for j, k in enumerate(free):
        h = _DIFF * scales[j] * (1.0 if x[k] + _DIFF * scales[j] <= bounds[k][1] else -1.0)
        moved = Controller(controller.type, {**x, k: x[k] + h})
        parts = _parts(spec, moved)
        if parts is None:
            return None
        grad_f[j] = (score(Loop(nominal, moved), terms) - f0) / h * scales[j]
        grad_g[:, j] = (parts[active] - base[active]) / h * scales[j]
    if not np.all(np.isfinite(grad_g)) or not np.all(np.isfinite(grad_f)) or not np.any(grad_f):
        return None
    # maximize z: grad_f d >= z |grad_f|, grad_g_i d >= z |grad_g_i|, |d| <= 1 (scaled), bounds kept
    n = len(free)
    rows = [np.append(-grad_f / np.linalg.norm(grad_f), 1.0)]
    for g in grad_g:
        norm = np.linalg.norm(g)
        if norm > 0:
            rows.append(np.append(-g / norm, 1.0))
    box = []
    for j, k in enumerate(free):
        lo, hi = bounds[k]
        box.append((0.0 if x[k] <= lo + 1e-12 * scales[j] else -1.0, 0.0 if x[k] >= hi - 1e-12 * scales[j] else 1.0))
    from scipy.optimize import linprog  # imported when needed: scipy.optimize costs 0.3 s to import

    lp = linprog(np.append(np.zeros(n), -1.0), A_ub=np.array(rows), b_ub=np.zeros(len(rows)),
                 bounds=[*box, (None, 1.0)], method="highs")
    if lp.status != 0 or -lp.fun <= 1e-6:
        return None
    d = lp.x[:n] * scales
    floor = min(keeping, closest_approach(spec.plants(), controller)) if keeping > 0 else 0.0
    for t in STEPS:
        params = dict(x)
        for j, k in enumerate(free):
            params[k] = float(np.clip(x[k] + t * d[j], *bounds[k]))
        trial = Controller(controller.type, params)
        if not score(Loop(nominal, trial), terms) > f0 + MIN_GAIN * max(abs(f0), 1e-12):  # (NaN: no gain)
            continue
        if quick_check(spec, trial).feasible and (floor == 0.0 or closest_approach(spec.plants(), trial) >= floor):
            return trial
    return None


def climb(spec: Spec, controller: Controller, terms: list[tuple[str, str, float]], keeping: float = 0.0,
          rounds: int = CLIMB_ROUNDS) -> tuple[Controller, int]:
    """:func:`ascent_probe` again from each point it finds, at most ``rounds`` times: the last point and the number
    of steps that improved it (0: ``controller`` passed the first-order test).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))"}, "requirements": [{"type":
    ...                    "peak_sensitivity", "max_db": 6}], "controller": {"type": "PI", "bounds": {"kp": [0, 5],
    ...                    "ki": [0, 20]}}, "objective": {"maximize": "integral_gain"}})
    >>> top, steps = climb(spec, Controller("PI", {"kp": 1.0, "ki": 2.0}), [("integral_gain", "maximize", 1.0)])
    >>> steps > 1, top.parameters["ki"] > 5.0
    (True, True)
    """
    steps = 0
    for _ in range(rounds):
        better = ascent_probe(spec, controller, terms, keeping)
        if better is None:
            break
        controller, steps = better, steps + 1
    return controller, steps
