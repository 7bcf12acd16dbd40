"""Design over one free parameter (a P gain, or any one parameter with the others fixed).

The exact feasible set is computed (:mod:`synth.synthesis.gainset`) and the objective is optimized
over it; the design is re-checked on a grid 20 times denser than the search grid, plus exact
stability, and a design that fails that certificate is not reported as a solution.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from synth.check import check
from synth.edge import edge_distance
from synth.errors import SynthError
from synth.forked import run_beside
from synth.loop import Loop
from synth.objectives import score as objective_score
from synth.progress import announce
from synth.requirements.base import fmt
from synth.results import (
    CERTIFICATE_PER_DECADE,
    Certificate,
    DesignResult,
    objective_label,
    objective_note,
    reference_check,
    reference_verdict,
)
from synth.spec import Spec
from synth.synthesis.gainset import GainSet, ScalarFamily, feasible_gain_set
from synth.synthesis.optimality import Optimality

__all__ = ["INWARD", "RETREAT_STEPS", "design_scalar", "feasible_verdict", "infeasible_verdict", "move_into_set",
           "scalar_family", "scalar_jobs", "stabilizing_text"]


SCALAR_GRID = 61
"""Points per interval of the feasible set at which the objective is evaluated before Brent's method."""


def _optimize_scalar(f: Callable[[float], float], intervals: list[tuple[float, float]]) -> tuple[float, float]:
    """Maximize ``f`` over a union of intervals: grid, then bounded Brent around the best point."""
    from scipy.optimize import minimize_scalar

    best_x, best_v = None, -np.inf
    for lo, hi in intervals:
        if hi <= lo:
            cand = [lo]
        else:
            cand = list(np.linspace(lo, hi, SCALAR_GRID))
        vals = [f(x) for x in cand]
        i = int(np.nanargmax(vals))
        x, v = cand[i], vals[i]
        if hi > lo and np.all(np.isfinite(vals[max(i - 1, 0):i + 2])):  # Brent needs finite values around the best
            a, b = cand[max(i - 1, 0)], cand[min(i + 1, len(cand) - 1)]
            res = minimize_scalar(lambda t: -f(t), bounds=(a, b), method="bounded",
                                  options={"xatol": 1e-10 * max(1.0, abs(b))})
            if -res.fun > v:
                x, v = float(res.x), float(-res.fun)
        if v > best_v or best_x is None:
            best_x, best_v = x, v
    return float(best_x), float(best_v)


INWARD = 1e-6
"""Relative step by which a design at an end set by a requirement is moved into the feasible set
(the end itself has zero slack up to rounding)."""


RETREAT_STEPS = 24
"""Bisection steps from an optimum that failed the dense re-check towards the middle of its interval (the
distance to the passing point shrinks 2^24-fold)."""


def _inside(x: float, gain_set: GainSet, unstable: Callable[[float], bool]) -> float:
    """``x``, or a point ``INWARD`` inside the feasible set when ``x`` is at an end set by a requirement, or at an
    end where the loop is not stable (a closed-loop root on the axis, e.g. kp = 0 on a plant with an integrator:
    the stabilizing set is open there)."""
    for iv in gain_set.intervals:
        step = INWARD * max(abs(x), iv.hi - iv.lo)  # relative: a gain of 5e-5 moves by 5e-11, not by 1e-6
        lo_req = any(not b.startswith("bounds") for b in iv.lo_binding) or (abs(x - iv.lo) <= step and unstable(iv.lo))
        hi_req = (any(not b.startswith("bounds") for b in iv.hi_binding)
                  and not any(b.startswith("bounds") for b in iv.hi_binding)) or (
                      abs(x - iv.hi) <= step and unstable(iv.hi))
        for end, sign, req in ((iv.lo, 1.0, lo_req), (iv.hi, -1.0, hi_req)):
            if req and abs(x - end) <= step:
                inner = step
                while iv.hi - iv.lo > 2 * inner and unstable(end + sign * inner) and inner < 1e-2 * (iv.hi - iv.lo):
                    inner *= 10.0  # a root within the stability floor of the axis: further in
                if iv.hi - iv.lo > 2 * inner:
                    return end + sign * inner
    return x


