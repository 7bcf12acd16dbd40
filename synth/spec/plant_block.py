"""The ``plant:`` block of a spec: a transfer function or an identification, an extra delay, variants.

``PlantSpec.build_all()`` gives the plants every requirement must hold on: the nominal plant,
the identification's uncertainty plants (if any), then the variants.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Union

import numpy as np
from pydantic import (
    Field,
    NonNegativeFloat,
    PrivateAttr,
    ValidationInfo,
    field_validator,
    model_validator,
)

from synth.errors import ModelError
from synth.plant import Plant, Signal
from synth.spec.strict import StrictModel, check_transfer_function

__all__ = ["DATA_FOLDER", "IdentifySpec", "PlantSpec", "SignalSpec", "VariantSpec"]

DATA_FOLDER = "data_folder"
"""Key of the validation context holding the folder that ``identify.data`` is relative to."""


class SignalSpec(StrictModel):
    """Name and unit of a signal."""

    name: str
    unit: str = ""


class VariantSpec(StrictModel):
    """A plant variant the requirements must also hold on (e.g. a battery state).

    ``gain`` scales the variant (the nominal plant, or its own ``tf``); ``tf`` replaces the nominal's rational
    part and ``delay`` the nominal's delay. A delay written in the variant's ``tf`` (``exp(-tau*s)``) is added to
    its ``delay``, or to the nominal's delay when it gives none (as ``plant.delay`` is added to an ``exp`` in the
    nominal's ``tf``). At least one must be given.
    """

    label: str
    gain: float | None = Field(default=None, gt=0)
    tf: str | None = None
    delay: NonNegativeFloat | None = None

    _parses = field_validator("tf")(classmethod(lambda cls, text: check_transfer_function(text)))

    @model_validator(mode="after")
    def _something(self) -> VariantSpec:
        if self.gain is None and self.tf is None and self.delay is None:
            raise ValueError("a variant needs at least one of gain, tf, delay")
        return self

    def build(self, nominal: Plant) -> Plant:
        """The variant plant derived from ``nominal``."""
        base = nominal if self.delay is None else nominal.with_delay(self.delay)
        if self.tf is not None:  # the tf's own exp(-tau*s) adds to the delay (it was replaced by `delay` before)
            parsed = Plant.from_string(self.tf)
            base = Plant(parsed.num, parsed.den, base.delay + parsed.delay, nominal.input, nominal.output)
        if self.gain is not None:
            base = base.scaled(self.gain)
        return Plant(base.num, base.den, base.delay, nominal.input, nominal.output, self.label)


class IdentifySpec(StrictModel):
    """Identify the plant from a measured record (``plant: {identify: {...}}``).

    ``data`` is a CSV or MAT file (relative to the spec file) or ``builtin:x4_step_train``
    (the SYNTHETIC X-4 step train); ``structure`` a formula such as
    ``k*(s+z)/((s+p1)*(s+p2))``; ``delay`` is ``fit`` or a value in seconds;
    ``sensor`` a known sensor transfer function in series (divided out);
    ``in_loop_delay`` says whether the identified delay is inside the control
    loop (the rotor paper does not say); ``uncertainty`` makes the requirements
    hold on the plants at the ends of the parameter confidence ellipsoid's axes.
    """

    data: str
    time: str | None = None
    input: str | None = None
    output: str | None = None
    structure: str
    delay: Union[float, str] = "fit"
    sensor: str | None = None
    average: str = "auto"
    in_loop_delay: bool = True
    confidence: float = Field(default=0.95, gt=0, lt=1)
    uncertainty_variants: bool = True

    @field_validator("structure")
    @classmethod
    def _formula(cls, text: str) -> str:
        from synth.ident.structure import parse_structure

        try:
            parse_structure(text)
        except ModelError as exc:
            raise ValueError(exc.message) from None
        return text

    @field_validator("delay")
    @classmethod
    def _delay(cls, value: float | str) -> float | str:
        if isinstance(value, str) and value != "fit":
            raise ValueError(f"delay must be 'fit' or a number of seconds >= 0, got {value!r}")
        if not isinstance(value, str) and (not np.isfinite(value) or value < 0):
            raise ValueError(f"delay must be 'fit' or a number of seconds >= 0, got {value!r}")
        return value

    _sensor = field_validator("sensor")(classmethod(lambda cls, text: check_transfer_function(text)))

    @field_validator("average")
    @classmethod
    def _average(cls, value: str) -> str:
        if value not in ("auto", "cycle", "edge", "none"):
            raise ValueError(f"average must be one of auto, cycle, edge, none, got {value!r}")
        return value

    def settings(self) -> Any:
        """The :class:`synth.ident.from_spec.IdentifySettings` of this block."""
        from synth.ident.from_spec import IdentifySettings

        return IdentifySettings(self.data, self.time, self.input, self.output, self.structure, self.delay,
                                self.sensor, self.average, self.confidence, self.uncertainty_variants)


class PlantSpec(StrictModel):
    """A plant given as a transfer-function string (or identified from data), with an extra delay and variants."""

    tf: str | None = None
    identify: IdentifySpec | None = None
    delay: NonNegativeFloat = 0.0
    input: SignalSpec = SignalSpec(name="u")
    output: SignalSpec = SignalSpec(name="y")
    label: str = "nominal"
    variants: list[VariantSpec] = Field(default_factory=list)
    _base: Path | None = PrivateAttr(default=None)

    @field_validator("variants")
    @classmethod
    def _unique_labels(cls, variants: list[VariantSpec], info: ValidationInfo) -> list[VariantSpec]:
        labels = [info.data.get("label", "nominal")] + [v.label for v in variants]
        dupes = sorted({x for x in labels if labels.count(x) > 1})
        if dupes:
            raise ValueError(f"plant labels must be unique; repeated: {', '.join(dupes)}")
        return variants

    _parses = field_validator("tf")(classmethod(lambda cls, text: check_transfer_function(text)))

    @field_validator("tf")
    @classmethod
    def _not_zero(cls, text: str | None) -> str | None:
        if text is not None and not any(Plant.from_string(text).num):
            raise ValueError(f"transfer function {text!r} is identically zero: no controller can act on this plant")
        return text

    @model_validator(mode="after")
    def _one_source(self) -> PlantSpec:
        if (self.tf is None) == (self.identify is None):
            raise ValueError("give exactly one of 'tf' (a transfer function) or 'identify' (a record to fit)")
        return self

    @model_validator(mode="after")
    def _data_folder_from_context(self, info: ValidationInfo) -> PlantSpec:
        folder = (info.context or {}).get(DATA_FOLDER)
        if self.identify is not None and folder is not None:  # a tf plant reads no data: specs compare equal
            self._base = Path(folder)
        return self

    @property
    def data_folder(self) -> Path | None:
        """Folder that ``identify.data`` is relative to (the spec file's folder; None: the working directory,
        and always None for a ``tf:`` plant).

        It comes from the validation context (``context={DATA_FOLDER: folder}``), as
        :func:`synth.spec.parse_spec` passes it.

        Examples
        --------
        >>> block = {"identify": {"data": "run.csv", "structure": "k/(s+p)"}}
        >>> PlantSpec.model_validate(block, context={DATA_FOLDER: "specs"}).data_folder
        PosixPath('specs')
        >>> PlantSpec.model_validate({"tf": "1/(s+1)"}).data_folder is None
        True
        """
        return self._base

    def _signals(self) -> tuple[Signal, Signal]:
        return Signal(self.input.name, self.input.unit), Signal(self.output.name, self.output.unit)

    def identification(self) -> Any | None:
        """The :class:`synth.ident.identification.IdentifyResult` of an ``identify:`` plant (None for ``tf:``)."""
        if self.identify is None:
            return None
        from synth.ident.from_spec import identify_plant

        return identify_plant(self.identify.settings(), self._base, *self._signals())

    def _loop_delay(self, identified_delay: float) -> float:
        assert self.identify is not None
        return (identified_delay if self.identify.in_loop_delay else 0.0) + self.delay

    def build(self) -> Plant:
        """The nominal :class:`~synth.plant.Plant` this entry describes."""
        inp, out = self._signals()
        if self.identify is not None:
            fitted = self.identification().plant
            return Plant(fitted.num, fitted.den, self._loop_delay(fitted.delay), inp, out, self.label)
        assert self.tf is not None
        return Plant.from_string(self.tf, self.delay, inp, out, self.label)

    def build_all(self) -> list[Plant]:
        """The nominal plant, the identification's uncertainty plants (if any), then every variant."""
        nominal = self.build()
        extra: list[Plant] = []
        if self.identify is not None and self.identify.uncertainty_variants:
            from synth.ident.from_spec import uncertainty_plants

            for p in uncertainty_plants(self.identification(), self.identify.confidence, *self._signals()):
                extra.append(Plant(p.num, p.den, self._loop_delay(p.delay), p.input, p.output, p.label))
        return [nominal, *extra] + [v.build(nominal) for v in self.variants]


