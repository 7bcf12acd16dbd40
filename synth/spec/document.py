"""The whole spec: name, plant, controller, requirements, objective, reference, analysis, simulation.

Each block has its own module (:mod:`synth.spec.plant_block`, :mod:`synth.spec.controller_block`,
:mod:`synth.spec.objective`, :mod:`synth.spec.reference`; requirements are
:data:`synth.requirements.REQUIREMENT_TYPES`, the simulation block :mod:`synth.sim.spec`).
"""

from __future__ import annotations

import re
from typing import Annotated, Any, Union

from pydantic import Field, field_validator

from synth.plant import Plant
from synth.requirements import REQUIREMENT_TYPES
from synth.sim.spec import SimulationSpec
from synth.spec.controller_block import ControllerSpec
from synth.spec.objective import ObjectiveSpec
from synth.spec.plant_block import PlantSpec
from synth.spec.reference import AnalysisSpec, ReferenceSpec
from synth.spec.strict import StrictModel

__all__ = ["RequirementEntry", "Spec"]

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
STABILITY_ROW = "closed-loop stability"
"""The label of the stability row every check reports (:mod:`synth.check`)."""


def _requirement_union() -> Any:
    types = tuple(REQUIREMENT_TYPES.values())
    return Annotated[Union[types], Field(discriminator="type")]  # type: ignore[valid-type]


RequirementEntry = _requirement_union()


class Spec(StrictModel):
    """A design problem: plant, controller structure, requirements and objective.

    Examples
    --------
    >>> spec = Spec.model_validate({
    ...     "name": "demo", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "P"},
    ...     "requirements": [{"type": "bandwidth", "min": 2}]})
    >>> spec.requirements[0].min
    2.0
    """

    name: str
    description: str = ""
    plant: PlantSpec
    controller: ControllerSpec
    requirements: list[RequirementEntry] = Field(min_length=1)  # type: ignore[valid-type]
    objective: ObjectiveSpec | None = None
    reference: ReferenceSpec | None = None
    analysis: AnalysisSpec = AnalysisSpec()
    simulation: SimulationSpec | None = None

    @field_validator("requirements")
    @classmethod
    def _distinct_labels(cls, requirements: list[Any]) -> list[Any]:
        labels = [r.label for r in requirements if getattr(r, "label", None)]
        repeated = sorted({x for x in labels if labels.count(x) > 1})
        if repeated:
            raise ValueError(f"label {repeated[0]!r} is given to {labels.count(repeated[0])} requirements; each "
                             "label names one (the report's rows, a --sweep requirements.LABEL)")
        if STABILITY_ROW in labels:
            raise ValueError(f"label {STABILITY_ROW!r} names the built-in stability row; choose another")
        return requirements

    @field_validator("name")
    @classmethod
    def _safe_name(cls, name: str) -> str:
        if not _NAME.match(name):
            raise ValueError(
                f"name {name!r} must start with a letter or digit and use only letters, digits, "
                "'_', '-' or '.' (it names the report folder)"
            )
        return name

    def plants(self) -> list[Plant]:
        """Plants the requirements must hold on: the nominal plant, then every variant."""
        return self.plant.build_all()

    def nominal_plant(self) -> Plant:
        """The nominal plant."""
        return self.plant.build()

    def with_parameter_fixed(self, name: str, value: float) -> Spec:
        """This spec with the controller parameter ``name`` held at ``value`` (its bounds ``[value, value]``).

        Examples
        --------
        >>> from synth.spec import parse_spec
        >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "PI"},
        ...                    "requirements": [{"type": "bandwidth", "min": 1.0}]})
        >>> spec.with_parameter_fixed("ki", 0.0).controller.all_bounds()["ki"]
        (0.0, 0.0)
        """
        bounds = {**self.controller.all_bounds(), name: (value, value)}
        return self.model_copy(update={"controller": self.controller.model_copy(update={"bounds": bounds})})
