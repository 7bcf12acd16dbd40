"""Spec files: YAML, validated by pydantic, with one-line errors naming file, line and key.

The schema is documented in ``docs/spec-format.md``. Loading is strict: an
unknown key, a missing field, a string where a number belongs, a reversed
band, an unparsable transfer function or an unknown type each raise a
:class:`~synth.errors.SpecError` whose text is
``<file>:<line>: <key path>: <what is wrong>``.
"""

from __future__ import annotations

import difflib
import json
import re
from pathlib import Path
from typing import Annotated, Any, Union

import numpy as np
import yaml
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    NonNegativeFloat,
    PrivateAttr,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from synth.controllers import (
    CONTROLLER_TYPES,
    RATIONAL,
    Controller,
    ControllerType,
    controller_type,
    rational_type,
)
from synth.errors import ModelError, SpecError
from synth.objectives import MEASURES
from synth.plant import Plant, Signal
from synth.requirements import REQUIREMENT_TYPES
from synth.sim.spec import BLOCK_TAGS, DISTURBANCE_TAGS, SIMULATION_TAGS, SimulationSpec

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class SignalSpec(_Model):
    """Name and unit of a signal."""

    name: str
    unit: str = ""


def _transfer_function(text: str | None) -> str | None:
    """Validator body: ``text`` must parse as a proper transfer function (None passes)."""
    if text is not None:
        try:
            Plant.from_string(text)
        except ModelError as exc:
            raise ValueError(exc.message) from None
    return text


class VariantSpec(_Model):
    """A plant variant the requirements must also hold on (e.g. a battery state).

    ``gain`` scales the nominal plant; ``tf`` replaces its rational part and
    ``delay`` its delay. At least one must be given.
    """

    label: str
    gain: float | None = Field(default=None, gt=0)
    tf: str | None = None
    delay: NonNegativeFloat | None = None

    _parses = field_validator("tf")(classmethod(lambda cls, text: _transfer_function(text)))

    @model_validator(mode="after")
    def _something(self) -> VariantSpec:
        if self.gain is None and self.tf is None and self.delay is None:
            raise ValueError("a variant needs at least one of gain, tf, delay")
        return self

    def build(self, nominal: Plant) -> Plant:
        """The variant plant derived from ``nominal``."""
        base = nominal
        if self.tf is not None:
            parsed = Plant.from_string(self.tf)
            base = Plant(parsed.num, parsed.den, nominal.delay + parsed.delay, nominal.input, nominal.output)
        if self.delay is not None:
            base = base.with_delay(self.delay)
        if self.gain is not None:
            base = base.scaled(self.gain)
        return Plant(base.num, base.den, base.delay, nominal.input, nominal.output, self.label)


class IdentifySpec(_Model):
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

    _sensor = field_validator("sensor")(classmethod(lambda cls, text: _transfer_function(text)))

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


class PlantSpec(_Model):
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

    _parses = field_validator("tf")(classmethod(lambda cls, text: _transfer_function(text)))

    @model_validator(mode="after")
    def _one_source(self) -> PlantSpec:
        if (self.tf is None) == (self.identify is None):
            raise ValueError("give exactly one of 'tf' (a transfer function) or 'identify' (a record to fit)")
        return self

    def _signals(self) -> tuple[Signal, Signal]:
        return Signal(self.input.name, self.input.unit), Signal(self.output.name, self.output.unit)

    def identification(self) -> Any | None:
        """The :class:`synth.ident.timefit.IdentifyResult` of an ``identify:`` plant (None for ``tf:``)."""
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


class ControllerSpec(_Model):
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


def _known_measure(name: str) -> str:
    if name not in MEASURES:
        raise ValueError(f"unknown objective {name!r}; expected one of: {', '.join(MEASURES)}")
    return name


class ObjectiveTerm(_Model):
    """One term of a weighted objective: ``{maximize: name, weight: w}`` or ``{minimize: ...}``."""

    maximize: str | None = None
    minimize: str | None = None
    weight: float = Field(default=1.0, gt=0)

    @model_validator(mode="after")
    def _exactly_one(self) -> ObjectiveTerm:
        given = [v for v in (self.maximize, self.minimize) if v is not None]
        if len(given) != 1:
            raise ValueError("each weighted term needs exactly one of 'maximize' or 'minimize'")
        _known_measure(given[0])
        return self


