"""Rational fixed-order controllers C = X/D through the P = D + G X convex forms and the NLP."""

import pytest

from synth.check import check
from synth.design import design
from synth.spec import parse_spec

X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"


def test_rational_first_order_with_integrator_equals_the_pi_optimum():
    # (b1 s + b0)/s is a PI with kp = b1, ki = b0: both parametrizations must reach the same optimum
    rational = design(parse_spec(f"""
name: r
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: rational, order: [1, 1], bounds: {{b0: [0, 200], b1: [0, 10], a0: [0, 0]}}}}
requirements: [{{type: peak_sensitivity, max_db: 6}}]
objective: {{maximize: integral_gain}}"""))
    pi = design(parse_spec(f"""
name: pi
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: PI, bounds: {{kp: [0, 10], ki: [0, 200]}}}}
requirements: [{{type: peak_sensitivity, max_db: 6}}]
objective: {{maximize: integral_gain}}"""))
    assert rational.feasible and pi.feasible
    assert rational.objective["value"] == pytest.approx(pi.objective["value"], rel=2e-3)
    assert rational.controller.parameters["b1"] == pytest.approx(pi.controller.parameters["kp"], rel=2e-2)


@pytest.mark.slow
def test_second_order_rational_meets_margins_exactly():
    spec = parse_spec(f"""
name: r2
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: rational, order: [2, 2], bounds: {{a0: [0, 0]}}}}
requirements:
  - {{type: peak_sensitivity, max_db: 6}}
  - {{type: margins, phase_margin_deg: 45, gain_margin_db: 6}}
objective: {{maximize: crossover}}""")
    result = design(spec)
    assert result.feasible and result.certificate.passed
    res = check(spec, result.controller, per_decade=4000)
    margins = {r.type: r for r in res.requirements}["margins"]
    assert margins.details["phase_margin_deg"] >= 45 and margins.details["gain_margin_db"] >= 6
    # a second-order controller does at least as well as the best PI on the same spec
    pi = design(parse_spec(f"""
name: pi
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: PI, bounds: {{kp: [0, 20], ki: [0, 500]}}}}
requirements:
  - {{type: peak_sensitivity, max_db: 6}}
  - {{type: margins, phase_margin_deg: 45, gain_margin_db: 6}}
objective: {{maximize: crossover}}"""))
    assert result.objective["value"] >= pi.objective["value"] * (1 - 1e-3)


def test_rational_controller_text_round_trip(run_cli):
    res = run_cli("check", "specs/x4_rotor.yaml", "--controller", "rational(b0=60, b1=3, a0=0)")
    assert res.code == 0, res.out + res.err
    assert "rational(b0=60, b1=3, a0=0)" in res.out