def scalar_family(spec: Spec) -> tuple[ScalarFamily, tuple[float, float]]:
    """The one-parameter family a spec designs over, and its bounds (error if it has several free parameters).

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> family, bounds = scalar_family(load_spec("specs/x4_rotor.yaml"))
    >>> family.parameter, bounds
    ('kp', (0.0, 20.0))
    """
    bounds = spec.controller.all_bounds()
    free = spec.controller.free_parameters()
    if len(free) != 1:
        raise SynthError(
            f"{spec.controller.type} design over {len(free)} free parameters "
            f"({', '.join(free) or 'none'}) needs the optimizer; the exact gain set handles one",
            where="controller.bounds",
        )
    name = free[0]
    fixed = {p: lo for p, (lo, hi) in bounds.items() if p != name}
    return ScalarFamily(spec.controller.type, name, fixed), bounds[name]


def design_scalar(spec: Spec) -> DesignResult:
    """Design the controller of ``spec`` over its one free parameter: exact feasible set, then the objective.

    Parameters
    ----------
    spec : Spec
        Loaded spec (see :func:`synth.load_spec`).

    Returns
    -------
    DesignResult
        ``feasible`` is False (and ``controller`` None) when no controller in
        the bounds meets every requirement; ``gain_set`` then names the
        conflicting requirements.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> result = design_scalar(load_spec("specs/x4_rotor.yaml"))
    >>> result.feasible, result.controller.parameters["kp"], result.gain_set.contains(3.0)
    (True, 20.0, True)
    """
    jobs, combine = scalar_jobs(spec)
    (reference,), designed = run_beside(jobs[1:], jobs[0])
    return combine([designed, reference])


def scalar_jobs(spec: Spec) -> tuple[list[Callable[[], Any]], Callable[[list[Any]], DesignResult]]:
    """:func:`design_scalar` as two independent jobs, the design and the check of the spec's reference
    controller, and the step that combines their results (the command line runs the jobs on two cores
    beside the report's own preparation: :func:`synth.design.design_jobs`).

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> jobs, combine = scalar_jobs(load_spec("specs/x4_rotor.yaml"))
    >>> result = combine([job() for job in jobs])
    >>> result.controller.parameters["kp"], result.reference.controller.parameters["kp"]
    (20.0, 3.0)
    """
    def combine(results: list[Any]) -> DesignResult:
        (result, verdict_gain_set), reference = results
        result.reference = reference
        result.verdict += reference_verdict(spec, reference, verdict_gain_set)
        return result

    return [lambda: _design_without_reference(spec), lambda: reference_check(spec)], combine


