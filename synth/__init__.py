"""synth: fixed-structure compensator design from measured data and written specs.

Public API
----------
load_spec, parse_spec
    Read and validate a spec file.
check
    Evaluate a controller against every requirement of a spec.
design
    Design the spec's controller (exact gain set for one free parameter).
feasible_gain_set
    Exact feasible set of one controller parameter.
Plant, Controller, Loop
    Models: rational transfer function times an exact delay; fixed-structure
    controllers; the feedback loop.
closed_loop_stability
    Exact closed-loop stability with a delay.
write_design_report
    ``result.json``, ``report.html`` and figures.

Examples
--------
>>> import synth
>>> spec = synth.load_spec("specs/x4_rotor.yaml")
>>> synth.check(spec, "P(3)").feasible
True
"""

__version__ = "0.1.0"

from synth.check import CheckResult, check
from synth.controllers import Controller
from synth.design import DesignResult, design
from synth.errors import DataError, ModelError, SpecError, SynthError
from synth.gainset import GainSet, ScalarFamily, feasible_gain_set
from synth.loop import Loop
from synth.plant import Plant, Signal
from synth.spec import Spec, load_spec, parse_spec
from synth.stability import closed_loop_stability


def write_design_report(*args, **kwargs):
    """Write a design report (see :func:`synth.report.design_report.write_design_report`).

    Imported on first use: matplotlib is not loaded by ``import synth``.
    """
    from synth.report.design_report import write_design_report as _write

    return _write(*args, **kwargs)


__all__ = [
    "CheckResult",
    "Controller",
    "DataError",
    "DesignResult",
    "GainSet",
    "Loop",
    "ModelError",
    "Plant",
    "ScalarFamily",
    "Signal",
    "Spec",
    "SpecError",
    "SynthError",
    "__version__",
    "check",
    "closed_loop_stability",
    "design",
    "feasible_gain_set",
    "load_spec",
    "parse_spec",
    "write_design_report",
]
