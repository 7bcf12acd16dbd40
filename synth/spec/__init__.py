"""Spec files: YAML, validated by pydantic, with one-line errors naming file, line and key.

The schema is documented in ``docs/spec-format.md``. The modules, along the spec's blocks:

- :mod:`synth.spec.loading`: :func:`parse_spec` (a mapping, YAML text, a path or a stream), :func:`load_spec`;
- :mod:`synth.spec.document`: :class:`Spec`, the whole problem;
- :mod:`synth.spec.plant_block`, :mod:`synth.spec.controller_block`, :mod:`synth.spec.objective`,
  :mod:`synth.spec.reference`: one block each, on the strict base of :mod:`synth.spec.strict`;
- :mod:`synth.spec.messages`: a pydantic error as one line ``<file>:<line>: <key path>: <what is wrong>``.
"""

from synth.spec.controller_block import ControllerSpec
from synth.spec.document import RequirementEntry, Spec
from synth.spec.loading import load_spec, parse_spec, parse_text
from synth.spec.objective import ObjectiveSpec, ObjectiveTerm
from synth.spec.plant_block import IdentifySpec, PlantSpec, SignalSpec, VariantSpec
from synth.spec.reference import AnalysisSpec, PublishedTF, ReferenceSpec

__all__ = [
    "AnalysisSpec",
    "ControllerSpec",
    "IdentifySpec",
    "ObjectiveSpec",
    "ObjectiveTerm",
    "PlantSpec",
    "PublishedTF",
    "ReferenceSpec",
    "RequirementEntry",
    "SignalSpec",
    "Spec",
    "VariantSpec",
    "load_spec",
    "parse_spec",
    "parse_text",
]