def _design_without_reference(spec: Spec) -> tuple[DesignResult, GainSet | None]:
    """:func:`design_scalar` but for the reference controller's check (run beside it, on the other core where
    the command line allows: :mod:`synth.forked`) and the verdict's sentence on it."""
    family, bounds = scalar_family(spec)
    requirements = list(spec.requirements)
    plants = spec.plants()
    announce(f"exact feasible set of {family.parameter} over {len(plants)} plant(s)")
    gain_set = feasible_gain_set(requirements, plants, family, bounds)
    objective = spec.objective
    sought = f"{objective.sense}d" if objective is not None else "maximized"  # no objective: the smallest slack
    method = f"exact feasible set of {family.parameter} ({gain_set.method}); objective {sought} over it"
    nominal = spec.nominal_plant()

    if not gain_set.intervals:
        def min_slack(x: float) -> float:
            c = family.controller(x)
            return min(r.slack for r in check(spec, c).requirements)

        x, _ = _optimize_scalar(min_slack, gain_set.per_requirement["stability"] or [bounds])  # stabilizing first
        compromise = check(spec, family.controller(x))
        result = DesignResult(spec.name, False, None, None, None, gain_set, None, compromise, method)
        result.verdict = infeasible_verdict(result, family)
        return result, None

    if objective is None:
        def score(x: float) -> float:
            return min(r.slack for r in check(spec, family.controller(x)).requirements)
    else:
        terms = objective.terms()

        def score(x: float) -> float:
            return objective_score(Loop(nominal, family.controller(x)), terms)
    x, _ = _optimize_scalar(score, [(iv.lo, iv.hi) for iv in gain_set.intervals])
    x = _inside(x, gain_set, lambda v: not all(Loop(p, family.controller(v)).stability().stable for p in plants))
    controller = family.controller(x)
    if objective is None:
        label = {"name": "smallest slack", "sense": "maximize", "unit": "Np", "value": float(score(x)),
                 "description": "no objective in the spec: the largest smallest slack"}
    else:
        label = objective_label(spec, Loop(nominal, controller))
    cert_check = check(spec, controller, CERTIFICATE_PER_DECADE)
    if not cert_check.feasible:  # an edge the search grid placed past a sharp peak: move into the set
        inner = move_into_set(x, gain_set, lambda v: check(spec, family.controller(v), CERTIFICATE_PER_DECADE).feasible)
        if inner is not None:
            x, controller = inner, family.controller(inner)
            cert_check = check(spec, controller, CERTIFICATE_PER_DECADE)
            method += (f"; the optimum at the set's end failed the dense re-check, so it moved into the set to the "
                       f"last point that passes it (bisection, {RETREAT_STEPS} checks)")
            label = objective_label(spec, Loop(nominal, controller)) if objective is not None else {
                **label, "value": float(score(x))}
    final = cert_check  # the reported values: the dense re-check's (checking again on the search grid cost a full check)
    certificate = Certificate(cert_check.feasible, CERTIFICATE_PER_DECADE, cert_check)
    feasible = certificate.passed
    result = DesignResult(spec.name, feasible, controller if feasible else None, final, label,
                          gain_set, certificate, None, method)
    result.verdict = feasible_verdict(result, family) if feasible else (
        f"The optimum {controller} failed the dense re-check ("
        + "; ".join(r.message for r in cert_check.failed()) + "): not reported as a solution.")
    if feasible:
        edge = edge_distance(plants, controller, CERTIFICATE_PER_DECADE)
        result.extras["edge_of_stability"] = edge.to_dict()
        result.verdict += edge.warning()
    if feasible and objective is not None:
        optimality = Optimality(True, "exact feasible set", f"the objective {sought} over the exact feasible set of "
                                f"{family.parameter} ({SCALAR_GRID} points per interval, then Brent's method around "
                                "the best)")
        result.extras["optimality"] = optimality.to_dict()
        result.verdict += f" Optimality: {optimality.basis}."
    return result, gain_set


def move_into_set(x: float, gain_set: GainSet, passes: Callable[[float], bool]) -> float | None:
    """The point nearest ``x`` towards the middle of its interval that ``passes`` (bisection between ``x`` and
    the interval's middle, :data:`RETREAT_STEPS` checks), or None when the middle fails too: where an optimum
    at the feasible set's end fails the dense re-check, the design moves back into the set.

    Examples
    --------
    >>> from synth.synthesis.gainset import GainInterval
    >>> gs = GainSet("kp", (0.0, 1.0), [GainInterval(0.0, 1.0, [], [])], {})
    >>> round(move_into_set(1.0, gs, lambda v: v <= 0.8), 6), move_into_set(1.0, gs, lambda v: v < 0.4)
    (0.8, None)
    """
    for iv in gain_set.intervals:
        if iv.lo <= x <= iv.hi:
            good = 0.5 * (iv.lo + iv.hi)
            if not passes(good):
                return None
            bad = x
            for _ in range(RETREAT_STEPS):
                mid = 0.5 * (good + bad)
                good, bad = (mid, bad) if passes(mid) else (good, mid)
            return good
    return None


