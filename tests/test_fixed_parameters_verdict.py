"""A design whose bounds fix every parameter says there is nothing to optimize (a black-box test, session 62: it
read "not shown to be a local optimum ... a better one may exist")."""

from synth.design import design
from synth.spec import parse_spec


def test_every_parameter_fixed_is_the_only_controller_not_a_possibly_better_one():
    spec = parse_spec({"name": "f1", "plant": {"tf": "1/((s+1)*(s+2))", "delay": 0.1},
                       "controller": {"type": "PI", "bounds": {"kp": [2, 2], "ki": [1.5, 1.5]}},
                       "requirements": [{"type": "margins", "gain_margin_db": 6, "phase_margin_deg": 45}],
                       "objective": {"maximize": "bandwidth"}})
    result = design(spec)
    assert result.feasible and result.controller.parameters == {"kp": 2.0, "ki": 1.5}
    assert "nothing to optimize" in result.verdict and "a better one may exist" not in result.verdict
    assert result.extras["optimality"]["local"] is True
