"""Every registered requirement type is one self-describing concept with both solver forms.

Walks :data:`synth.requirements.REQUIREMENT_TYPES`: each type has a convex form and an NLP form, its
report row's slack has the sign its bound's direction says (checked on small loops where it is met and
where it is not), it declares a direction for each bound it has, and its spec-file block reads back as
the same requirement. A type registered without forms is a ``SpecError`` naming it (docs/extending-requirements.md).
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
import pytest
import yaml

from synth.controllers import Controller
from synth.errors import SpecError
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements import REQUIREMENT_TYPES, Bound, Requirement, register
from synth.requirements.base import RequirementResult
from synth.spec import parse_spec
from synth.synthesis.convex_forms import CONVEX_FORMS, build_forms
from synth.synthesis.nlp import polish
from synth.synthesis.nlp_forms import NLP_FORMS
from synth.synthesis.parametrization import parametrize

TYPES = sorted(REQUIREMENT_TYPES)
PLANT = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
GAINS = [0.05, 0.5, 3.0, 20.0, 60.0]  # from sluggish to aggressive: most types are met at one end only


def _example(name: str) -> Requirement:
    cls = REQUIREMENT_TYPES[name]
    assert cls.example, f"{cls.__name__} has no example spec block"
    return cls.model_validate(cls.example)


@pytest.mark.parametrize("name", TYPES)
def test_every_type_has_a_convex_and_an_nlp_form(name):
    cls = REQUIREMENT_TYPES[name]
    assert cls in CONVEX_FORMS, f"{cls.__name__}: no @convex_form in synth/synthesis/convex_forms.py"
    assert cls in NLP_FORMS, f"{cls.__name__}: no @nlp_form in synth/synthesis/nlp_forms.py"
    assert isinstance(CONVEX_FORMS.entry(cls).exact, bool) and isinstance(NLP_FORMS.entry(cls).exact, bool)


@pytest.mark.parametrize("name", TYPES)
def test_every_type_declares_its_bounds(name):
    cls = REQUIREMENT_TYPES[name]
    assert cls.bounds, f"{cls.__name__} declares no bound fields"
    req = _example(name)
    for field, bound in cls.bounds.items():
        assert field in cls.model_fields, f"{cls.__name__}.bounds names {field!r}, not a field"
        assert cls.stricter_when(field) == (+1 if bound.direction == "lower" else -1)
        value = getattr(req, field)
        if value is not None and bound.unit == "dB":
            assert req.linear_bound(field) == pytest.approx(10 ** (value / 20))
    with pytest.raises(SpecError, match=name):
        cls.stricter_when("no_such_field")


@pytest.mark.parametrize("name", TYPES)
def test_report_row_sign_follows_the_bound_direction(name):
    req = _example(name)
    seen = set()
    for kp in GAINS:
        result = req.evaluate(Loop(PLANT, Controller("P", {"kp": kp})))
        row = req.report_row(result)
        assert row.relation in ("<=", ">="), row
        assert row.consistent(), f"{name} at P({kp}): {row}"
        if np.isfinite(row.value) and row.value != row.bound:
            seen.add(row.met)
            if row.relation == ">=":  # a lower bound met shows positive slack, violated negative
                assert (row.value > row.bound) == (row.slack > 0) == row.met
            else:
                assert (row.value < row.bound) == (row.slack > 0) == row.met
    assert seen == {True, False}, f"{name}: the example should be met at one gain and violated at another"


@pytest.mark.parametrize("name", TYPES)
def test_spec_file_round_trip(name):
    req = _example(name)
    block = req.model_dump(mode="json", exclude_none=True)
    text = yaml.safe_dump({"name": "round-trip", "plant": {"tf": "1/(s+1)"},
                           "controller": {"type": "P", "bounds": {"kp": [0, 10]}}, "requirements": [block]})
    spec = parse_spec(text)
    assert spec.requirements[0] == req
    assert type(spec.requirements[0]) is type(req)


class _Throwaway(Requirement):
    """A type with no forms (registered for this test only)."""

    type: Literal["throwaway_test_type"] = "throwaway_test_type"
    max_db: float = 0.0
    bounds: ClassVar[dict[str, Bound]] = {"max_db": Bound("upper", "dB")}

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        return self.result(value=0.0, bound=self.max_db, unit="dB", slack=0.0, margin=0.0,
                           binding_frequency=None, message="")


@pytest.fixture
def throwaway():
    register(_Throwaway)
    try:
        yield _Throwaway()
    finally:
        REQUIREMENT_TYPES.pop("throwaway_test_type", None)
        CONVEX_FORMS.remove(_Throwaway)
        NLP_FORMS.remove(_Throwaway)


def test_a_type_without_forms_is_a_spec_error_naming_it(throwaway):
    par = parametrize("PI", {"kp": (0.0, 10.0), "ki": (0.0, 10.0)}, None, 1.0)
    grid = np.geomspace(0.1, 100, 50)
    with pytest.raises(SpecError, match=r"throwaway_test_type.*no convex form"):
        build_forms([throwaway], ["t"], [PLANT], par, grid, 20, 0.1)
    with pytest.raises(SpecError, match=r"throwaway_test_type.*no NLP form"):
        polish([throwaway], [PLANT], Controller("PI", {"kp": 1.0, "ki": 1.0}),
               {"kp": (0.0, 10.0), "ki": (0.0, 10.0)}, [("integral_gain", "maximize", 1.0)], grid, 20, 0.1)