class ObjectiveSpec(_Model):
    """What to optimize: ``{maximize: name}``, ``{minimize: name}`` or
    ``{weighted: [{maximize: name, weight: w}, {minimize: name, weight: w}, ...]}``.

    A weighted objective maximizes ``sum(+w f)`` over maximized terms and
    ``sum(-w f)`` over minimized ones, each ``f`` in its own unit.
    """

    maximize: str | None = None
    minimize: str | None = None
    weighted: list[ObjectiveTerm] | None = None

    @model_validator(mode="after")
    def _exactly_one(self) -> ObjectiveSpec:
        given = [v for v in (self.maximize, self.minimize, self.weighted) if v is not None]
        if len(given) != 1:
            raise ValueError("give exactly one of 'maximize', 'minimize' or 'weighted'")
        if self.weighted is not None and not self.weighted:
            raise ValueError("'weighted' needs at least one term")
        if self.weighted is None:
            _known_measure(self.maximize or self.minimize)  # type: ignore[arg-type]
        return self

    def terms(self) -> list[tuple[str, str, float]]:
        """``[(measure, sense, weight), ...]``."""
        if self.weighted is None:
            return [(self.name, self.sense, 1.0)]
        return [(t.maximize or t.minimize, "maximize" if t.maximize else "minimize", t.weight)  # type: ignore[misc]
                for t in self.weighted]

    @property
    def name(self) -> str:
        """The measure's name (``"weighted"`` for a weighted sum)."""
        if self.weighted is not None:
            return "weighted"
        return self.maximize or self.minimize  # type: ignore[return-value]

    @property
    def sense(self) -> str:
        """``"maximize"`` or ``"minimize"`` (a weighted sum is maximized)."""
        if self.weighted is not None:
            return "maximize"
        return "maximize" if self.maximize else "minimize"

    def describe(self) -> str:
        """Plain text, e.g. ``"maximize bandwidth"`` or ``"maximize 1*bandwidth - 20*peak_sensitivity"``.

        Examples
        --------
        >>> terms = [{"maximize": "bandwidth"}, {"minimize": "peak_sensitivity", "weight": 20}]
        >>> ObjectiveSpec(weighted=terms).describe()
        'maximize 1*bandwidth - 20*peak_sensitivity'
        """
        if self.weighted is None:
            return f"{self.sense} {self.name}"
        parts = [f"{'+' if s == 'maximize' else '-'} {w:g}*{n}" for n, s, w in self.terms()]
        return "maximize " + " ".join(parts).lstrip("+ ").replace("+ ", "+ ")


class PublishedTF(_Model):
    """A published transfer function to compare against (e.g. a paper's closed loop)."""

    label: str
    tf: str

    @field_validator("tf")
    @classmethod
    def _parses(cls, text: str) -> str:
        try:
            Plant.from_string(text)
        except ModelError as exc:
            raise ValueError(exc.message) from None
        return text


class ReferenceSpec(_Model):
    """Published numbers the report compares the design with (a paper, an earlier design)."""

    source: str = ""
    controller: str | None = None
    closed_loop: list[PublishedTF] = Field(default_factory=list)
    slew_rate_crossing: float | None = Field(default=None, gt=0)
    rise_time: float | None = Field(default=None, gt=0)
    bandwidth: float | None = Field(default=None, gt=0)
    notes: list[str] = Field(default_factory=list)

    @field_validator("controller")
    @classmethod
    def _parses(cls, text: str | None) -> str | None:
        if text is not None:
            try:
                Controller.from_string(text)
            except ModelError as exc:
                raise ValueError(exc.message) from None
        return text


class AnalysisSpec(_Model):
    """Extra analyses for the report."""

    loop_delays: list[NonNegativeFloat] = Field(default_factory=lambda: [0.0, 0.005, 0.01, 0.015, 0.02])


def _requirement_union() -> Any:
    types = tuple(REQUIREMENT_TYPES.values())
    return Annotated[Union[types], Field(discriminator="type")]  # type: ignore[valid-type]


RequirementEntry = _requirement_union()


class Spec(_Model):
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


# ------------------------------------------------------------------------------ loading
class _Loader(yaml.SafeLoader):
    """SafeLoader that also reads ``1e4`` (no dot) as a float, as people write it."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
        |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
        |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
        |[-+]?\.(?:inf|Inf|INF)
        |\.(?:nan|NaN|NAN))$""",
        re.X,
    ),
    list("-+0123456789."),
)


