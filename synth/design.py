"""Design a controller for a spec.

With one free parameter (a P gain, or any one parameter with the others
fixed) the exact feasible set is computed (:mod:`synth.gainset`) and the
objective is optimized over it. With several, the convex-concave procedure
of :mod:`synth.synthesis` designs the controller. Every returned design is re-checked on a
grid 20 times denser than the one used while searching, plus exact
stability; a design that fails that certificate is not reported as a
solution.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from synth.check import CheckResult, check
from synth.controllers import Controller
from synth.errors import SynthError
from synth.gainset import GainSet, ScalarFamily, feasible_gain_set
from synth.loop import Loop
from synth.objectives import measure
from synth.objectives import score as objective_score
from synth.requirements.base import fmt
from synth.spec import Spec

SEARCH_PER_DECADE = 80
CERTIFICATE_PER_DECADE = 20 * SEARCH_PER_DECADE


@dataclass
class Certificate:
    """Dense re-check of a design.

    Attributes
    ----------
    passed : bool
        Every requirement met and the loop stable on every plant.
    per_decade : int
        Grid density of the re-check (points per decade, plus local refinement
        of every peak and crossing).
    check : CheckResult
        The re-check itself.
    """

    passed: bool
    per_decade: int
    check: CheckResult

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            "passed": self.passed,
            "grid": f"log grid, {self.per_decade} points per decade, peaks and crossings refined",
            "per_decade": self.per_decade,
            "stability": [r.details | {"plant": r.plant} for r in self.check.requirements
                          if r.type == "stability"],
            "slacks": {r.label: r.slack for r in self.check.requirements},
        }


@dataclass
class DesignResult:
    """Outcome of :func:`design`.

    Attributes
    ----------
    spec : str
        Spec name.
    feasible : bool
        A controller meeting every requirement was found and certified.
    controller : Controller or None
        The design (None when infeasible).
    check : CheckResult or None
        Requirements evaluated at the design.
    objective : dict or None
        ``{"name", "sense", "value", "unit"}`` of the optimized measure.
    gain_set : GainSet or None
        Exact feasible set, for one free parameter.
    certificate : Certificate or None
        Dense re-check of the design.
    compromise : CheckResult or None
        When infeasible: the value with the largest smallest slack, to show
        where and by how much the requirements fail. Not a solution.
    reference : CheckResult or None
        The spec's reference controller (e.g. a published design) checked.
    method : str
        How the design was found.
    verdict : str
        Plain-language summary.
    """

    spec: str
    feasible: bool
    controller: Controller | None
    check: CheckResult | None
    objective: dict[str, Any] | None
    gain_set: GainSet | None
    certificate: Certificate | None
    compromise: CheckResult | None = None
    method: str = ""
    verdict: str = ""
    reference: CheckResult | None = None
    extras: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict; ``requirements`` and ``gain_set`` at top level as the CLI contract asks."""
        shown = self.check if self.check is not None else self.compromise
        out: dict[str, Any] = {
            "spec": self.spec,
            "feasible": self.feasible,
            "verdict": self.verdict,
            "method": self.method,
            "controller": self.controller.to_dict() if self.controller else None,
            "objective": self.objective,
            "requirements": [r.to_dict() for r in shown.requirements] if shown else [],
        }
        if self.gain_set is not None:
            out["gain_set"] = self.gain_set.as_list()
            out["gain_set_detail"] = self.gain_set.to_dict()
        if self.certificate is not None:
            out["certificate"] = self.certificate.to_dict()
        if self.compromise is not None:
            out["compromise"] = {"note": "best compromise, NOT a solution: it violates the requirements below",
                                 **self.compromise.to_dict()}
        if self.reference is not None:
            out["reference_check"] = self.reference.to_dict()
        out.update(self.extras)
        return out


def _optimize_scalar(f: Callable[[float], float], intervals: list[tuple[float, float]]) -> tuple[float, float]:
    """Maximize ``f`` over a union of intervals: grid, then bounded Brent around the best point."""
    best_x, best_v = None, -np.inf
    for lo, hi in intervals:
        if hi <= lo:
            cand = [lo]
        else:
            cand = list(np.linspace(lo, hi, 61))
        vals = [f(x) for x in cand]
        i = int(np.nanargmax(vals))
        x, v = cand[i], vals[i]
        if hi > lo and np.all(np.isfinite(vals[max(i - 1, 0):i + 2])):  # Brent needs finite values around the best
            a, b = cand[max(i - 1, 0)], cand[min(i + 1, len(cand) - 1)]
            res = minimize_scalar(lambda t: -f(t), bounds=(a, b), method="bounded",
                                  options={"xatol": 1e-10 * max(1.0, abs(b))})
            if -res.fun > v:
                x, v = float(res.x), float(-res.fun)
        if v > best_v:
            best_x, best_v = x, v
    return float(best_x), float(best_v)


INWARD = 1e-6
"""Relative step by which a design at an end set by a requirement is moved into the feasible set
(the end itself has zero slack up to rounding)."""


def _inside(x: float, gain_set: GainSet) -> float:
    for iv in gain_set.intervals:
        step = INWARD * max(1.0, abs(x), iv.hi - iv.lo)
        lo_req = any(not b.startswith("bounds") for b in iv.lo_binding)
        hi_req = any(not b.startswith("bounds") for b in iv.hi_binding)
        if lo_req and abs(x - iv.lo) <= step and iv.hi - iv.lo > 2 * step:
            return iv.lo + step
        if hi_req and abs(x - iv.hi) <= step and iv.hi - iv.lo > 2 * step and not any(
                b.startswith("bounds") for b in iv.hi_binding):
            return iv.hi - step
    return x


