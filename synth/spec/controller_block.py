"""The ``controller:`` block of a spec: the structure, parameter bounds and an optional start.

``type`` is one of :data:`synth.controllers.CONTROLLER_TYPES` or ``rational`` (with
``order: [m, n]``); ``bounds`` are ``[lo, hi]`` per parameter (``lo == hi`` fixes it).
"""

from __future__ import annotations

import numpy as np
from pydantic import Field, ValidationInfo, field_validator, model_validator

from synth.controllers import (
    CONTROLLER_TYPES,
    RATIONAL,
    Controller,
    ControllerType,
    controller_type,
    rational_type,
)
from synth.errors import ModelError
from synth.spec.strict import StrictModel

__all__ = ["ControllerSpec"]


class ControllerSpec(StrictModel):
    """Controller structure and parameter bounds (``[lo, hi]``; ``lo == hi`` fixes a parameter).

    ``type: rational`` takes ``order: [m, n]`` (numerator and denominator degrees).
    """

    type: str
    order: tuple[int, int] | None = None
    bounds: dict[str, tuple[float, float]] = Field(default_factory=dict)
    initial: dict[str, float] | None = None

    @field_validator("type")
    @classmethod
    def _known_type(cls, name: str) -> str:
        if str(name).lower() in (RATIONAL, "fixed_order"):
            return RATIONAL
        try:
            return controller_type(name).name
        except ModelError as exc:
            raise ValueError(exc.message) from None

    @field_validator("order")
    @classmethod
    def _order(cls, order: tuple[int, int] | None, info: ValidationInfo):
        if info.data.get("type") == RATIONAL:
            if order is None:
                raise ValueError("a rational controller needs 'order: [m, n]' (numerator, denominator degree)")
            try:
                rational_type(*order)
            except ModelError as exc:
                raise ValueError(exc.message) from None
        elif order is not None:
            raise ValueError(f"'order' applies to rational controllers only, not {info.data.get('type')}")
        return order

    @model_validator(mode="after")
    def _rational_needs_order(self) -> ControllerSpec:
        if self.type == RATIONAL and self.order is None:
            raise ValueError("a rational controller needs 'order: [m, n]' (numerator, denominator degree)")
        return self

    def kind(self) -> ControllerType:
        """The :class:`~synth.controllers.ControllerType`."""
        return controller_type(self.type, self.order)

    @field_validator("bounds")
    @classmethod
    def _check_bounds(cls, bounds: dict[str, tuple[float, float]], info: ValidationInfo):
        if "type" not in info.data:
            return bounds
        if info.data["type"] == RATIONAL:
            if info.data.get("order") is None:
                return bounds
            ctype = rational_type(*info.data["order"])
        else:
            ctype = CONTROLLER_TYPES[info.data["type"]]
        for name, (lo, hi) in bounds.items():
            if name not in ctype.parameters:
                raise ValueError(
                    f"{ctype.name} has no parameter {name!r}; its parameters are "
                    f"{', '.join(ctype.parameters)}"
                )
            if not (np.isfinite(lo) and np.isfinite(hi)):
                raise ValueError(f"{name}: bounds must be finite, got [{lo:g}, {hi:g}]")
            if lo > hi:
                raise ValueError(f"{name}: lower bound {lo:g} is above upper bound {hi:g}")
            if name in ctype.positive and lo <= 0:
                raise ValueError(f"{name}: {name} must stay > 0, got lower bound {lo:g}")
        return bounds

    @field_validator("initial")
    @classmethod
    def _check_initial(cls, initial: dict[str, float] | None, info: ValidationInfo):
        if initial is None or "type" not in info.data:
            return initial
        order = info.data.get("order")
        names = (rational_type(*order) if info.data["type"] == RATIONAL and order else
                 CONTROLLER_TYPES.get(info.data["type"]))
        if names is None:
            return initial
        missing = [p for p in names.parameters if p not in initial]
        extra = [p for p in initial if p not in names.parameters]
        if extra:
            raise ValueError(f"{names.name} has no parameter {extra[0]!r}")
        if missing:
            raise ValueError(f"initial needs a value for every parameter; missing {', '.join(missing)}")
        return initial

    def initial_controller(self) -> Controller | None:
        """The starting controller given in the spec, if any."""
        return None if self.initial is None else Controller(self.type, dict(self.initial))

    def all_bounds(self) -> dict[str, tuple[float, float]]:
        """Bounds for every parameter (defaults where the spec gives none)."""
        ctype = self.kind()
        return {p: tuple(self.bounds.get(p, ctype.default_bounds[p])) for p in ctype.parameters}

    def free_parameters(self) -> list[str]:
        """Parameters whose bounds leave room (``lo < hi``)."""
        return [p for p, (lo, hi) in self.all_bounds().items() if lo < hi]