def _ends(names: list[str]) -> str:
    return " and ".join(names) if names else "nothing"


def feasible_verdict(result: DesignResult, family: ScalarFamily) -> str:
    """Plain-language summary of a successful scalar design.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> feasible_verdict(design_scalar(spec), scalar_family(spec)[0])[:44]
    'P(kp=20) meets all 3 requirements and keeps '
    """
    p = family.parameter
    gs = result.gain_set
    assert result.controller is not None and gs is not None and result.objective is not None
    sets = "; ".join(
        f"{fmt(iv.lo)} <= {p} <= {fmt(iv.hi)} (lower end set by {_ends(iv.lo_binding)}, "
        f"upper end by {_ends(iv.hi_binding)})" for iv in gs.intervals
    )
    obj = result.objective
    return (f"{result.controller} meets all {len(result.check.requirements) - 1} requirements and keeps the "
            f"loop stable ({obj['sense']} {obj['name']}: {fmt(obj['value'])} {obj['unit']}). "
            f"Feasible {p}: {sets}.") + objective_note(obj) + stabilizing_text(gs)


def stabilizing_text(gs: GainSet) -> str:
    """The stabilizing set of the parameter, when it is not the whole search range (exact: D-decomposition).

    Examples
    --------
    >>> from synth.synthesis.gainset import GainInterval
    >>> stabilizing_text(GainSet("kp", (0.0, 20.0), [], {"stability": [(0.5, 20.0)]}))
    ' The closed loop is stable only for kp in (0.5, 20] (exact, D-decomposition); the search stayed inside it.'
    """
    lo, hi = gs.bounds
    stab = gs.per_requirement.get("stability")
    if stab is None or stab == [(lo, hi)]:
        return ""
    if not stab:
        return f" No {gs.parameter} in [{fmt(lo)}, {fmt(hi)}] stabilizes the closed loop (exact, D-decomposition)."
    ivs = ", ".join(f"{'[' if a == lo else '('}{fmt(a)}, {fmt(b)}{']' if b == hi else ')'}" for a, b in stab)
    return (f" The closed loop is stable only for {gs.parameter} in {ivs} (exact, D-decomposition); "
            "the search stayed inside it.")


def infeasible_verdict(result: DesignResult, family: ScalarFamily) -> str:
    """Plain-language explanation of why no value works.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor_strict.yaml")
    >>> infeasible_verdict(design_scalar(spec), scalar_family(spec)[0])[:40]
    'No kp in [0, 5] meets every requirement.'
    """
    p = family.parameter
    gs = result.gain_set
    assert gs is not None
    lo, hi = gs.bounds
    parts = [f"No {p} in [{fmt(lo)}, {fmt(hi)}] meets every requirement."]
    for name in gs.never_met():
        wide = gs.outside_bounds.get(name) or []
        if wide:
            where = ", ".join(f"[{fmt(a)}, {fmt(b)}]" for a, b in wide)
            parts.append(f"{name} is met by no {p} within the bounds; it would need {p} in {where} "
                         "(searched up to ten times the upper bound).")
        else:
            parts.append(f"{name} is met by no {p} within the bounds nor ten times beyond.")
    for a, b in gs.conflicts():
        parts.append(f"{a} and {b} conflict: {a} needs {p} in "
                     f"{_ivs(gs.per_requirement[a])}, {b} needs {_ivs(gs.per_requirement[b])}.")
    stab = stabilizing_text(gs)
    if stab:
        parts.append(stab.strip())
    if result.compromise is not None:
        failed = result.compromise.failed()
        parts.append(f"Best compromise {result.compromise.controller} (not a solution): "
                     + "; ".join(r.message for r in failed) + ".")
    return " ".join(parts)


def _ivs(ivs: list[tuple[float, float]]) -> str:
    return ", ".join(f"[{fmt(a)}, {fmt(b)}]" for a, b in ivs)
