"""Design a controller for a spec: the dispatcher.

With one free parameter (a P gain, or any one parameter with the others fixed) the exact feasible
set is computed and the objective optimized over it (:func:`synth.synthesis.scalar.design_scalar`).
With several, the convex-concave procedure and the NLP polish design the controller
(:func:`synth.synthesis.multi.design_convex`); requirements with no solver form (step response, no limit
cycle) are met by a certified outer loop on a convex surrogate (:mod:`synth.synthesis.surrogate`).
Every returned design is re-checked on a grid 20 times denser than the one used while searching, plus
exact stability; a design that fails that certificate is not reported as a solution. The result types
live in :mod:`synth.results`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from synth.results import DesignResult
from synth.spec import Spec
from synth.synthesis.scalar import design_scalar

__all__ = ["design", "design_jobs", "with_tracking_caveat"]


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
        the bounds meets every requirement; ``gain_set`` (one free parameter)
        then names the conflicting requirements.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> result = design(load_spec("specs/x4_rotor.yaml"))
    >>> result.feasible, result.controller.parameters["kp"], result.gain_set.contains(3.0)
    (True, 20.0, True)
    """
    return with_tracking_caveat(spec, _designed(spec))


def _designed(spec: Spec) -> DesignResult:
    """:func:`design` before its verdict's tracking caveat (which the combining step of :func:`design_jobs` adds once,
    to the design it keeps)."""
    if len(spec.controller.free_parameters()) == 1:
        return design_scalar(spec)
    from synth.synthesis.multi import design_convex, design_trial  # cvxpy and casadi: several parameters only
    from synth.synthesis.surrogate import design_certified

    # the surrogate's bisection only needs to know which level passes: its designs are the convex stage's alone
    return design_certified(spec, design_convex, design_trial)


def with_tracking_caveat(spec: Spec, result: DesignResult) -> DesignResult:
    """``result`` with its verdict saying so when the design's loop on the nominal plant barely follows the reference
    (:func:`synth.requirements.tracking.tracking_caveat`); said once, however often this is applied.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "idle", "plant": {"tf": "5/((s+1)*(s+4))"}, "requirements": [
    ...     {"type": "margins", "gain_margin_db": 6}], "controller": {"type": "P", "bounds": {"kp": [0, 10]}},
    ...     "objective": {"minimize": "control_effort"}})
    >>> design(spec).verdict.split("; but ")[1][:45]
    'its loop follows a slow reference to only 0 o'
    """
    from synth.loop import Loop
    from synth.requirements.tracking import tracking_caveat

    if not result.feasible or result.controller is None:
        return result
    note = tracking_caveat(Loop(spec.nominal_plant(), result.controller))
    if note and note not in result.verdict:
        text = result.verdict.rstrip()
        result.verdict = f"{text.removesuffix('.')}{note}{'.' if text.endswith('.') else ''}"
    return result


def design_jobs(spec: Spec) -> tuple[list[Callable[[], Any]], Callable[[list[Any]], DesignResult]]:
    """:func:`design` as independent jobs and the step that combines their results into its answer.

    A PI or PID whose integral gain may be zero is designed with and without integral action; the two
    designs are independent, so the command line runs them on two cores (:func:`synth.forked.run_beside`).
    One free parameter: the design and the check of the spec's reference controller. Everything else is
    one job. ``combine(results)`` is what :func:`design` returns.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> jobs, combine = design_jobs(load_spec("specs/x4_rotor.yaml"))
    >>> len(jobs), combine([job() for job in jobs]).controller.parameters["kp"]
    (2, 20.0)
    """
    from synth.synthesis.integral_action import integral_only, without_integral_action
    from synth.synthesis.surrogate import certified_only

    if len(spec.controller.free_parameters()) == 1:  # the design and the reference controller's check
        from synth.synthesis.scalar import scalar_jobs

        jobs, combine_scalar = scalar_jobs(spec)
        return jobs, lambda results: with_tracking_caveat(spec, combine_scalar(results))
    without = without_integral_action(spec)
    if certified_only(spec) or without is None \
            or integral_only(spec):  # maximize ki: the design without it only runs when this one fails
        return [lambda: design(spec)], lambda results: results[0]

    def with_integral_action() -> DesignResult:  # cvxpy and casadi are imported in the job, on its core
        from synth.synthesis.multi import design_with_integral_action

        return design_with_integral_action(spec)

    def combine(results: list[DesignResult]) -> DesignResult:
        from synth.synthesis.multi import choose

        return with_tracking_caveat(spec, choose(spec, *results))

    return [with_integral_action, lambda: _designed(without)], combine
