"""Requirement types, registered by the ``type:`` name used in spec files.

Importing this package registers every built-in type in :data:`REQUIREMENT_TYPES`.
"""

from synth.requirements.bandwidth import Bandwidth
from synth.requirements.base import (
    REQUIREMENT_TYPES,
    Bound,
    ReportRow,
    Requirement,
    RequirementResult,
    magnitude,
    register,
    unique_names,
)
from synth.requirements.control_sensitivity import PeakControlSensitivity
from synth.requirements.delay_margin import DelayMargin
from synth.requirements.disk_margin import DiskMargin
from synth.requirements.margins import MarginsRequirement
from synth.requirements.no_limit_cycle import NoLimitCycle
from synth.requirements.sensitivity import (
    PeakComplementary,
    PeakRequirement,
    PeakSensitivity,
    Sensitivity,
    StaticSensitivity,
)
from synth.requirements.slew_rate import SlewRate
from synth.requirements.step_response import StepResponse

__all__ = [
    "REQUIREMENT_TYPES",
    "Bandwidth",
    "Bound",
    "DelayMargin",
    "DiskMargin",
    "MarginsRequirement",
    "NoLimitCycle",
    "PeakComplementary",
    "PeakControlSensitivity",
    "PeakRequirement",
    "PeakSensitivity",
    "ReportRow",
    "Requirement",
    "RequirementResult",
    "Sensitivity",
    "SlewRate",
    "StaticSensitivity",
    "StepResponse",
    "magnitude",
    "register",
    "unique_names",
]
