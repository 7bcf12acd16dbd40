"""Result types of a design: the dense certificate, the design result, and what both quote.

:class:`DesignResult` is what every design method returns (the one-parameter exact set in
:mod:`synth.synthesis.scalar`, the convex and NLP stages in :mod:`synth.synthesis.multi`), with the
:class:`Certificate` (a dense re-check at :data:`CERTIFICATE_PER_DECADE` points per decade or more),
the objective's label and the spec's reference controller checked.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from synth.check import CheckResult, check
from synth.controllers import Controller
from synth.loop import BANDWIDTH_LEVEL, Loop
from synth.objectives import in_plant_units, measure
from synth.objectives import score as objective_score
from synth.requirements.base import fmt
from synth.spec import Spec

if TYPE_CHECKING:
    from synth.synthesis.gainset import GainSet

__all__ = [
    "CERTIFICATE_PER_DECADE",
    "DESIGN_STATUSES",
    "SEARCH_PER_DECADE",
    "Certificate",
    "DesignResult",
    "objective_label",
    "objective_note",
    "reference_check",
    "reference_controller",
    "reference_verdict",
]

SEARCH_PER_DECADE = 80
"""Grid density (points per decade) while searching."""
CERTIFICATE_PER_DECADE = 20 * SEARCH_PER_DECADE
"""Smallest grid density of the certificate: 20 times the search grid."""


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

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> cert = Certificate(True, CERTIFICATE_PER_DECADE, check(spec, "P(3)", CERTIFICATE_PER_DECADE))
    >>> cert.to_dict()["grid"]
    'log grid, 1600 points per decade, peaks and crossings refined'
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


DESIGN_STATUSES = ("feasible", "infeasible", "undetermined")
"""The answers of a design: found and certified; shown impossible as far as searched; not decided."""


@dataclass
class DesignResult:
    """Outcome of :func:`synth.design.design`.

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
    extras : dict
        Method-specific records (the convex and NLP stages, a diagnosis), merged into :meth:`to_dict`.
    status : str
        ``"feasible"``, ``"infeasible"`` (the search's evidence says no controller in the bounds meets
        the requirements) or ``"undetermined"`` (the search could not decide: no stabilizing controller
        was found to start from, or the best design failed its dense re-check). Defaults from ``feasible``.

    Examples
    --------
    >>> from synth.controllers import Controller
    >>> r = DesignResult("demo", True, Controller("P", {"kp": 3.0}), None, None, None, None, verdict="ok")
    >>> sorted(r.to_dict())
    ['controller', 'feasible', 'method', 'objective', 'requirements', 'spec', 'status', 'verdict']
    >>> DesignResult("demo", False, None, None, None, None, None, status="undetermined").status
    'undetermined'
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
    status: str = ""

    def __post_init__(self) -> None:
        if not self.status:
            self.status = "feasible" if self.feasible else "infeasible"
        if self.status not in DESIGN_STATUSES or (self.status == "feasible") != self.feasible:
            raise ValueError(f"status {self.status!r} does not go with feasible={self.feasible}")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict; ``requirements`` and ``gain_set`` at top level as the CLI contract asks."""
        shown = self.check if self.check is not None else self.compromise
        out: dict[str, Any] = {
            "spec": self.spec,
            "feasible": self.feasible,
            "status": self.status,
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


def objective_label(spec: Spec, loop: Loop) -> dict[str, Any]:
    """``{"name", "sense", "unit", "description", "value"}`` of the spec's objective at ``loop``.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> label = objective_label(spec, Loop(spec.nominal_plant(), reference_controller(spec)))
    >>> label["name"], label["sense"], round(label["value"], 2), label["unit"]
    ('bandwidth', 'maximize', 83.16, 'rad/s')
    """
    obj = spec.objective
    assert obj is not None
    if obj.weighted is None:
        m = measure(obj.name)
        unit = in_plant_units(m.unit, spec.plant.input.unit, spec.plant.output.unit)
        label = {"name": m.name, "sense": obj.sense, "unit": unit, "description": m.description,
                 "value": float(m.evaluate(loop))}
        t0 = abs(loop.T0())
        if m.name == "bandwidth" and np.isfinite(t0) and t0 < BANDWIDTH_LEVEL:
            label["note"] = (f"this bandwidth is measured 3 dB below |T(0)| = {fmt(t0, 3)} ({fmt(20 * np.log10(t0), 3)} "
                             f"dB): the loop does not follow slow references (a unit reference step settles at "
                             f"{fmt(t0, 3)}); bound the static sensitivity or require integral action to exclude such "
                             "designs") if t0 > 0 else "T(0) = 0: the loop does not follow slow references at all"
        return label
    parts = {n: float(measure(n).evaluate(loop)) for n, _, _ in obj.terms()}
    return {"name": "weighted", "sense": "maximize", "unit": "", "description": obj.describe(),
            "value": objective_score(loop, obj.terms()), "terms": parts}


def describe_objective(spec: Spec, label: dict[str, Any]) -> str:
    """The design's objective and its value, as its verdict states them (the smallest peak |S| without an objective).

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> describe_objective(spec, {"value": 473.3, "unit": "rad/s"})
    'maximize bandwidth: 473.3 rad/s'
    """
    if spec.objective is None:
        return f"smallest peak |S|: {fmt(label['value'])} dB"
    return f"{spec.objective.describe()}: {fmt(label['value'])} {label['unit']}".rstrip()


def objective_note(label: dict[str, Any] | None) -> str:
    """The sentence a design's verdict adds when its objective's value needs a caveat (see
    :func:`objective_label`'s ``note``), else "".

    Examples
    --------
    >>> objective_note({"name": "bandwidth", "note": "T(0) = 0: the loop does not track at all"})
    ' Note: T(0) = 0: the loop does not track at all.'
    >>> objective_note({"name": "bandwidth"})
    ''
    """
    return f" Note: {label['note']}." if label and label.get("note") else ""


def reference_verdict(spec: Spec, ref: CheckResult | None, gain_set: GainSet | None = None) -> str:
    """One or two sentences on the spec's reference controller (empty without one).

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> reference_verdict(spec, reference_check(spec))[:50]
    ' The reference P(kp=3) (Seed 1, X-4 Flyer rotor dr'
    """
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


def reference_controller(spec: Spec) -> Controller | None:
    """The spec's reference controller (e.g. the paper's P(3)), if any.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> str(reference_controller(load_spec("specs/x4_rotor.yaml")))
    'P(kp=3)'
    """
    if spec.reference is None or spec.reference.controller is None:
        return None
    return Controller.from_string(spec.reference.controller)


def reference_check(spec: Spec) -> CheckResult | None:
    """Requirements evaluated at the spec's reference controller (None without one).

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> reference_check(load_spec("specs/x4_rotor.yaml")).feasible
    True
    """
    c = reference_controller(spec)
    return check(spec, c) if c is not None else None
