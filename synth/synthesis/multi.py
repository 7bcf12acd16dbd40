"""Design with several free parameters: convex stage, NLP polish, certificate, diagnosis.

1. **Convex** (:mod:`synth.synthesis.convex`) on the linear parametrization. A PID filter ``tf`` or lead-lag
   pole ``p`` that is free is held at a few log-spaced values and the best is kept.
2. **NLP polish** (:mod:`synth.synthesis.nlp`) from the convex answer, every parameter free, requirements and
   objective exact. It is skipped when it cannot add anything: the convex stage converged to a KKT point of
   the very problem the NLP would solve (see :func:`polish_redundant`) and that answer passed the certificate.
3. **Certificate**: each candidate is re-checked on a grid 20 times denser (plus refined peaks and crossings)
   and for exact closed-loop stability; the best candidate that passes is the design. None passing means no
   solution is reported, and the answer is "undetermined", as it is when no stabilizing start is found.

When the integral gain may be zero, the structure without it is designed too (a type-0 loop has
``|T(0)| < 1``, which changes the bandwidth and static readings) and the better certified design wins.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from synth.check import check
from synth.controllers import Controller
from synth.edge import edge_distance
from synth.errors import NoStabilizingStartError, SynthError
from synth.loop import Loop
from synth.objectives import score
from synth.progress import announce, within
from synth.requirements.base import fmt, unique_names
from synth.results import (
    CERTIFICATE_PER_DECADE,
    Certificate,
    DesignResult,
    describe_objective,
    objective_label,
    objective_note,
    reference_check,
    reference_verdict,
)
from synth.spec import Spec
from synth.synthesis.ascent_probe import climb
from synth.synthesis.conflict_set import conflict_set
from synth.synthesis.convex import ConvexDesigner
from synth.synthesis.convex_results import ConvexResult, infeasible_verdict
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.integral_action import integral_only, objective_terms, without_integral_action
from synth.synthesis.nlp import polish
from synth.synthesis.no_start import no_start_result
from synth.synthesis.optimality import Optimality, optimality_of
from synth.synthesis.parametrization import STRUCTURAL, parametrize, reference_frequency, structural_values
from synth.synthesis.pattern import BOUNDARY_CHECKS, pattern_search
from synth.synthesis.polish_skip import exact_forms, polish_redundant
from synth.synthesis.rational_rescale import rescaled_run
from synth.synthesis.scalar import design_scalar
from synth.synthesis.screen import SCREEN_ITERATIONS, screen_improving, screen_size, screen_starts
from synth.synthesis.screen_polish import near_misses_polished, near_misses_text, polished_from
from synth.synthesis.stabilizing_slices import open_loop_unstable, slices_text, stabilizing_slices

__all__ = ["STRUCTURAL", "STRUCTURAL_REFINEMENTS", "certificate_density", "choose", "conflict_set", "convex_runs",
           "design_convex", "design_trial", "design_with_integral_action", "exact_forms", "infeasible_verdict",
           "objective_terms", "polish_redundant"]

IMPROVEMENT = 0.01
"""A screened controller is a start for another NLP polish when it scores this much (relative) better than the
certified design."""

STRUCTURAL_REFINEMENTS = 5
"""Times the structural grid (three values over the bounds) is bisected around its best run: a feasible set
or an optimum between two of the three values (a lead-lag pole over three decades) is not missed. Five
bisections narrow a bracket of three decades to a factor of about 1.25; with two (a factor of 2.4) the design
benchmark's fresh seed 8 ended 5-12 % below the reference on lead-lags whose optimum had the zero at its bound
and the pole between two bracket values (problems 133, 166, 269)."""


def design_convex(spec: Spec, settings: ConvexSettings | None = None, nlp: bool | str = True) -> DesignResult:
    """Design a controller with several free parameters and certify it.

    ``nlp``: True runs the NLP polish unless :func:`polish_redundant` shows it cannot improve the convex
    answer; ``"always"`` runs it regardless (for comparison); False never.

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
    main = _design(spec, settings, nlp)
    without = without_integral_action(spec)
    if without is None or not _may_need_alternative(spec, main):  # else the alternative cannot win
        return main
    with within("without integral action"):
        alt = design_scalar(without) if len(without.controller.free_parameters()) == 1 else design_convex(without)
    return choose(spec, main, alt)


