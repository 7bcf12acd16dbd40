"""synth: fixed-structure compensator design from measured data and written specs.

Public API
----------
load_spec, parse_spec
    Read and validate a spec file (``parse_spec`` also takes YAML text, a mapping or a stream).
check
    Evaluate a controller against every requirement of a spec.
design
    Design the spec's controller (exact gain set for one free parameter).
feasible_gain_set
    Exact feasible set of one controller parameter.
Plant, Controller, Loop
    Models: rational transfer function times an exact delay; fixed-structure
    controllers; the feedback loop. python-control models go in with
    ``Plant.from_control(sys, delay=...)`` (``Loop`` takes them, and ``"P(3)"``, as they are)
    and come back with ``Controller.to_control()`` and ``Plant.to_control(pade_order=...)``.
closed_loop_stability
    Exact closed-loop stability with a delay.
write_design_report
    ``result.json``, ``report.html`` and figures.
load_record, Record, as_record, record_from_arrays
    Measured records (CSV, MAT, arrays, a DataFrame) with one-line errors naming file and column.
identify
    Identify a structure such as ``k*(s+z)/((s+p1)*(s+p2))`` from a record or
    ``(t, u, y)`` arrays (step trains are averaged first); more in :mod:`synth.ident`.

Examples
--------
>>> import synth
>>> spec = synth.load_spec("specs/x4_rotor.yaml")
>>> synth.check(spec, "P(3)").feasible
True
"""

import os as _os

# synth's matrices are small (a few states, a few parameters): threaded BLAS only adds overhead, and on a
# loaded 2-core machine its spinning threads made 3x3 matrix exponentials 1000x slower. A user's own
# setting wins; this takes effect only if numpy was not imported before synth.
_os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from synth.check import CheckResult, check
from synth.controllers import Controller
from synth.data import Record, as_record, load_record, record_from_arrays
from synth.design import design
from synth.errors import DataError, ModelError, SpecError, SynthError
from synth.loop import Loop
from synth.plant import Plant, Signal
from synth.results import DesignResult
from synth.spec import Spec, load_spec, parse_spec
from synth.stability import closed_loop_stability
from synth.synthesis.gainset import GainSet, ScalarFamily, feasible_gain_set
from synth.version import __version__


def write_design_report(*args, **kwargs):
    """Write a design report (see :func:`synth.report.design_report.write_design_report`).

    Imported on first use: matplotlib is not loaded by ``import synth``.
    """
    from synth.report.design_report import write_design_report as _write

    return _write(*args, **kwargs)


def identify(*args, **kwargs):
    """Identify a structure from a record or arrays (see :func:`synth.ident.identification.identify`).

    The record may be ``(t, u, y)`` arrays, an N x 3 array, a DataFrame or mapping of
    columns, a CSV/MAT path or a :class:`Record` (see :func:`as_record`).
    Imported on first use: casadi is not loaded by ``import synth``.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 3, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(s+3)"), t, u)
    >>> identify((t, u, y), "k/(s+p)", average="none").plant.to_string(4)
    '2/(s+3)'
    """
    from synth.ident.identification import identify as _identify

    return _identify(*args, **kwargs)


__all__ = [
    "CheckResult",
    "Controller",
    "DataError",
    "DesignResult",
    "GainSet",
    "Loop",
    "ModelError",
    "Plant",
    "Record",
    "ScalarFamily",
    "Signal",
    "Spec",
    "SpecError",
    "SynthError",
    "__version__",
    "as_record",
    "check",
    "closed_loop_stability",
    "design",
    "feasible_gain_set",
    "identify",
    "load_record",
    "load_spec",
    "parse_spec",
    "record_from_arrays",
    "write_design_report",
]