def scalar_family(spec: Spec) -> tuple[ScalarFamily, tuple[float, float]]:
    """The one-parameter family a spec designs over (error if it has several free parameters)."""
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


def design(spec: Spec) -> DesignResult:
    """Design the controller of ``spec``.

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
    >>> result = design(load_spec("specs/x4_rotor.yaml"))
    >>> result.feasible, result.controller.parameters["kp"], result.gain_set.contains(3.0)
    (True, 20.0, True)
    """
    if len(spec.controller.free_parameters()) != 1:
        from synth.synthesis.multi import design_convex

        return design_convex(spec)
    family, bounds = scalar_family(spec)
    requirements = list(spec.requirements)
    plants = spec.plants()
    gain_set = feasible_gain_set(requirements, plants, family, bounds)
    method = f"exact feasible set of {family.parameter} ({gain_set.method}); objective maximized over it"
    objective = spec.objective
    nominal = spec.nominal_plant()

    if not gain_set.intervals:
        def min_slack(x: float) -> float:
            c = family.controller(x)
            return min(r.slack for r in check(spec, c).requirements)

        x, _ = _optimize_scalar(min_slack, [bounds])
        compromise = check(spec, family.controller(x))
        result = DesignResult(spec.name, False, None, None, None, gain_set, None, compromise, method,
                              reference=reference_check(spec))
        result.verdict = infeasible_verdict(result, family) + reference_verdict(spec, result.reference)
        return result

    if objective is None:
        def score(x: float) -> float:
            return min(r.slack for r in check(spec, family.controller(x)).requirements)
    else:
        terms = objective.terms()

        def score(x: float) -> float:
            return objective_score(Loop(nominal, family.controller(x)), terms)
    x, _ = _optimize_scalar(score, [(iv.lo, iv.hi) for iv in gain_set.intervals])
    x = _inside(x, gain_set)
    controller = family.controller(x)
    if objective is None:
        label = {"name": "smallest slack", "sense": "maximize", "unit": "Np", "value": float(score(x)),
                 "description": "no objective in the spec: the largest smallest slack"}
    else:
        label = objective_label(spec, Loop(nominal, controller))
    final = check(spec, controller, SEARCH_PER_DECADE)
    cert_check = check(spec, controller, CERTIFICATE_PER_DECADE)
    certificate = Certificate(cert_check.feasible, CERTIFICATE_PER_DECADE, cert_check)
    feasible = certificate.passed
    result = DesignResult(spec.name, feasible, controller if feasible else None, final, label,
                          gain_set, certificate, None, method, reference=reference_check(spec))
    result.verdict = (feasible_verdict(result, family) if feasible else (
        f"The optimum {controller} failed the dense re-check ("
        + "; ".join(r.message for r in cert_check.failed()) + "): not reported as a solution.")
    ) + reference_verdict(spec, result.reference, gain_set)
    return result


def objective_label(spec: Spec, loop: Loop) -> dict[str, Any]:
    """``{"name", "sense", "unit", "description", "value"}`` of the spec's objective at ``loop``."""
    obj = spec.objective
    assert obj is not None
    if obj.weighted is None:
        m = measure(obj.name)
        return {"name": m.name, "sense": obj.sense, "unit": m.unit, "description": m.description,
                "value": float(m.evaluate(loop))}
    parts = {n: float(measure(n).evaluate(loop)) for n, _, _ in obj.terms()}
    return {"name": "weighted", "sense": "maximize", "unit": "", "description": obj.describe(),
            "value": objective_score(loop, obj.terms()), "terms": parts}


def _ends(names: list[str]) -> str:
    return " and ".join(names) if names else "nothing"


def feasible_verdict(result: DesignResult, family: ScalarFamily) -> str:
    """Plain-language summary of a successful scalar design."""
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
            f"Feasible {p}: {sets}.")


def infeasible_verdict(result: DesignResult, family: ScalarFamily) -> str:
    """Plain-language explanation of why no value works."""
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
    if result.compromise is not None:
        failed = result.compromise.failed()
        parts.append(f"Best compromise {result.compromise.controller} (not a solution): "
                     + "; ".join(r.message for r in failed) + ".")
    return " ".join(parts)


def reference_verdict(spec: Spec, ref: CheckResult | None, gain_set: GainSet | None = None) -> str:
    """One or two sentences on the spec's reference controller (empty without one)."""
    if ref is None:
        return ""
    source = f" ({spec.reference.source})" if spec.reference and spec.reference.source else ""
    if ref.feasible:
        text = f" The reference {ref.controller}{source} meets every requirement"
        if gain_set is not None:
            value = ref.controller.parameters.get(gain_set.parameter)
            if value is not None:
                text += f" and lies {'inside' if gain_set.contains(value) else 'outside'} the feasible set"
        return text + "."
    return (f" The reference {ref.controller}{source} does not meet every requirement: "
            + "; ".join(r.message for r in ref.failed()) + ".")


def _ivs(ivs: list[tuple[float, float]]) -> str:
    return ", ".join(f"[{fmt(a)}, {fmt(b)}]" for a, b in ivs)


def reference_controller(spec: Spec) -> Controller | None:
    """The spec's reference controller (e.g. the paper's P(3)), if any."""
    if spec.reference is None or spec.reference.controller is None:
        return None
    return Controller.from_string(spec.reference.controller)


def reference_check(spec: Spec) -> CheckResult | None:
    """Requirements evaluated at the spec's reference controller."""
    c = reference_controller(spec)
    return check(spec, c) if c is not None else None
