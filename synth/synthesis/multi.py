"""Design with several free parameters: convex-concave optimization, certificate, diagnosis."""

from __future__ import annotations

from synth.check import check
from synth.design import (
    CERTIFICATE_PER_DECADE,
    Certificate,
    DesignResult,
    reference_check,
    reference_verdict,
)
from synth.gainset import _unique_names
from synth.requirements.base import fmt
from synth.spec import Spec
from synth.synthesis.convex import ConvexDesigner, ConvexResult, ConvexSettings
from synth.synthesis.parametrization import parametrize


def design_convex(spec: Spec, settings: ConvexSettings | None = None) -> DesignResult:
    """Design a linearly parametrized controller by convex-concave optimization and certify it.

    When the integral gain may be zero, the structure without it (a type-0 loop,
    whose |T(0)| < 1 changes the bandwidth and static-sensitivity readings) is
    designed too, and the better certified design is returned.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec('''
    ... name: pi
    ... plant: {tf: "23*(s+0.43)/((s+9.6)*(s+0.54))", delay: 0.02}
    ... controller: {type: PI, bounds: {kp: [0, 10], ki: [0, 200]}}
    ... requirements: [{type: peak_sensitivity, max_db: 6}]
    ... objective: {maximize: integral_gain}''')
    >>> r = design_convex(spec)
    >>> r.feasible, round(r.controller.parameters["ki"], 2)
    (True, 24.93)
    """
    settings = settings or ConvexSettings()
    main = _design_convex(spec, settings)
    bounds = spec.controller.all_bounds()
    if "ki" not in bounds or bounds["ki"][0] != 0.0 or bounds["ki"][1] == 0.0:
        return main
    without = spec.model_copy(update={"controller": spec.controller.model_copy(
        update={"bounds": {**bounds, "ki": (0.0, 0.0)}})})
    from synth.design import design

    alt = design(without)
    if alt.feasible and (not main.feasible or _better(alt, main)):
        alt.method = (main.method + "; the same structure without integral action (ki = 0) did better: "
                      + alt.method)
        alt.extras.setdefault("alternatives", []).append({"ki_free": main.to_dict().get("objective")})
        return alt
    return main


def _better(a: DesignResult, b: DesignResult) -> bool:
    va, vb = a.objective["value"], b.objective["value"]
    return va > vb if a.objective["sense"] == "maximize" else va < vb


def _design_convex(spec: Spec, settings: ConvexSettings) -> DesignResult:
    requirements = list(spec.requirements)
    names = _unique_names(requirements)
    par = parametrize(spec.controller.type, spec.controller.all_bounds())
    objective = (spec.objective.name, spec.objective.sense) if spec.objective else None
    designer = ConvexDesigner(requirements, names, spec.plants(), par, objective, settings)
    convex = designer.run()
    method = (f"convex-concave optimization over ({', '.join(par.names)}) with cvxpy + Clarabel on "
              f"{convex.grid_points} frequency points per plant x {len(spec.plants())} plant(s); "
              f"{convex.solves} convex solves")
    ref = reference_check(spec)
    extras = {"synthesis": convex.to_dict()}
    if convex.status != "optimal":
        compromise = check(spec, convex.controller)
        result = DesignResult(spec.name, False, None, None, None, None, None, compromise, method,
                              reference=ref, extras=extras)
        result.verdict = infeasible_verdict(convex) + reference_verdict(spec, ref)
        return result
    controller = convex.controller
    final = check(spec, controller)
    per_decade = max(CERTIFICATE_PER_DECADE, 20 * settings.per_decade)
    cert_check = check(spec, controller, per_decade)
    certificate = Certificate(cert_check.feasible, per_decade, cert_check)
    label = _objective_label(spec, designer, convex)
    feasible = certificate.passed
    result = DesignResult(spec.name, feasible, controller if feasible else None, final, label, None,
                          certificate, None, method, reference=ref, extras=extras)
    if feasible:
        result.verdict = (f"{controller} meets all {len(requirements)} requirements and keeps the loop stable on "
                          f"{len(spec.plants())} plant(s) ({label['sense']} {label['name']}: "
                          f"{fmt(label['value'])} {label['unit']}).") + reference_verdict(spec, ref)
    else:
        result.verdict = (f"The optimum {controller} failed the dense re-check ("
                          + "; ".join(r.message for r in cert_check.failed()) + "): not reported as a solution.")
    return result


def _objective_label(spec: Spec, designer: ConvexDesigner, convex: ConvexResult) -> dict:
    from synth.objectives import measure

    name, sense = designer.objective
    m = measure(name)
    label = {"name": name, "sense": sense, "unit": m.unit, "description": m.description,
             "value": designer.measure(convex.rho)}
    if spec.objective is None:
        label["note"] = "no objective in the spec: the most robust design (smallest peak |S|) is returned"
    return label


def infeasible_verdict(convex: ConvexResult) -> str:
    """Plain-language explanation of an infeasible convex design."""
    diag = convex.diagnosis
    assert diag is not None
    parts = ["The requirements cannot all be met within the controller bounds."]
    violated = [c for c in diag.conflicts if c.violated]
    pushing = [c for c in diag.conflicts if not c.violated and c.name in diag.conflicting()]
    if violated:
        parts.append("Closest design (minimum total violation) still violates: "
                     + "; ".join(f"{c.name} (slack {c.exact_slack:+.3g} Np: {c.message})" for c in violated) + ".")
    if pushing:
        parts.append("Requirements that hold there but push against them (dual price > 0): "
                     + ", ".join(f"{c.name} (price {c.price:.3g})" for c in pushing) + ".")
    if diag.bounds_active:
        parts.append("Active parameter bounds: " + ", ".join(diag.bounds_active) + ".")
    parts.append("Conflicting: " + ", ".join(diag.conflicting()) + ".")
    return " ".join(parts)