def design_with_integral_action(spec: Spec) -> DesignResult:
    """The design of the spec as written (default settings), without :func:`design_convex`'s second design
    with ``ki = 0``: one of the two jobs of :func:`synth.design.design_jobs`, combined by :func:`choose`.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "23*(s+0.43)/((s+9.6)*(s+0.54))", "delay": 0.02},
    ...                    "controller": {"type": "PI", "bounds": {"kp": [0, 10], "ki": [0, 200]}},
    ...                    "requirements": [{"type": "peak_sensitivity", "max_db": 6}],
    ...                    "objective": {"maximize": "integral_gain"}})
    >>> round(design_with_integral_action(spec).controller.parameters["ki"], 2)
    24.93
    """
    return _design(spec, ConvexSettings(), True)


def design_trial(spec: Spec) -> DesignResult:
    """The convex stage's certified design of ``spec`` alone: no NLP polish, no second design without integral
    action, and no search for the conflicting requirements when it fails. The certified outer loop's trials
    under a surrogate bound (:mod:`synth.synthesis.surrogate`) read only whether a design passes and how it
    scores (an infeasible trial of x4_pi_step spent 1.8 s on the fallback and the conflicts, unread).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "23*(s+0.43)/((s+9.6)*(s+0.54))", "delay": 0.02},
    ...                    "controller": {"type": "PI", "bounds": {"kp": [0, 10], "ki": [0, 200]}},
    ...                    "requirements": [{"type": "peak_sensitivity", "max_db": 6}],
    ...                    "objective": {"maximize": "integral_gain"}})
    >>> r = design_trial(spec)
    >>> r.feasible, r.certificate.passed, "NLP" in r.method
    (True, True, False)
    """
    return _design(spec, ConvexSettings(), False, explain=False)


def _may_need_alternative(spec: Spec, main: DesignResult) -> bool:
    """False when the design with integral action wins whatever the other finds."""
    return not (main.feasible and integral_only(spec))


def choose(spec: Spec, main: DesignResult, alt: DesignResult) -> DesignResult:
    """``main`` (designed with integral action) unless ``alt`` (the same structure with ``ki = 0``) is feasible
    and scores better; the choice :func:`design_convex` makes.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "PI"},
    ...                    "requirements": [{"type": "bandwidth", "min": 1.0}]})
    >>> no = DesignResult("pi", False, None, None, None, None, None, None, "")
    >>> choose(spec, no, no) is no
    True
    """
    if not _may_need_alternative(spec, main):
        return main
    if alt.feasible and (not main.feasible or _better(alt, main)):
        alt.method = (main.method + "; the same structure without integral action (ki = 0) did better: "
                      + alt.method)
        alt.extras.setdefault("alternatives", []).append({"with_integral_action": main.objective})
        unit = f" {alt.objective['unit']}" if alt.objective.get("unit") else ""
        than = (f"{alt.objective['value']:.6g} against {main.objective['value']:.6g}{unit} with ki free"
                if main.feasible else "with ki free no feasible design was found")
        alt.verdict = f"{alt.verdict.rstrip()} The design without integral action (ki = 0) was kept: {than}."
        return alt
    return main


def _better(a: DesignResult, b: DesignResult) -> bool:
    va, vb = a.objective["value"], b.objective["value"]
    return va > vb if a.objective["sense"] == "maximize" else va < vb


