"""The ``objective:`` block of a spec: one measure to maximize or minimize, or a weighted sum.

The measures are :data:`synth.objectives.MEASURES`.
"""

from __future__ import annotations

from pydantic import Field, model_validator

from synth.objectives import MEASURES
from synth.spec.strict import StrictModel

__all__ = ["ObjectiveSpec", "ObjectiveTerm"]


def _known_measure(name: str) -> str:
    if name not in MEASURES:
        raise ValueError(f"unknown objective {name!r}; expected one of: {', '.join(MEASURES)}")
    return name


class ObjectiveTerm(StrictModel):
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


class ObjectiveSpec(StrictModel):
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