def _line_of(root: yaml.Node | None, loc: tuple[Any, ...]) -> int | None:
    node = root
    line = node.start_mark.line + 1 if node is not None else None
    for key in loc:
        if isinstance(node, yaml.MappingNode):
            nxt = None
            for k, v in node.value:
                if isinstance(k, yaml.ScalarNode) and k.value == str(key):
                    nxt, line = v, k.start_mark.line + 1
                    break
            if nxt is None:
                break
            node = nxt
        elif isinstance(node, yaml.SequenceNode) and isinstance(key, int) and key < len(node.value):
            node = node.value[key]
            line = node.start_mark.line + 1
        else:
            break
    return line


def _clean_loc(loc: tuple[Any, ...]) -> tuple[Any, ...]:
    out: list[Any] = []
    for i, part in enumerate(loc):
        if (
            isinstance(part, str)
            and i > 0
            and isinstance(loc[i - 1], int)
            and (part in REQUIREMENT_TYPES or part in SIMULATION_TAGS)
        ):
            continue  # discriminated-union tag inserted by pydantic
        if isinstance(part, str) and ("[" in part or part.startswith("function-")):
            continue
        out.append(part)
    return tuple(out)


def _key_path(loc: tuple[Any, ...]) -> str:
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(top level)"


def _allowed_keys(loc: tuple[Any, ...], data: Any) -> list[str]:
    """Keys the model at ``loc[:-1]`` accepts (for 'did you mean' hints)."""
    model: Any = Spec
    node = data
    for part in loc[:-1]:
        if isinstance(part, int):
            node = node[part] if isinstance(node, list) and part < len(node) else None
            if model == "requirements":
                model = REQUIREMENT_TYPES.get(node.get("type")) if isinstance(node, dict) else None
            elif isinstance(model, dict):  # a list of tagged models (simulation blocks, disturbances)
                model = model.get(node.get("type")) if isinstance(node, dict) else None
            continue
        node = node.get(part) if isinstance(node, dict) else None
        if model is Spec and part == "requirements":
            model = "requirements"
            continue
        field = getattr(model, "model_fields", {}).get(part)
        if field is None:
            return []
        tagged = _tagged_members(field.annotation)
        if tagged:
            model = tagged
            continue
        candidates = [field.annotation, *getattr(field.annotation, "__args__", ())]
        model = next((c for c in candidates if isinstance(c, type) and issubclass(c, BaseModel)), None)
    fields = getattr(model, "model_fields", None)
    return list(fields) if isinstance(fields, dict) else []


def _tagged_members(annotation: Any) -> dict[str, type[BaseModel]]:
    """``{tag: model}`` when ``annotation`` is a list of models told apart by a ``type`` literal."""
    from typing import get_args, get_origin

    if get_origin(annotation) is not list:
        return {}
    found: dict[str, type[BaseModel]] = {}
    stack = list(get_args(annotation))
    while stack:
        item = stack.pop()
        if isinstance(item, type) and issubclass(item, BaseModel):
            field = item.model_fields.get("type")
            tags = get_args(field.annotation) if field is not None else ()
            if tags and all(isinstance(t, str) for t in tags):
                found.update({t: item for t in tags})
        else:
            stack.extend(get_args(item))
    return found


def _message(err: dict[str, Any], data: Any, loc: tuple[Any, ...]) -> str:
    kind = err["type"]
    given = err.get("input")
    if kind == "missing":
        return "missing (required)"
    if kind == "extra_forbidden":
        allowed = [k for k in _allowed_keys(loc, data) if k != "type"]
        near = difflib.get_close_matches(str(loc[-1]), allowed, n=1)
        hint = f"; did you mean {near[0]!r}?" if near else (f"; allowed: {', '.join(allowed)}" if allowed else "")
        return f"unknown key {loc[-1]!r}{hint}"
    if kind in {"union_tag_invalid", "union_tag_not_found"} and loc and loc[0] == "simulation":
        what = "disturbance" if "disturbances" in loc else "block"
        expected = ", ".join(DISTURBANCE_TAGS if what == "disturbance" else BLOCK_TAGS)
        if kind == "union_tag_not_found":
            return f"{what} has no 'type'; expected one of: {expected}"
        return f"unknown {what} type {err['ctx']['tag']!r}; expected one of: {expected}"
    if kind == "union_tag_invalid":
        return (f"unknown requirement type {err['ctx']['tag']!r}; expected one of: "
                f"{', '.join(REQUIREMENT_TYPES)}")
    if kind == "union_tag_not_found":
        return f"requirement has no 'type'; expected one of: {', '.join(REQUIREMENT_TYPES)}"
    if kind in {"float_type", "float_parsing", "int_type", "finite_number"}:
        return f"expected a number, got {given!r}"
    if kind in {"string_type"}:
        return f"expected text, got {given!r}"
    if kind in {"tuple_type", "list_type", "dict_type", "model_type"}:
        what = {"tuple_type": "a list [low, high]", "list_type": "a list", "dict_type": "a mapping",
                "model_type": "a mapping of keys"}[kind]
        return f"expected {what}, got {given!r}"
    if kind in {"too_short", "too_long"}:
        if loc and loc[-1] == "requirements":
            return "the requirement list is empty; give at least one requirement"
        return f"expected exactly 2 numbers [low, high], got {given!r}"
    if kind in {"greater_than", "greater_than_equal"}:
        limit = err["ctx"].get("gt", err["ctx"].get("ge"))
        return f"must be {'>' if kind == 'greater_than' else '>='} {limit}, got {given!r}"
    msg = str(err.get("msg", "invalid value"))
    return msg.removeprefix("Value error, ")