def convex_runs(spec: Spec, settings: ConvexSettings) -> list[tuple[ConvexDesigner, ConvexResult]]:
    """The convex-concave design from each structural start (e.g. three filter constants of a PID).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "23*(s+0.43)/((s+9.6)*(s+0.54))"},
    ...                    "controller": {"type": "PI"}, "objective": {"maximize": "integral_gain"},
    ...                    "requirements": [{"type": "peak_sensitivity", "max_db": 6.0}]})
    >>> [result.status for _, result in convex_runs(spec, ConvexSettings())]
    ['optimal']
    """
    bounds = spec.controller.all_bounds()
    ctype = spec.controller.type
    key = STRUCTURAL.get(ctype)
    values = structural_values(*bounds[key]) if key else [None]
    requirements = list(spec.requirements)
    names = unique_names(requirements)
    name, sense, _ = objective_terms(spec)[0]
    runs = []
    w0 = reference_frequency(spec)
    start = spec.controller.initial_controller()
    tried: dict[float, tuple[ConvexDesigner, ConvexResult]] = {}

    def run(v: float | None) -> None:
        announce("convex stage" + (f", {key} = {fmt(v)} (run {len(tried) + 1})" if key else ""))
        b = dict(bounds) if key is None else {**bounds, key: (v, v)}
        par = parametrize(ctype, b, spec.controller.order, w0)
        designer = ConvexDesigner(requirements, names, spec.plants(), par, (name, sense), settings)
        initial = None
        if start is not None:
            fixed = start if key is None else start.with_parameters(**{key: v})
            initial = par.rho(fixed)
        try:
            runs.append((designer, designer.run(initial)))
        except SynthError as e:  # no stabilizing start at this value of the structural parameter
            if key is None:
                raise
            no_start.append(e)
            return
        if v is not None:
            tried[float(v)] = runs[-1]

    no_start: list[SynthError] = []
    for v in values:
        run(v)
    if not runs:
        raise no_start[0]
    if key is None and runs[0][1].status != "optimal":  # a rational loop far above the plant's corners
        runs.extend([rescaled] if (rescaled := rescaled_run(spec, settings, names, (name, sense))) else [])
    if key is not None and len(values) > 1:
        terms, nominal = objective_terms(spec), spec.nominal_plant()

        def rank(v: float) -> tuple[float, float]:
            """Feasible runs by objective, the others by their exact total violation (the elastic total of a
            run that stalled, every step towards the linearized answer destabilizing, is not a measure)."""
            res = tried[v][1]
            if res.status == "optimal":
                return (1.0, float(score(Loop(nominal, res.controller), terms)))
            return (0.0, sum(min(r.slack, 0.0) for r in check(spec, res.controller).requirements))

        for _ in range(STRUCTURAL_REFINEMENTS):  # bisect the structural parameter around the best run
            grid = sorted(tried)
            if not grid:
                break
            i = max(range(len(grid)), key=lambda j: rank(grid[j]))
            for j in (i - 1, i + 1):
                if 0 <= j < len(grid):
                    a, b = sorted((grid[i], grid[j]))
                    run(float(np.sqrt(a * b)) if a > 0 else 0.5 * (a + b))
    return runs


def certificate_density(settings: ConvexSettings, grids: list[np.ndarray]) -> int:
    """Points per decade of the certificate: at least 20 times the densest grid the design used (the
    band grids at ``settings.per_decade``, the design grid, with its refinement points, on average over
    its span), and at least :data:`synth.results.CERTIFICATE_PER_DECADE`.

    Examples
    --------
    >>> certificate_density(ConvexSettings(), [np.geomspace(0.01, 1e4, 500)])
    1664
    """
    density = float(settings.per_decade)
    for g in grids:
        decades = float(np.log10(g[-1] / g[0])) if g.size > 1 and g[0] > 0 else 0.0
        if decades > 0:
            density = max(density, (g.size - 1) / decades)
    return int(max(CERTIFICATE_PER_DECADE, np.ceil(20 * density)))


def _certify(spec: Spec, controller: Controller, per_decade: int) -> Certificate:
    cert = check(spec, controller, per_decade)
    return Certificate(cert.feasible, per_decade, cert)


def _certify_best(spec: Spec, found: list[tuple[str, Controller]], terms: list[tuple[str, str, float]],
                  per_decade: int, cache: dict[int, Certificate] | None = None, scores: list[float] | None = None
                  ) -> tuple[list[tuple[str, Controller, Certificate]], tuple[str, Controller, Certificate] | None]:
    """The best-scoring candidate that passes the certificate, and every candidate certified on the way.

    Candidates are certified from the best score down and the search stops at the first that passes: the
    same choice as certifying all of them and taking the best that passed (ties keep the earlier
    candidate), without certifying designs that could not be chosen. When none passes, all are certified
    and returned in their original order. ``cache`` keeps certificates by candidate index across calls
    (a list that only grows at its end), ``scores`` the candidates' scores in their order (a design certifies
    up to seven times as candidates are added: each candidate is scored once).
    """
    nominal = spec.nominal_plant()
    scores = [] if scores is None else scores
    scores.extend(score(Loop(nominal, c), terms) for _, c in found[len(scores):])
    order = sorted(range(len(found)), key=lambda i: -scores[i])  # stable: ties keep the original order
    certified: dict[int, Certificate] = {} if cache is None else cache
    for i in order:
        if i not in certified:
            certified[i] = _certify(spec, found[i][1], per_decade)
        if certified[i].passed:
            return [(*found[k], certified[k]) for k in sorted(certified)], (*found[i], certified[i])
    return [(*found[k], certified[k]) for k in range(len(found))], None


