"""Requirement base class, result record and registry.

A requirement is a validated spec entry (a pydantic model, selected by its
``type:`` name) with an ``evaluate(loop)`` method returning a
:class:`RequirementResult`.

Slack convention
----------------
``slack >= 0`` means met. Slacks are dimensionless and share one scale: for
magnitudes and frequencies the slack is the natural log of the ratio between
bound and value (nepers; 1 dB = 0.1151), for phases it is the difference in
radians. These are the real and imaginary parts of the complex logarithm, so
a 1-neper magnitude slack and a 1-radian phase slack weigh the same.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict

from synth.errors import SpecError
from synth.requirements.bands import BandMixin, check_band

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = [
    "NEPER_PER_DB",
    "REQUIREMENT_TYPES",
    "BandMixin",
    "Bound",
    "ReportRow",
    "Requirement",
    "RequirementResult",
    "check_band",
    "db",
    "db_values",
    "fmt",
    "magnitude",
    "register",
    "tagged_type",
    "unique_names",
]

NEPER_PER_DB = np.log(10.0) / 20.0


def magnitude(value_db: float) -> float:
    """Magnitude of a level in dB, ``10^(value_db / 20)``: the one dB-to-magnitude conversion of the
    package (requirements, convex forms and NLP forms all use it).

    Examples
    --------
    >>> magnitude(20.0), round(magnitude(-6.0), 4)
    (10.0, 0.5012)
    """
    return float(10.0 ** (value_db / 20.0))


@dataclass(frozen=True)
class Bound:
    """One bound field of a requirement: which side it bounds and in which unit.

    Attributes
    ----------
    direction : {"upper", "lower"}
        ``"upper"``: the measured value must stay at or below the bound (``max_db``);
        ``"lower"``: at or above it (``min``, margins).
    unit : str
        Unit of the spec value; ``"dB"`` bounds are read as magnitudes by :meth:`Requirement.linear_bound`.

    Examples
    --------
    >>> Bound("upper", "dB").relation, Bound("lower", "rad/s").stricter_when
    ('<=', 1)
    """

    direction: Literal["upper", "lower"]
    unit: str

    @property
    def relation(self) -> str:
        """``"<="`` for an upper bound, ``">="`` for a lower bound."""
        return "<=" if self.direction == "upper" else ">="

    @property
    def stricter_when(self) -> int:
        """+1 when a larger bound is stricter (lower bounds), -1 when a smaller one is (upper bounds)."""
        return -1 if self.direction == "upper" else +1


@dataclass
class ReportRow:
    """One requirement's row in a report: measured value, relation to its bound, slack.

    Examples
    --------
    >>> row = ReportRow("Ms", 4.2, "<=", 6.0, "dB", 0.2, True)
    >>> row.bound_text(), row.consistent()
    ('<= 6 dB', True)
    """

    label: str
    value: float
    relation: str
    bound: float
    unit: str
    slack: float
    met: bool

    def bound_text(self) -> str:
        """``"<= 6 dB"``, ``">= 60 rad/s"``."""
        return f"{self.relation} {fmt(self.bound)} {self.unit}".rstrip()

    def consistent(self) -> bool:
        """The slack's sign agrees with the value's side of the bound (a met lower bound has
        ``value >= bound`` and ``slack >= 0``, a violated upper bound ``value > bound`` and ``slack < 0``)."""
        if not (np.isfinite(self.value) and np.isfinite(self.bound)) or self.value == self.bound:
            return True
        on_side = self.value > self.bound if self.relation == ">=" else self.value < self.bound
        return on_side == (self.slack >= 0) == self.met

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return asdict(self)


@dataclass
class RequirementResult:
    """Outcome of one requirement on one loop.

    Attributes
    ----------
    type : str
        Requirement type name (``"sensitivity"``, ...).
    label : str
        Short human label.
    value : float
        Measured quantity, in ``unit``.
    bound : float
        Required bound, in ``unit``.
    unit : str
        Unit of ``value`` and ``bound``.
    slack : float
        Normalized signed slack, ``>= 0`` when met (nepers or radians).
    margin : float
        Signed distance to the bound in ``unit`` (``>= 0`` when met).
    binding_frequency : float or None
        Frequency (rad/s) where the requirement is tightest.
    met : bool
        ``slack >= 0``.
    message : str
        One plain-language line for reports.
    details : dict
        Extra numbers (e.g. ``met_up_to``, ``crossing_frequency``).
    plant : str
        Label of the plant it was evaluated on (robust specs).
    """

    type: str
    label: str
    value: float
    bound: float
    unit: str
    slack: float
    margin: float
    binding_frequency: float | None
    met: bool
    message: str
    details: dict[str, Any] = field(default_factory=dict)
    plant: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return asdict(self)


REQUIREMENT_TYPES: dict[str, type[Requirement]] = {}


def register(cls: type[Requirement]) -> type[Requirement]:
    """Class decorator: make a requirement available under its ``type`` name.

    The solver forms are registered beside their solvers (``convex_form`` in
    :mod:`synth.synthesis.convex_forms`, ``nlp_form`` in :mod:`synth.synthesis.nlp_forms`);
    docs/extending-requirements.md gives the recipe.

    Examples
    --------
    >>> REQUIREMENT_TYPES["peak_sensitivity"].__name__
    'PeakSensitivity'
    """
    name = cls.model_fields["type"].default
    REQUIREMENT_TYPES[name] = cls
    return cls


def tagged_type(table: dict[str, Any], entry: Any) -> Any:
    """The entry of ``table`` named by a spec entry's ``type`` (None when the entry is no mapping, or its type is
    not a string or not in the table): a user's ``type: [1]`` is an unknown type, not a lookup that fails.

    Examples
    --------
    >>> tagged_type(REQUIREMENT_TYPES, {"type": "peak_sensitivity"}).__name__
    'PeakSensitivity'
    >>> tagged_type(REQUIREMENT_TYPES, {"type": [1]}), tagged_type(REQUIREMENT_TYPES, "bandwidth")
    (None, None)
    """
    kind = entry.get("type") if isinstance(entry, dict) else None
    return table.get(kind) if isinstance(kind, str) else None


class Requirement(BaseModel):
    """Base of all requirement types (one pydantic model per ``type:``)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    type: str
    label: str | None = None

    title: ClassVar[str] = "requirement"
    bounds: ClassVar[dict[str, Bound]] = {}
    """The bound fields: name -> :class:`Bound` (direction and unit)."""
    stricter: ClassVar[dict[str, int]] = {}
    """Other swept fields and their direction: +1 when a larger value makes the requirement stricter."""
    example: ClassVar[dict[str, Any]] = {}
    """A spec-file block of this type (docs, the registry test's round trip)."""
    costly: ClassVar[bool] = False
    """Its evaluation simulates (a time response, a describing-function chain): checks that may stop at the
    first failure (:func:`synth.check.quick_check`) evaluate it last."""

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:  # pragma: no cover
        """Evaluate on ``loop``; ``per_decade`` sets the density of the frequency grid."""
        raise NotImplementedError

    def slack(self, loop: Loop, per_decade: int = 80) -> float:
        """The slack of :meth:`evaluate` alone (a type may skip work its message needs and its slack
        does not; the number is the same).

        Examples
        --------
        >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
        >>> from synth.requirements import Bandwidth
        >>> loop = Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 9.0}))
        >>> Bandwidth(min=100).slack(loop) == Bandwidth(min=100).evaluate(loop).slack
        True
        """
        return self.evaluate(loop, per_decade).slack

    def part_slacks(self, loop: Loop, per_decade: int = 80) -> list[float]:
        """The slacks of the requirement's parts (one per limit it sets; :meth:`slack` is their minimum): a
        search that moves along several active limits at once needs each one's gradient, not the minimum's.

        Examples
        --------
        >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
        >>> from synth.requirements import Bandwidth
        >>> loop = Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 9.0}))
        >>> Bandwidth(min=100).part_slacks(loop) == [Bandwidth(min=100).slack(loop)]
        True
        """
        return [self.slack(loop, per_decade)]

    def stable_slack(self, loop: Loop, per_decade: int = 80) -> float:
        """:meth:`slack` on a loop the caller has already counted closed-loop stable (as
        :meth:`synth.loop.Loop.stability` counts, e.g. by a D-decomposition over a grid): a type that would count
        the loop's roots again before its own work skips that count. The base form is :meth:`slack`.

        Examples
        --------
        >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
        >>> from synth.requirements import Bandwidth
        >>> loop = Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 9.0}))
        >>> Bandwidth(min=100).stable_slack(loop) == Bandwidth(min=100).slack(loop)
        True
        """
        return self.slack(loop, per_decade)

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Slack on every loop of ``batch`` (one plant, many controllers), as an array.

        A type with a vectorized form overrides this (all loops and frequencies at once, peaks and
        crossings refined; it agrees with :meth:`slack` to rounding and is used to bracket the edges
        of feasible sets, which :meth:`slack` then refines). This base form is the scalar fallback:
        :meth:`slack` on one loop at a time.

        Examples
        --------
        >>> from synth.loop_batch import LoopBatch; from synth.plant import Plant; from synth.controllers import Controller
        >>> from synth.requirements import Bandwidth
        >>> batch = LoopBatch(Plant.from_string("1/(s+1)"), [Controller("P", {"kp": k}) for k in (9.0, 200.0)])
        >>> bool(np.allclose(Bandwidth(min=100).batch_slack(batch), Requirement.batch_slack(Bandwidth(min=100), batch)))
        True
        """
        return np.array([self.slack(loop, per_decade) for loop in batch.loops()], dtype=float)

    def fails_surely(self, loops: list[Any]) -> np.ndarray:
        """For each loop (closed-loop stable), True where a cheaper evaluation than :meth:`slack`'s proves the
        requirement fails (its slack would be negative); False says nothing. Searches on the exact check ask
        this first and evaluate the requirement only where it says nothing. The base form proves nothing.

        Examples
        --------
        >>> from synth.plant import Plant; from synth.controllers import Controller; from synth.loop import Loop
        >>> from synth.requirements import Bandwidth
        >>> Bandwidth(min=100).fails_surely([Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1.0}))])
        array([False])
        """
        return np.zeros(len(loops), dtype=bool)

    @classmethod
    def has_batch_form(cls) -> bool:
        """Whether the type has a vectorized :meth:`batch_slack` (else the scalar fallback runs).

        Examples
        --------
        >>> from synth.requirements import Bandwidth
        >>> Bandwidth.has_batch_form()
        True
        """
        return cls.batch_slack is not Requirement.batch_slack

    def vectorized_on(self, plants: list[Any]) -> bool:
        """Whether :meth:`batch_slack` is vectorized on these plants (the type's form, :meth:`has_batch_form`; a
        type whose form covers only some plants or settings says so here).

        Examples
        --------
        >>> from synth.plant import Plant; from synth.requirements import Bandwidth
        >>> Bandwidth(min=1).vectorized_on([Plant.from_string("1/(s+1)")])
        True
        """
        return type(self).has_batch_form()

    def name(self) -> str:
        """Label given in the spec, or the type name."""
        return self.label or self.type

    @classmethod
    def stricter_when(cls, field: str, index: int | None = None) -> int:
        """+1 when a larger value of ``field`` (item ``index`` of a pair such as ``band``) makes the
        requirement stricter, -1 when a smaller one does; a field with no known direction is a
        :class:`SpecError` naming the type and the field.

        Examples
        --------
        >>> from synth.requirements import Bandwidth, SlewRate
        >>> Bandwidth.stricter_when("min"), Bandwidth.stricter_when("max"), SlewRate.stricter_when("max_error")
        (1, -1, 1)
        >>> SlewRate.stricter_when("band", 0), SlewRate.stricter_when("band", 1)
        (-1, 1)
        """
        name = cls.model_fields["type"].default
        if field in cls.bounds:
            return cls.bounds[field].stricter_when
        if field in cls.stricter:
            return cls.stricter[field]
        if field == "band" and "band" in cls.model_fields and index in (0, 1):
            return -1 if index == 0 else +1  # a wider band is stricter
        raise SpecError(f"requirement type {name!r} has no direction for {field!r}: "
                        "sweep one of " + ", ".join([*cls.bounds, *cls.stricter]), where=f"requirements.{name}")

    def linear_bound(self, field: str) -> float | None:
        """The bound ``field`` in linear units (a dB bound as a magnitude); None when not given.

        Examples
        --------
        >>> from synth.requirements import PeakSensitivity
        >>> round(PeakSensitivity(max_db=6).linear_bound("max_db"), 4)
        1.9953
        """
        value = getattr(self, field)
        if value is None:
            return None
        return magnitude(value) if self.bounds[field].unit == "dB" else float(value)

    def bound_of(self, value: float) -> Bound:
        """The bound a result quotes as ``value`` (for requirements with several bounds, the one with
        that value; else the first given).

        Examples
        --------
        >>> from synth.requirements import Bandwidth
        >>> Bandwidth(min=60, max=80).bound_of(80.0).direction
        'upper'
        """
        given = [(f, b) for f, b in self.bounds.items() if getattr(self, f, None) is not None]
        if not given:
            raise SpecError(f"requirement type {self.type!r} declares no bound fields", where="requirements")
        for f, b in given:
            if getattr(self, f) == value:
                return b
        return given[0][1]

    def report_row(self, result: RequirementResult) -> ReportRow:
        """The report's row for ``result`` (this requirement evaluated on a loop).

        Examples
        --------
        >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
        >>> from synth.requirements import Bandwidth
        >>> req = Bandwidth(min=100)
        >>> row = req.report_row(req.evaluate(Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 9.0}))))
        >>> row.bound_text(), row.met, row.slack < 0
        ('>= 100 rad/s', False, True)
        """
        return ReportRow(result.label, result.value, self.bound_of(result.bound).relation, result.bound, result.unit,
                         result.slack, result.met)

    def result(self, *, value: float, bound: float, unit: str, slack: float, margin: float,
               binding_frequency: float | None, message: str, **details: Any) -> RequirementResult:
        """Build a :class:`RequirementResult` for this requirement."""
        slack = float(slack)
        return RequirementResult(
            type=self.type, label=self.name(), value=float(value), bound=float(bound), unit=unit,
            slack=slack, margin=float(margin),
            binding_frequency=None if binding_frequency is None else float(binding_frequency),
            met=bool(slack >= 0), message=message, details=details,
        )


def fmt(x: float | None, digits: int = 4) -> str:
    """Format a number for messages: ``inf``, ``-inf``, ``n/a``, or ``digits`` significant digits.

    Examples
    --------
    >>> fmt(83.1567), fmt(10000.0), fmt(float("inf")), fmt(None)
    ('83.16', '10000', 'inf', 'n/a')
    """
    if x is None or (isinstance(x, float) and np.isnan(x)):
        return "n/a"
    if np.isinf(x):
        return "inf" if x > 0 else "-inf"
    text = f"{x:.{digits}g}"
    if "e+" in text and abs(x) < 1e7:  # 10000, not 1e+04
        text = f"{x:.{int(np.floor(np.log10(abs(x)))) + 1}g}"
    return text


def db(x: float) -> float:
    """``20 log10 |x|`` with ``-inf`` for zero.

    Examples
    --------
    >>> round(db(0.1), 6)
    -20.0
    """
    with np.errstate(divide="ignore"):
        return float(20.0 * np.log10(abs(x)))


def db_values(x: Any) -> np.ndarray:
    """``20 log10 |x|`` elementwise, ``-inf`` for zero.

    Examples
    --------
    >>> db_values(np.array([0.1, 10.0])).round(6)
    array([-20.,  20.])
    """
    with np.errstate(divide="ignore"):
        return 20.0 * np.log10(np.abs(np.asarray(x)))


def unique_names(requirements: list[Requirement]) -> list[str]:
    """One name per requirement, in order: its label or type, with ``#2``, ``#3`` ... on repeats.

    Examples
    --------
    >>> from synth.requirements import PeakSensitivity
    >>> unique_names([PeakSensitivity(max_db=6), PeakSensitivity(max_db=4, label="Ms")] * 2)
    ['peak_sensitivity', 'Ms', 'peak_sensitivity#2', 'Ms#2']
    """
    names, seen = [], {}
    for r in requirements:
        base = r.name()
        seen[base] = seen.get(base, 0) + 1
        names.append(base if seen[base] == 1 else f"{base}#{seen[base]}")
    return names
