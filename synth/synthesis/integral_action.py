"""Whether a design is also run without integral action, decided from the spec alone (no solver imports).

A PI or PID whose integral gain may be zero is designed twice, with and without it: a type-0 loop has
``|T(0)| < 1``, which changes the bandwidth and static readings, so the structure without integral action is
not a point the first design's local search reaches. The two designs are independent (two cores).
"""

from __future__ import annotations

from synth.spec import Spec

__all__ = ["integral_only", "objective_terms", "without_integral_action"]


def objective_terms(spec: Spec) -> list[tuple[str, str, float]]:
    """The spec's objective as ``(measure, sense, weight)`` terms; minimum peak |S| when it has none.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "PI"},
    ...                    "requirements": [{"type": "bandwidth", "min": 1.0}]})
    >>> objective_terms(spec)
    [('peak_sensitivity', 'minimize', 1.0)]
    """
    return spec.objective.terms() if spec.objective else [("peak_sensitivity", "minimize", 1.0)]


def without_integral_action(spec: Spec) -> Spec | None:
    """The spec with ``ki`` fixed at 0 when its bounds let the integral gain be zero and positive; else None.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "PI",
    ...                    "bounds": {"kp": [0, 5], "ki": [0, 2]}}, "requirements": [{"type": "bandwidth", "min": 1.0}]})
    >>> without_integral_action(spec).controller.all_bounds()["ki"]
    (0.0, 0.0)
    """
    bounds = spec.controller.all_bounds()
    if "ki" not in bounds or bounds["ki"][0] != 0.0 or bounds["ki"][1] == 0.0:
        return None
    return spec.with_parameter_fixed("ki", 0.0)


def integral_only(spec: Spec) -> bool:
    """Every objective term maximizes the integral (or low-frequency) gain: 0 or finite without integral
    action, so a feasible design with it always wins.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> integral_only(parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "PI"},
    ...                           "requirements": [{"type": "bandwidth", "min": 1.0}],
    ...                           "objective": {"maximize": "integral_gain"}}))
    True
    """
    return all(n in ("integral_gain", "low_frequency_gain") and s == "maximize" for n, s, _ in objective_terms(spec))