def initial_in_bounds(spec: Spec) -> Controller | None:
    """The spec's ``controller.initial``, when every parameter of it lies within the spec's bounds (the design
    without integral action fixes ``ki`` at 0, outside a start that has one).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "requirements": [{"type": "bandwidth",
    ...                    "min": 1.0}], "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]},
    ...                    "initial": {"kp": 1.0, "ki": 2.0}}})
    >>> str(initial_in_bounds(spec)), initial_in_bounds(without_integral_action(spec))
    ('PI(kp=1, ki=2)', None)
    """
    start = spec.controller.initial_controller()
    if start is None:
        return None
    bounds = spec.controller.all_bounds()
    return start if all(lo <= start.parameters[p] <= hi for p, (lo, hi) in bounds.items()) else None


def _design(spec: Spec, settings: ConvexSettings, nlp: bool | str, explain: bool = True) -> DesignResult:
    terms = objective_terms(spec)
    try:
        runs = convex_runs(spec, settings)
    except NoStabilizingStartError as e:
        return no_start_result(spec, e)
    per_decade = certificate_density(settings, [d.grid for d, _ in runs])
    nominal = spec.nominal_plant()
    found: list[tuple[str, Controller]] = [("convex", conv.controller) for _, conv in runs
                                           if conv.status == "optimal"]
    initial = initial_in_bounds(spec)
    if initial is not None:  # the spec's own start is a candidate: no design scores below it if it certifies
        found.append(("initial", initial))
    feasible_runs = [(d, r) for d, r in runs if r.status == "optimal"]
    extras: dict[str, Any] = {"synthesis": {"convex": [r.to_dict() for _, r in runs]}}
    unconverged = {str(r.controller) for _, r in runs if r.status == "optimal" and not r.converged}
    screened = ""
    ref = reference_check(spec)
    stages = [f"convex-concave (cvxpy + Clarabel) on {runs[0][1].grid_points} frequency points x "
              f"{len(spec.plants())} plant(s), {sum(r.solves for _, r in runs)} convex solves"]
    if len(runs) > 1 and spec.controller.type in STRUCTURAL:
        stages[0] += f", {len(runs)} fixed values of {STRUCTURAL[spec.controller.type]}"
    stages[0] += "".join(f"; {r.note}" for _, r in runs if r.note)
    cache: dict[int, Certificate] = {}
    scores: list[float] = []
    redundant = polish_redundant(spec, [r for _, r in runs]) if nlp is True else None
    if redundant is not None:
        _, passed = _certify_best(spec, found, terms, per_decade, cache, scores)
        if passed is not None:
            nlp = False
            extras["synthesis"]["nlp_skipped"] = redundant
            stages.append(f"NLP polish skipped ({redundant})")
    if nlp:
        if feasible_runs:
            start_designer, start = max(feasible_runs,
                                        key=lambda dr: score(Loop(nominal, dr[1].controller), terms))
        else:
            start_designer, start = min(runs, key=lambda dr: dr[1].diagnosis.total_slack)
        announce("NLP polish (casadi + IPOPT)")
        res = polish(list(spec.requirements), spec.plants(), start.controller, spec.controller.all_bounds(),
                     terms, start_designer.grid, settings.per_decade, settings.stability_level)
        extras["synthesis"]["nlp"] = res.to_dict()
        exact = " (limited-memory BFGS; exact Hessian after it stopped at its iteration limit)" \
            if any("exact_hessian" in h for h in res.history) else ""
        stages.append(f"NLP polish (casadi + IPOPT{exact}, {res.iterations} iterations, {res.status})")
        found.extend(("nlp", c) for c in reversed(res.candidates))
        unconverged.update(h["controller"] for h in res.history if h.get("offered"))
        if initial is not None:  # the convex runs fix a structural parameter on their own grid: its basin is lost
            announce("NLP polish from the spec's initial controller")
            res = polish(list(spec.requirements), spec.plants(), initial, spec.controller.all_bounds(), terms,
                         runs[0][0].grid, settings.per_decade, settings.stability_level)
            found.extend(("nlp from initial", c) for c in reversed(res.candidates))
            unconverged.update(h["controller"] for h in res.history if h.get("offered"))
            stages.append(f"NLP polish from the spec's initial controller ({res.iterations} iterations, "
                          f"{res.status})")
    candidates, passed = _certify_best(spec, found, terms, per_decade, cache, scores)
    if passed is not None and nlp and spec.objective is not None:  # a local optimum? better points elsewhere
        value = score(Loop(nominal, passed[1]), terms)
        announce(f"screen of {screen_size(spec)} controllers for better starts")
        above = value + IMPROVEMENT * max(abs(value), 1e-12)
        starts = screen_improving(spec, terms, above)
        found.extend(kc for c in starts for kc in polished_from(spec, [c], terms, runs[0][0].grid, settings,
                                                                  unconverged))
        if starts:
            candidates, passed = _certify_best(spec, found, terms, per_decade, cache, scores)
        near, near_polished = [], []
        if passed is not None and (score(Loop(nominal, passed[1]), terms) if starts else value) < above:  # no start: the
            # near misses, as when no start led 1 % higher (seed 16 #118: a screen of 1536 held starts, which polished
            # back to the old basin)
            near, near_polished = near_misses_polished(spec, terms, above, runs[0][0].grid, settings, unconverged)
            found.extend(kc for p in near_polished for kc in p)
            if near:
                candidates, passed = _certify_best(spec, found, terms, per_decade, cache, scores)
        stages.append(f"random screen of the bounds ({screen_size(spec)} controllers): {len(starts)} scored more "
                      "than 1 % better on its grid" + (", NLP polish from each" if starts else "")
                      + (", NLP polish from the least violating of those that score better" if near else "")
                      + (" and from the least violating one apart from it in the box" if len(near) > 1 else ""))
        screened = (f"a random screen of {screen_size(spec)} controllers over the bounds found "
                    + (f"{len(starts)} scoring more than 1 % better on its grid, polished" if starts
                       else "none scoring more than 1 % better on its grid"))
        if near:
            screened += near_misses_text(near_polished, passed)
    if passed is None and nlp:  # the local stages found nothing that certifies: starts from the whole box
        announce(f"nothing certified: screen of {screen_size(spec)} controllers")
        starts = screen_starts(spec)
        found.extend(polished_from(spec, starts, terms, runs[0][0].grid, settings, unconverged))
        stages.append(f"random screen of the bounds ({screen_size(spec)} controllers, every requirement and plant): "
                      f"NLP polish from the {len(starts)} least violating (at most 3 rounds of {SCREEN_ITERATIONS} "
                      "iterations each)")
        candidates, passed = _certify_best(spec, found, terms, per_decade, cache, scores)
    if nlp and passed is not None and spec.objective is not None and optimality_of(passed[0], str(passed[1]),
                                                                                   unconverged).local:
        climbed, steps = climb(spec, passed[1], terms, settings.stability_level)  # the claim, on the exact check
        if steps:
            found.append(("ascent probe", climbed))
            stages.append(f"first-order test of the {passed[0]} design on the exact requirements: {steps} steps up")
            candidates, passed = _certify_best(spec, found, terms, per_decade, cache, scores)
    searched = ""
    if passed is not None and spec.objective is not None \
            and not optimality_of(passed[0], str(passed[1]), unconverged).local:
        # the best certified design is not a converged stage's answer (a raw screened point, an IPOPT round
        # stopped at its limit, a convex bisection): pattern search on the exact check from it
        announce("pattern search")
        search = pattern_search(spec, passed[1], terms, max_checks=BOUNDARY_CHECKS, keeping=settings.stability_level,
                                boundary_moves=True)
        stages.append(f"pattern search on the exact check from the {passed[0]} design ({search.checks} checks, "
                      f"{'improved' if search.improved else 'no improvement'})")
        if search.improved:
            found.append(("pattern search", search.controller))
            if nlp:  # the polish again, from a start better than the stages had (seed 8 #190: 0.31 -> 1.0 rad/s)
                announce("NLP polish from the pattern search's design")
                res = polish(list(spec.requirements), spec.plants(), search.controller,
                             spec.controller.all_bounds(), terms, runs[0][0].grid, settings.per_decade,
                             settings.stability_level)
                found.extend(("nlp from pattern search", c) for c in reversed(res.candidates))
                unconverged.update(h["controller"] for h in res.history if h.get("offered"))
                stages.append(f"NLP polish from the pattern search's design ({res.iterations} iterations, "
                              f"{res.status})")
            candidates, passed = _certify_best(spec, found, terms, per_decade, cache, scores)
        if passed is not None and passed[0] not in ("pattern search", "nlp from pattern search"):
            searched = ("a pattern search on the exact check from it found a better point that failed the dense "
                        "certificate" if search.improved else "a pattern search on the exact check from it found no "
                        f"better point (steps down to {search.final_step:.0e} of each parameter's scale, "
                        f"{search.checks} checks)" if search.checks > 1 else "a pattern search on the exact check "
                        "could not start from it (it fails the search's own check)")
    method = "; ".join(stages) + f"; certificate: dense re-check, {per_decade} points per decade"
    if passed is not None:
        stage, controller, certificate = passed
        label = objective_label(spec, Loop(nominal, controller)) if spec.objective else {
            "name": "peak_sensitivity", "sense": "minimize", "unit": "dB",
            "value": float(-score(Loop(nominal, controller), terms)),
            "note": "no objective in the spec: the most robust design (smallest peak |S|) is returned"}
        extras["synthesis"]["chosen"] = stage
        optimality = optimality_of(stage, str(controller), unconverged, "; ".join(x for x in (searched, screened) if x),
                                   settings.stability_level) if spec.controller.free_parameters() else Optimality(
            True, stage, "the only controller the bounds allow (every parameter fixed): nothing to optimize")
        extras["optimality"] = optimality.to_dict()
        slices = stabilizing_slices(spec, controller) if open_loop_unstable(spec) else {}
        if slices:
            extras["stabilizing_slices"] = {k: [list(iv) for iv in v] for k, v in slices.items()}
        edge = edge_distance(spec.plants(), controller, CERTIFICATE_PER_DECADE)
        extras["edge_of_stability"] = edge.to_dict()
        result = DesignResult(spec.name, True, controller, certificate.check, label, None, certificate,
                              None, method + f"; chosen: {stage}", reference=ref, extras=extras)
        result.verdict = (f"{controller} meets all {len(spec.requirements)} requirements and keeps the loop "
                          f"stable on {len(spec.plants())} plant(s) ({describe_objective(spec, label)}).") \
            + objective_note(label) + edge.warning() \
            + (f" Optimality: {optimality.basis}." if spec.objective is not None else "") \
            + slices_text(slices, spec.plants()) + reference_verdict(spec, ref)
        return result
    if feasible_runs:  # optimal on the grid but none survives the certificate
        stage, controller, certificate = candidates[-1]
        result = DesignResult(spec.name, False, None, check(spec, controller), None, None, certificate, None,
                              method, reference=ref, extras=extras, status="undetermined")
        result.verdict = (f"The best design found, {controller} ({stage}), failed the dense re-check ("
                          + "; ".join(r.message for r in certificate.check.failed())
                          + "): not reported as a solution.") + reference_verdict(spec, ref)
        return result
    worst = min(runs, key=lambda dr: dr[1].diagnosis.total_slack)[1]
    if explain:
        worst.diagnosis.conflict_set = conflict_set(spec, settings)
    compromise = check(spec, worst.controller)
    result = DesignResult(spec.name, False, None, None, None, None, None, compromise, method, reference=ref,
                          extras=extras)
    result.extras["diagnosis"] = worst.diagnosis.to_dict()
    nlp_note = ""
    from_closest = [c for c in candidates if c[0] == "nlp"]
    if from_closest:  # the NLP returned something from the infeasible start, and it failed the certificate
        stage, controller, certificate = from_closest[-1]
        nlp_note = (f" The NLP started from the closest design ended at {controller}, which fails the "
                    "certificate (" + "; ".join(r.message for r in certificate.check.failed()) + ").")
    screened = sum(1 for c in candidates if c[0] in ("screen", "nlp from screen"))
    if screened:
        nlp_note += (f" {screened} more candidate(s) from the random screen of the bounds and NLP polishes from "
                     "them fail it too.")
    nlp_note += "".join(f" Also tried: {r.note}." for _, r in runs if r.note)
    result.verdict = infeasible_verdict(worst, compromise) + nlp_note + reference_verdict(spec, ref)
    return result
