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
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, field_validator

if TYPE_CHECKING:
    from synth.loop import Loop

NEPER_PER_DB = np.log(10.0) / 20.0


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
    """Class decorator: make a requirement available under its ``type`` name."""
    name = cls.model_fields["type"].default
    REQUIREMENT_TYPES[name] = cls
    return cls


class Requirement(BaseModel):
    """Base of all requirement types (one pydantic model per ``type:``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    type: str
    label: str | None = None

    title: ClassVar[str] = "requirement"

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:  # pragma: no cover
        """Evaluate on ``loop``; ``per_decade`` sets the density of the frequency grid."""
        raise NotImplementedError

    def name(self) -> str:
        """Label given in the spec, or the type name."""
        return self.label or self.type

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


class BandMixin(BaseModel):
    """A frequency band ``[low, high]`` in rad/s with ``0 <= low < high``."""

    band: tuple[float, float]

    @field_validator("band")
    @classmethod
    def _check_band(cls, band: tuple[float, float]) -> tuple[float, float]:
        lo, hi = band
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise ValueError(f"band must be finite, got [{lo:g}, {hi:g}]")
        if lo < 0 or hi <= 0:
            raise ValueError(f"band must be non-negative frequencies in rad/s, got [{lo:g}, {hi:g}]")
        if hi <= lo:
            raise ValueError(f"band must be [low, high] with low < high, got [{lo:g}, {hi:g}]")
        return band


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
