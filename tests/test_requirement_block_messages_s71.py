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


def test_a_check_across_a_blocks_keys_points_at_the_line_of_the_key_it_names(tmp_path):
    """``controller_rate: 33`` under ``dt: 0.01`` pointed at the ``simulation:`` line (black-box finding)."""
    from synth.spec import load_spec

    path = tmp_path / "cr.yaml"
    path.write_text("name: cr\nplant: {tf: '1/(s+1)'}\ncontroller: {type: P}\n"
                    "requirements: [{type: margins, gain_margin_db: 1}]\n"
                    "simulation:\n  dt: 0.01\n  step: [0, 1]\n  controller_rate: 33\n")
    with pytest.raises(SpecError) as err:
        load_spec(path)
    assert f"{path}:8: simulation: controller_rate 33 Hz must be 1/dt" in str(err.value)
