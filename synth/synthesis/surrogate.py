"""Requirements without a solver form inside the design loop: a certified outer loop on a convex surrogate.

Step-response limits and "no limit cycle" have no convex or NLP form (:data:`CERTIFIED_ONLY`): with several
free parameters the convex and NLP stages cannot see them, and before this loop the certificate rejected
every design they made (a PI design with ``max_overshoot`` fell back to a ``ki = 0`` design).
:func:`design_certified` designs without them, and when the design fails them, designs again under a
surrogate with exact solver forms, peak ``|S|`` and peak ``|T|`` both at most ``level`` dB (the overshoot
follows the resonance peak of ``T``, a limit cycle the distance of ``L`` to ``-1`` and its critical loci),
bisecting on ``level`` for the loosest one whose design passes the exact check of every requirement
(certificate density). The surrogate is only a search direction: every returned design passed the full
certificate, and the method says which level was used and how many designs the bisection took. A bisection
on the segment from the chosen design towards the first design that failed the exact check
(:data:`LINE_STEPS` checks) moves it closer to the limits when that scores better and still passes; then a
pattern search on the exact check (:func:`synth.synthesis.pattern.pattern_search`) walks it to where the
requirements themselves bind (the surrogate's level bounds the whole loop, not the step).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from synth.check import check, quick_check
from synth.controllers import Controller
from synth.errors import NoStabilizingStartError
from synth.loop import Loop
from synth.objectives import score
from synth.progress import within
from synth.requirements import NoLimitCycle, PeakComplementary, PeakSensitivity, StepResponse
from synth.requirements.base import Requirement, db, fmt
from synth.results import (
    CERTIFICATE_PER_DECADE,
    Certificate,
    DesignResult,
    describe_objective,
    objective_label,
    objective_note,
)
from synth.spec import Spec
from synth.speculation import Speculator
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.exact_search import exact_search
from synth.synthesis.integral_action import objective_terms
from synth.synthesis.no_start import no_start_result
from synth.synthesis.parametrization import STRUCTURAL
from synth.synthesis.pattern import pattern_search

__all__ = ["BISECTIONS", "CERTIFIED_ONLY", "LINE_STEPS", "RESOLUTION_DB", "SEARCH_CHECKS", "certified_only",
           "design_certified", "surrogate_spec"]

CERTIFIED_ONLY = (StepResponse, NoLimitCycle)
"""Requirement types with no convex or NLP form: the certificate (and this loop) enforce them."""
BISECTIONS = 6
"""Designs of the bisection on the surrogate level after the first (it stops earlier at :data:`RESOLUTION_DB`)."""
LINE_STEPS = 4
"""Exact checks of the last step, from the chosen design towards the first one that failed."""
SEARCH_CHECKS = 400
"""Most checks of the pattern search after the surrogate (it stops earlier at its smallest step): a PID's design
climbs a ridge of the step limit in three parameters (160 checks left one at ki 1.88 where 400 reach 2.98)."""
RESOLUTION_DB = 0.1
"""The bisection stops when the passing and the failing levels are this close (dB)."""
_FLOOR_DB = 0.05  # peak |S| is at least 1 for every loop of relative degree >= 2, peak |T| with integral action


def certified_only(spec: Spec) -> list[Requirement]:
    """The spec's requirements with no solver form (:data:`CERTIFIED_ONLY`).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "s", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "PI"},
    ...                    "requirements": [{"type": "step_response", "max_overshoot": 5},
    ...                                     {"type": "bandwidth", "min": 1}]})
    >>> [r.type for r in certified_only(spec)]
    ['step_response']
    """
    return [r for r in spec.requirements if isinstance(r, CERTIFIED_ONLY)]


def surrogate_spec(spec: Spec, level_db: float | None) -> Spec:
    """``spec`` without its :func:`certified_only` requirements, with peak ``|S|`` and ``|T|`` at most
    ``level_db`` instead (none when ``level_db`` is None).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "s", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "PI"},
    ...                    "requirements": [{"type": "step_response", "max_overshoot": 5}]})
    >>> [(r.type, r.max_db) for r in surrogate_spec(spec, 2.0).requirements]
    [('peak_sensitivity', 2.0), ('peak_complementary', 2.0)]
    """
    kept = [r for r in spec.requirements if not isinstance(r, CERTIFIED_ONLY)]
    if level_db is not None:
        kept += [PeakSensitivity(max_db=level_db, label="surrogate: peak |S|"),
                 PeakComplementary(max_db=level_db, label="surrogate: peak |T|")]
    return spec.model_copy(update={"requirements": kept})


def _start_level(hard: list[Requirement]) -> float:
    """The peak |T| of a second-order loop with the tightest overshoot limit (its damping), in dB; else 3 dB."""
    bounds = [r.max_overshoot for r in hard if isinstance(r, StepResponse) and r.max_overshoot is not None]
    if not bounds:
        return 3.0
    lo = np.log(max(min(bounds), 1e-3) / 100.0)
    zeta = -lo / np.sqrt(np.pi**2 + lo**2)
    return float(db(1.0 / (2 * zeta * np.sqrt(1 - zeta**2)))) if zeta < np.sqrt(0.5) else 0.5


def _peaks_db(spec: Spec, result: DesignResult) -> float:
    loops = [Loop(p, result.controller) for p in spec.plants()]
    return max(max(PeakSensitivity(max_db=0).evaluate(lp).value, PeakComplementary(max_db=0).evaluate(lp).value)
               for lp in loops)


def _better(a: DesignResult, b: DesignResult) -> bool:
    va, vb = a.objective["value"], b.objective["value"]
    return va > vb if a.objective["sense"] == "maximize" else va < vb


def design_certified(spec: Spec, design_fn: Callable[[Spec], DesignResult],
                     trial_fn: Callable[[Spec], DesignResult] | None = None) -> DesignResult:
    """``design_fn(spec)``, and when the spec has requirements with no solver form that its design could not
    meet (or met only by dropping the integral action), the certified outer loop of this module.

    The better of the two certified designs is returned (the plain one when the loop finds nothing).
    ``trial_fn`` makes the bisection's designs under the surrogate (default ``design_fn``): a cheaper one (the
    convex stage without the NLP polish) does, since the design it picks is then moved by the exact check.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> from synth.synthesis.multi import design_convex
    >>> spec = parse_spec({"name": "os", "plant": {"tf": "2/((s+1)*(s+2))"},
    ...     "controller": {"type": "PI", "bounds": {"kp": [0.01, 5], "ki": [0, 10]}},
    ...     "requirements": [{"type": "step_response", "max_overshoot": 10}],
    ...     "objective": {"maximize": "integral_gain"}})
    >>> r = design_certified(spec, design_convex)
    >>> r.feasible, r.certificate.passed, r.certificate.check.requirements[1].value <= 10
    (True, True, True)
    >>> round(r.controller.parameters["ki"], 2), r.extras["surrogate"]["designs"] <= 3 + BISECTIONS
    (1.76, True)
    """
    hard = certified_only(spec)
    if not hard:
        return design_fn(spec)
    with within(f"outer loop 1/{BISECTIONS + 3} (no surrogate bound)"):
        free = design_fn(surrogate_spec(spec, None))
    no_start = free.extras.get("undetermined", {})
    if no_start.get("reason") == "no stabilizing start":  # same plants and bounds, same seeded search: same answer
        return no_start_result(spec, NoStabilizingStartError(no_start["searched"], searched=no_start["searched"]))
    if not free.feasible:  # the other requirements already fail: nothing for the surrogate to add
        return design_fn(spec)
    loose = _peaks_db(spec, free)  # the free design's level: too loose (it fails the exact check)
    level = float(np.clip(_start_level(hard), _FLOOR_DB + 0.2, max(loose - 0.2, _FLOOR_DB + 0.2)))
    held = _held_structure(spec, free.controller)
    make = trial_fn or design_fn
    trial_make = make if held is None else (lambda s: make(s.with_parameter_fixed(held[0], held[1])))
    with Speculator(lambda level: _trial(spec, trial_make, level)) as guesses:  # the idle core
        guesses.ahead(level)  # while the free design is checked
        if quick_check(spec, free.controller).feasible:
            return _certified(spec, free, None, 1)
        best, tried, over = _bisection(guesses, level, loose, free.controller, 1)
    if best is None and held is not None:  # no level passed with the structure held: its grid in each design
        held = None
        with Speculator(lambda level: _trial(spec, make, level)) as guesses:
            best, tried, over = _bisection(guesses, level, loose, free.controller, tried)
    integral_only = all(n in ("integral_gain", "low_frequency_gain") and sense == "maximize"
                        for n, sense, _ in objective_terms(spec))
    found = None
    if best is not None:
        refined, checks = _toward(spec, best[0].controller, over)
        found = _certified(spec, best[0], best[1], tried, refined, checks, held=held) if refined is not None else None
        if found is None or not found.feasible:
            found = _certified(spec, best[0], best[1], tried, held=held)
        if found.feasible:
            # the surrogate bounds peak |S| and |T| where the requirement bounds the time response: its loosest
            # passing level leaves room (a PI with an overshoot limit: ki 8.79 -> 12.9); a pattern search on the
            # exact check from there takes it
            moved = checks if found.controller is refined else 0  # the segment's checks, when they moved it
            found = _searched(spec, found, lambda c, n: _certified(spec, best[0], best[1], tried, c, moved, n,
                                                                   held=held))
    if found is not None and integral_only:  # the plain design can only do better by dropping integral action
        return found
    if best is None and integral_only and len(hard) == len(spec.requirements):
        # nothing but certified-only requirements: the plain design's stages see none of them (it is the free
        # design again, then a screen and polishes that only its certificate judges), so the search of the
        # bounds on the exact check goes first and the plain design is made only if that search finds nothing
        return _last_resort(spec, None, free, tried, lambda: design_fn(spec))
    plain = design_fn(spec)
    if best is None:
        return _last_resort(spec, plain, free, tried)
    assert found is not None
    if plain.feasible and _better(plain, found):
        return plain
    return found


def _bisection(guesses: Speculator, level: float, loose: float, over: Controller, tried: int
               ) -> tuple[tuple[DesignResult, float] | None, int, Controller]:
    """The bisection on the surrogate's level from ``level`` (``loose``: a level whose design fails the exact
    check) down to :data:`_FLOOR_DB`: the best design that passed and its level (or None), the number of designs
    made (``tried`` before), and the last design that failed the exact check (``over`` when none did)."""
    best, tight = None, _FLOOR_DB  # no design below this level
    for _ in range(BISECTIONS + 2):
        if level - tight >= RESOLUTION_DB and not guesses.expects(level):  # the next level should this fail
            guesses.ahead(float(np.sqrt(tight * level)))
        with within(f"outer loop {tried + 1}/{BISECTIONS + 3} (surrogate bound {level:.2f} dB)"):
            trial, designed, passes = guesses.value(level)
        tried += 1
        if passes:  # the certificate re-checks the chosen one
            if best is None or _better(trial, best[0]):
                best = (trial, level)
            tight = level  # passes: a looser level may do better
        elif designed or best is not None:
            loose = level  # fails the exact check (or, above a level that passed, no design: stay below)
            over = trial.controller if designed else over
        else:
            tight = level  # no design and nothing passed yet: the surrogate is too strict
        if loose - tight < RESOLUTION_DB:
            break
        level = float(np.sqrt(tight * loose))  # geometric: the free level can be tens of dB
    return best, tried, over


def _held_structure(spec: Spec, controller: Controller) -> tuple[str, float, str] | None:
    """The structural parameter (:data:`~synth.synthesis.parametrization.STRUCTURAL`: a PID's filter, a lead-lag's
    pole), its value in ``controller`` and its unit, when the spec leaves it free; the surrogate's designs hold it
    there.
    Each design of the bisection is then one convex run instead of the structural grid's eleven or more, and the
    pattern search on the exact check that follows moves it with the other parameters (session 62's PID on
    ``2/((s-0.5)(s+4)) e^(-0.05 s)`` with step limits: 4 min 44 s -> 1 min 41 s, control effort 8.285 -> 8.322 dB;
    benchmarks/README.md, "Certified designs with a free structural parameter")."""
    key = STRUCTURAL.get(spec.controller.type)
    if key is None or controller.parameters.get(key) is None:
        return None
    lo, hi = spec.controller.all_bounds()[key]
    return None if lo == hi else (key, float(np.clip(controller.parameters[key], lo, hi)), controller.kind.units[key])


def _trial(spec: Spec, make: Callable[[Spec], DesignResult], level: float) -> tuple[DesignResult, bool, bool]:
    """The design under the surrogate at ``level`` dB, whether it is a design (not the structure's fallback),
    and whether it passes the exact check."""
    trial = make(surrogate_spec(spec, level))
    designed = trial.feasible and "alternatives" not in trial.extras
    return trial, designed, designed and quick_check(spec, trial.controller).feasible


def _toward(spec: Spec, inside: Controller, outside: Controller) -> tuple[Controller | None, int]:
    """The best-scoring controller on the segment from ``inside`` (passes the exact check) towards ``outside``
    (fails it) that passes the exact check (bisection, :data:`LINE_STEPS` checks), or None when none beats
    ``inside``; and the number of checks."""
    if inside.type != outside.type:
        return None, 0
    terms = objective_terms(spec)
    nominal = spec.nominal_plant()
    base = score(Loop(nominal, inside), terms)
    lo, hi, found = 0.0, 1.0, None
    for _ in range(LINE_STEPS):
        t = 0.5 * (lo + hi)
        c = inside.with_parameters(**{p: (1 - t) * inside.parameters[p] + t * outside.parameters[p]
                                      for p in inside.parameters})
        if quick_check(spec, c).feasible and score(Loop(nominal, c), terms) > base:
            lo, found = t, c
        else:
            hi = t
    return found, LINE_STEPS


def _last_resort(spec: Spec, plain: DesignResult | None, free: DesignResult, tried: int,
                 make_plain: Callable[[], DesignResult] | None = None) -> DesignResult:
    """No design under the surrogate passed: the plain design (which meets the requirements, when it does, often
    only without integral action) improved by a pattern search on the exact check, or what a search of the
    whole box on the exact check finds (:func:`synth.synthesis.exact_search.exact_search`), whichever scores
    better and passes the certificate. With ``plain`` None the search starts near the free design and what it
    finds is returned; ``make_plain()`` makes the plain design only when the search finds nothing."""
    hard = ", ".join(r.type for r in certified_only(spec))
    none_passes = f"; certified-only requirements ({hard}): no design under peak |S|, |T| <= {fmt(_FLOOR_DB)} dB " \
                  "passes them either"
    opening = f"designed with them ({tried} designs under the surrogate found none that passes)"
    with within("search of the bounds on the exact check"):
        near = plain.controller if plain is not None and plain.controller is not None else free.controller
        found = exact_search(spec, near)
    searched = None
    if found.controller is not None:
        walked = ("; one of them reached by a walk on the requirements' worst slack from the least violating "
                  "sample" if found.walked else "")
        how = (f"found by a search of the bounds on the exact check ({found.samples} controllers sampled, "
               f"{found.checked_samples} checked in order of score; pattern search from the best {found.starts} "
               f"that passed, a few sample spacings apart{walked}; {found.checks} "
               f"checks), as {tried} designs under the surrogate found none that passes")
        base = plain if plain is not None else free
        searched = _certified(spec, replace(base, method=base.method + none_passes), None, tried,
                              found.controller, 0, 0, how)
        if plain is None and searched.feasible:
            return searched
    if plain is None:
        assert make_plain is not None
        plain = make_plain()
    plain = replace(plain, method=plain.method + none_passes)
    out = _searched(spec, plain, lambda c, n: _certified(spec, plain, None, tried, c, 0, n, opening))
    if searched is None:
        out.method += (f"; a search of the bounds on the exact check found no controller that passes "
                       f"({found.samples} sampled, {found.checks} checks)")
        return out
    if searched.feasible and (not out.feasible or _better(searched, out)):
        return searched
    return out


def _searched(spec: Spec, result: DesignResult, certify: Callable[[Controller, int], DesignResult]) -> DesignResult:
    """``result``, or what a pattern search on the exact check from its controller found (certified by
    ``certify(controller, checks)``) when that scores better and passes the certificate."""
    if not result.feasible or result.controller is None:
        return result
    with within("pattern search on the exact check"):
        search = pattern_search(spec, result.controller, objective_terms(spec), max_checks=SEARCH_CHECKS,
                                keeping=ConvexSettings().stability_level)
    if not search.improved:
        return result
    moved = certify(search.controller, search.checks)
    return moved if moved.feasible else result


def _certified(spec: Spec, result: DesignResult, level: float | None, tried: int,
               controller: Controller | None = None, checks: int = 0, searched: int = 0,
               opening: str | None = None, held: tuple[str, float, str] | None = None) -> DesignResult:
    """``result`` (designed on a surrogate spec), or ``controller`` found from it (by ``checks`` checks on the
    segment towards the first design that failed, then ``searched`` checks of a pattern search), re-checked
    and certified against ``spec`` itself; ``opening`` says how ``result`` was made when not by the surrogate;
    ``held``: the structural parameter the surrogate's designs held (:func:`_held_structure`)."""
    chosen = controller or result.controller
    cert = check(spec, chosen, CERTIFICATE_PER_DECADE)  # dense; the step response is grid-free
    hard = ", ".join(r.type for r in certified_only(spec))
    how = opening or ("designed without them and met as designed" if level is None else
                      f"designed with peak |S| and |T| <= {fmt(level)} dB instead, the loosest level at which the "
                      f"exact check passed (bisection, {tried} designs"
                      + (f", {held[0]} held at {fmt(held[1])} {held[2]}, its value in the design without them"
                         if held else "")
                      + ")")
    if controller is not None and checks:
        how += (f", then moved towards the first design that failed it while the exact check passes "
                f"(bisection on the segment, {checks} checks)")
    if searched:
        how += f", then improved by a pattern search on the exact check ({searched} checks)"
    extras: dict[str, Any] = {**result.extras, "surrogate": {"requirements": hard, "level_db": level,
                                                             "designs": tried, "segment_checks": checks,
                                                             "pattern_checks": searched,
                                                             "held": None if held is None else {held[0]: held[1]}}}
    objective = result.objective if controller is None or spec.objective is None else \
        objective_label(spec, Loop(spec.nominal_plant(), chosen))
    out = DesignResult(spec.name, cert.feasible, chosen, cert, objective, None,
                       Certificate(cert.feasible, CERTIFICATE_PER_DECADE, cert), None,
                       result.method + f"; requirements with no solver form ({hard}): {how}; certificate: every "
                       "requirement re-checked exactly", reference=result.reference, extras=extras)
    value = f" ({describe_objective(spec, objective)})" if objective is not None and "value" in objective else ""
    out.verdict = (f"{chosen} meets all {len(spec.requirements)} requirements and keeps the loop "
                   f"stable on {len(spec.plants())} plant(s){value}; {hard}: {how}.") + objective_note(objective)
    return out
