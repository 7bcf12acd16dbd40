"""The answer of a design whose search found no controller in the bounds that stabilizes the loop."""

from __future__ import annotations

from synth.errors import NoStabilizingControllerError, NoStabilizingStartError
from synth.results import DesignResult, reference_check, reference_verdict
from synth.spec import Spec

__all__ = ["no_start_result"]


def no_start_result(spec: Spec, error: NoStabilizingStartError) -> DesignResult:
    """The "undetermined" answer of a design whose search found no stabilizing controller in the bounds.

    Random controllers that all destabilize the loop show that the stabilizing set is small or empty, not
    that it is empty: the verdict says what was searched and is neither feasible nor infeasible. When the
    error is a :class:`~synth.errors.NoStabilizingControllerError` (the bounds were shown to hold no stabilizing
    controller), the answer is "infeasible" and says what shows it.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "u", "plant": {"tf": "1.9/(s-0.92)", "delay": 1.7},
    ...                    "controller": {"type": "PI", "bounds": {"kp": [0, 6], "ki": [0, 10]}},
    ...                    "requirements": [{"type": "margins", "gain_margin_db": 6}]})
    >>> r = no_start_result(spec, NoStabilizingStartError("600 random controllers gave none"))
    >>> r.status, r.feasible, r.verdict[:27]
    ('undetermined', False, 'No controller in the bounds')
    """
    ref = reference_check(spec)
    searched = error.searched
    n = len(spec.plants())
    on = "the plant" if n == 1 else f"all {n} plants"
    if isinstance(error, NoStabilizingControllerError):  # shown, not only searched: the design is infeasible
        verdict = (f"No controller in the bounds stabilizes the loop on {on}, so no requirement can be met "
                   f"(exact: {error.proof}). Widen the bounds (negative gains included where the plant needs "
                   "them) or choose another controller structure." + reference_verdict(spec, ref))
        return DesignResult(spec.name, False, None, None, None, None, None, None,
                            f"stabilizing set: {error.proof}", verdict, reference=ref,
                            extras={"infeasible": {"reason": "no stabilizing controller", "proof": error.proof}},
                            status="infeasible")
    verdict = (f"No controller in the bounds was found that stabilizes the loop on {on}, so no "
               f"requirement could be evaluated ({searched}). The bounds may hold no stabilizing controller; a "
               "search that found none does not prove it."
               + reference_verdict(spec, ref))
    return DesignResult(spec.name, False, None, None, None, None, None, None,
                        f"stabilizing start search: {searched}", verdict, reference=ref,
                        extras={"undetermined": {"reason": "no stabilizing start", "searched": searched}},
                        status="undetermined")
