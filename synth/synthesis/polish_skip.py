"""When the NLP polish cannot improve on the convex stage's answer, so that the design skips it."""

from __future__ import annotations

from synth.requirements.base import Requirement
from synth.spec import Spec
from synth.synthesis.convex_forms import CONVEX_FORMS
from synth.synthesis.convex_results import ConvexResult
from synth.synthesis.integral_action import objective_terms
from synth.synthesis.nlp_forms import NLP_FORMS

__all__ = ["exact_forms", "polish_redundant"]


def exact_forms(requirement: Requirement) -> bool:
    """Whether the requirement's convex form and NLP form are both registered as exact: the same set on
    the same frequencies (:data:`~synth.synthesis.convex_forms.CONVEX_FORMS`,
    :data:`~synth.synthesis.nlp_forms.NLP_FORMS`).

    Examples
    --------
    >>> from synth.requirements import Bandwidth, PeakSensitivity
    >>> exact_forms(PeakSensitivity(max_db=6)), exact_forms(Bandwidth(min=10))
    (True, False)
    """
    return CONVEX_FORMS.entry(requirement).exact and NLP_FORMS.entry(requirement).exact


def polish_redundant(spec: Spec, runs: list[ConvexResult]) -> str | None:
    """Why the NLP polish cannot improve on the convex answer, or None when it might.

    The polish is redundant when the convex stage ended at a KKT point of the problem the polish
    would solve: one convex run (no structural parameter to vary) of a P, PI or PID controller, whose
    parameters are then exactly the NLP's variables; every requirement with :func:`exact_forms`, whose
    inner approximations touch the exact constraints at the linearization point with the same gradient
    (the NLP imposes them on the same design and band grids, squared); a linear objective (the integral
    or low-frequency gain), solved directly; and a converged phase 2 (the last convex problem, built
    around the answer, could not improve it beyond the tolerance, and the dense check found nothing
    between the grid points). IPOPT started at a KKT point stays there: the polish would return the
    same design to its tolerance (tests/test_synthesis_polish.py compares both).
    """
    terms = objective_terms(spec)
    if len(runs) != 1 or runs[0].status != "optimal" or not runs[0].converged:
        return None
    if spec.controller.type not in ("P", "PI", "PID"):
        return None
    if not all(exact_forms(r) for r in spec.requirements):
        return None
    if len(terms) != 1 or terms[0][0] not in ("integral_gain", "low_frequency_gain"):
        return None
    return ("the convex answer is a KKT point of the polish's own problem: same parameters, requirements "
            "with exact convex forms, linear objective, converged")
