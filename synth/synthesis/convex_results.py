"""What the convex stage returns: the design, its history, and for infeasible specs the diagnosis."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.errors import SynthError

__all__ = ["ConvexResult", "Diagnosis", "RequirementConflict", "infeasible_verdict"]


@dataclass
class RequirementConflict:
    """One requirement in an infeasibility diagnosis."""

    name: str
    elastic_slack: float
    price: float
    violated: bool
    exact_slack: float
    message: str

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


@dataclass
class Diagnosis:
    """Why a spec cannot be met: the elastic solution, slacks and prices."""

    total_slack: float
    conflicts: list[RequirementConflict]
    bounds_active: list[str]
    controller: Controller
    conflict_set: list[str] | None = None

    def conflicting(self) -> list[str]:
        """A minimal set of requirements that cannot be met together (deletion filter) when computed;
        otherwise those violated at the elastic solution or pushing against them (price >= 1 % of the
        largest)."""
        if self.conflict_set is not None:
            return list(self.conflict_set)
        top = max((c.price for c in self.conflicts), default=0.0)
        return [c.name for c in self.conflicts if c.violated or (top > 0 and c.price >= 0.01 * top)]

    def to_dict(self) -> dict[str, Any]:
        return {
            "total_elastic_slack": self.total_slack,
            "conflicting": self.conflicting(),
            "conflict_set_method": "deletion filter: each requirement dropped in turn; kept if the rest "
                                   "became feasible" if self.conflict_set is not None else "elastic prices",
            "requirements": [c.to_dict() for c in self.conflicts],
            "bounds_active": self.bounds_active,
            "elastic_controller": self.controller.to_dict(),
        }


@dataclass
class ConvexResult:
    """Outcome of :meth:`ConvexDesigner.run`."""

    status: str
    controller: Controller
    rho: np.ndarray
    objective_value: float | None
    iterations: int
    solves: int
    solve_time: float
    history: list[dict[str, float]] = field(default_factory=list)
    diagnosis: Diagnosis | None = None
    grid_points: int = 0
    starts_tried: int = 1
    converged: bool = False
    note: str = ""
    """What was run or kept beyond the usual (a rescaled second run: :mod:`synth.synthesis.rational_rescale`; an
    earlier iterate kept because the last failed the exact check: :mod:`synth.synthesis.convex_exact`)."""

    def to_dict(self) -> dict[str, Any]:
        return {
            "status": self.status,
            "controller": self.controller.to_dict(),
            "objective_value": self.objective_value,
            "converged": self.converged,
            "iterations": self.iterations,
            "convex_solves": self.solves,
            "solve_time": self.solve_time,
            "grid_points": self.grid_points,
            "starts_tried": self.starts_tried,
            "history": self.history,
            "diagnosis": self.diagnosis.to_dict() if self.diagnosis else None,
        } | ({"note": self.note} if self.note else {})


def infeasible_verdict(convex: ConvexResult, compromise: Any = None) -> str:
    """Plain-language explanation of an infeasible design from the convex stage's diagnosis (``compromise``, the
    check of the closest design, is not read: kept for callers that pass it).

    Examples
    --------
    >>> c = Controller("P", {"kp": 1.0})
    >>> why = Diagnosis(0.3, [RequirementConflict("bandwidth", 0.3, 2.0, True, -0.3, "bandwidth 1 < 2 rad/s")], [], c)
    >>> infeasible_verdict(ConvexResult("infeasible", c, np.ones(1), None, 3, 3, 0.1, diagnosis=why))[-94:]
    'Conflicting requirements (a minimal set the same searches could not meet together): bandwidth.'
    """
    diag = convex.diagnosis
    if diag is None:
        raise SynthError("no diagnosis for a design that was not found infeasible")
    parts = [f"No design found that meets every requirement within the controller bounds (convex-concave from "
             f"{convex.starts_tried} stabilizing start(s), then NLP from the closest design: local searches, which "
             "do not prove that none exists)."]
    violated = [c for c in diag.conflicts if c.violated]
    pushing = [c for c in diag.conflicts if not c.violated and c.name in diag.conflicting()]
    if violated:
        parts.append("The closest design (least total violation) still violates: "
                     + "; ".join(f"{c.name} (slack {c.exact_slack:+.3g} Np: {c.message})" for c in violated)
                     + ".")
    if pushing:
        parts.append("Met there but pushing against them (dual price > 0): "
                     + ", ".join(f"{c.name} (price {c.price:.3g})" for c in pushing) + ".")
    if diag.bounds_active:
        parts.append("Active parameter bounds: " + ", ".join(diag.bounds_active) + ".")
    parts.append("Conflicting requirements (a minimal set the same searches could not meet together): "
                 + ", ".join(diag.conflicting()) + ".")
    return " ".join(parts)