def spec_error(exc: ValidationError, source: str, root: yaml.Node | None, data: Any) -> SpecError:
    """Turn the first pydantic error into a one-line :class:`SpecError`."""
    errors = exc.errors(include_url=False)
    # a misspelled key shows up as "unknown key" plus "missing": the first says more
    errors.sort(key=lambda e: e["type"] != "extra_forbidden")
    err = errors[0]
    loc = _clean_loc(tuple(err["loc"]))
    if err["type"] in {"union_tag_invalid", "union_tag_not_found"}:
        loc = (*loc, "type")
    line = _line_of(root, loc)
    where = f"{source}:{line}" if line else source
    return SpecError(_message(err, data, loc), where=f"{where}: {_key_path(loc)}")


def parse_spec(text: str, source: str = "<spec>") -> Spec:
    """Validate spec text (YAML).

    Examples
    --------
    >>> parse_spec("name: x\\nplant: {tf: '1/(s+1)'}\\ncontroller: {type: P}\\nrequirements: []")
    Traceback (most recent call last):
    ...
    synth.errors.SpecError: <spec>:4: requirements: the requirement list is empty; give at least one requirement
    """
    try:
        root = yaml.compose(text, Loader=_Loader)
        data = yaml.load(text, Loader=_Loader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{source}:{mark.line + 1}" if mark is not None else source
        problem = getattr(exc, "problem", None) or str(exc)
        raise SpecError(f"invalid YAML: {problem}", where=where) from None
    if data is None:
        raise SpecError("the spec file is empty", where=source)
    if not isinstance(data, dict):
        raise SpecError("the spec must be a mapping of keys (name, plant, controller, ...)", where=source)
    try:
        spec = Spec.model_validate_json(json.dumps(data, default=str), strict=True)
    except ValidationError as exc:
        raise spec_error(exc, source, root, data) from None
    if spec.plant.identify is not None:
        _check_identify_data(spec, source, root)
    return spec


def _check_identify_data(spec: Spec, source: str, root: yaml.Node | None) -> None:
    """Resolve ``plant.identify.data`` against the spec file's folder; a missing file is a spec error."""
    from synth.ident.from_spec import resolve_data

    base = Path(source).parent if source != "<spec>" else None
    spec.plant._base = base
    try:
        path = resolve_data(spec.plant.identify.data, base)
    except ModelError as exc:
        path, problem = None, exc.message
    else:
        problem = None if path.is_file() else f"data file {str(path)!r} not found"
    if problem:
        loc = ("plant", "identify", "data")
        line = _line_of(root, loc)
        raise SpecError(problem, where=f"{source}:{line}: {_key_path(loc)}" if line else f"{source}: {_key_path(loc)}")


def load_spec(path: str | Path) -> Spec:
    """Read and validate a spec file.

    Parameters
    ----------
    path : str or Path
        A YAML spec file (see ``docs/spec-format.md``).

    Returns
    -------
    Spec

    Raises
    ------
    SpecError
        One line naming the file, line, key and problem.

    Examples
    --------
    >>> import tempfile, os
    >>> f = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)
    >>> _ = f.write("name: demo\\nplant: {tf: '1/(s+1)'}\\ncontroller: {type: P}\\n"
    ...             "requirements: [{type: bandwidth, min: 2}]\\n"); f.close()
    >>> load_spec(f.name).controller.type
    'P'
    >>> os.unlink(f.name)
    """
    path = Path(path)
    if not path.exists():
        raise SpecError("spec file not found", where=str(path))
    if path.is_dir():
        raise SpecError("is a directory, not a spec file", where=str(path))
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(f"cannot read spec file: {exc}", where=str(path)) from None
    return parse_spec(text, source=str(path))
