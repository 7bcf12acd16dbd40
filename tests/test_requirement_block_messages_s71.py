"""A no_limit_cycle requirement's actuator holds simulation blocks: a block without a type, or of an unknown
type, is named as a block (it said "requirement has no 'type'" with the list of requirement types)."""

from __future__ import annotations

import pytest

from synth.errors import SpecError
from synth.spec import parse_spec


def _spec(block: dict) -> dict:
    return {"name": "nlc", "plant": {"tf": "1/s^2"}, "controller": {"type": "leadlag"},
            "requirements": [{"type": "no_limit_cycle", "actuator": [block], "delay": [0, 0.01]}]}


@pytest.mark.parametrize("block, message", [
    ({"saturation": {"limit": 1.0}}, "requirements[0].actuator[0].type: block has no 'type'; expected one of: "
                                     "rate_limit, saturation"),
    ({"type": "satur", "max": 1}, "requirements[0].actuator[0].type: unknown block type 'satur'; expected one of: "
                                  "rate_limit, saturation"),
])
def test_a_requirement_block_is_named_as_a_block(block, message):
    with pytest.raises(SpecError) as err:
        parse_spec(_spec(block))
    assert message in str(err.value) and "margins" not in str(err.value)
