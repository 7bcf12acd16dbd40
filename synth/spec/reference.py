"""The report's extras in a spec: published numbers to compare with (``reference:``) and extra analyses."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, NonNegativeFloat, field_validator

from synth.controllers import Controller
from synth.errors import ModelError
from synth.spec.strict import StrictModel, check_transfer_function

__all__ = ["AnalysisSpec", "PublishedTF", "ReferenceSpec"]


class PublishedTF(StrictModel):
    """A published transfer function to compare against (e.g. a paper's closed loop)."""

    label: str
    tf: str

    @field_validator("tf")
    @classmethod
    def _parses(cls, text: str) -> str:
        return check_transfer_function(text)  # type: ignore[return-value]


class ReferenceSpec(StrictModel):
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


class AnalysisSpec(StrictModel):
    """Extra analyses for the report."""

    loop_delays: list[NonNegativeFloat] = Field(default_factory=lambda: [0.0, 0.005, 0.01, 0.015, 0.02])
    #: a seed paper whose numbers the report reconciles (``x4``: sizing, the disturbance chain on a
    #: SYNTHETIC record, every number that does not reconcile; :mod:`synth.report.paper_section`)
    paper: Literal["x4"] | None = None


