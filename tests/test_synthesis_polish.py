"""The NLP polish is skipped only where it cannot improve the convex answer, and there it indeed does not.

``polish_redundant`` skips IPOPT when the convex-concave stage converged to a KKT point of the very
problem the polish solves (P/PI/PID, requirements with exact convex forms, a linear objective). These
tests run the polish anyway from that answer and check that it finds nothing better, on specs of
every admitted requirement type, one and several plants; and that the polish still runs elsewhere.
"""

import pytest

from synth.spec import parse_spec
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.multi import convex_runs, design_convex, objective_terms, polish_redundant
from synth.synthesis.nlp import polish

X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"
VARIANTS = """
  variants:
    - {label: low, gain: 0.85}
    - {label: high, gain: 1.1}"""

SKIPPED = [
    ("PI", "{kp: [0, 10], ki: [0, 200]}", 0.02, "", "[{type: peak_sensitivity, max_db: 6}]", "integral_gain"),
    ("PI", "{kp: [0, 10], ki: [0, 200]}", 0.01, "",
     "[{type: peak_sensitivity, max_db: 5}, {type: peak_complementary, max_db: 2}]", "integral_gain"),
    ("PI", "{kp: [0, 10], ki: [0, 200]}", 0.015, VARIANTS,
     "[{type: peak_sensitivity, max_db: 6}, {type: peak_control_sensitivity, max_db: 12}]", "integral_gain"),
    ("PI", "{kp: [0, 10], ki: [0, 200]}", 0.02, VARIANTS,
     "[{type: sensitivity, max_db: -10, band: [0, 2]}, {type: slew_rate, rate_limit: 1000, max_error: 5, "
     "band: [0.1, 100]}, {type: peak_sensitivity, max_db: 6}]", "integral_gain"),
    ("PID", "{kp: [0, 20], ki: [0, 2000], kd: [0, 0.5], tf: [0.002, 0.002]}", 0.01, "",
     "[{type: sensitivity, max_db: -15, band: [0, 5]}, {type: peak_sensitivity, max_db: 6}, "
     "{type: peak_complementary, max_db: 2}, {type: slew_rate, rate_limit: 10000, max_error: 5, "
     "band: [0.1, 1000]}]", "integral_gain"),
    ("P", "{kp: [0, 20]}", 0.01, "", "[{type: peak_complementary, max_db: 2}]", "low_frequency_gain"),
]


def _spec(ctype, bounds, delay, variants, reqs, obj):
    return parse_spec(f"""
name: polish
plant:
  tf: "{X4}"
  delay: {delay}{variants}
controller: {{type: {ctype}, bounds: {bounds}}}
requirements: {reqs}
objective: {{maximize: {obj}}}""")


@pytest.mark.parametrize("case", SKIPPED, ids=[f"{c[0]}-{i}" for i, c in enumerate(SKIPPED)])
def test_polish_from_a_converged_convex_answer_finds_nothing_better(case):
    spec = _spec(*case)
    settings = ConvexSettings()
    runs = convex_runs(spec, settings)
    designer, conv = runs[0]
    assert polish_redundant(spec, [r for _, r in runs]) is not None
    terms = objective_terms(spec)
    res = polish(list(spec.requirements), spec.plants(), conv.controller, spec.controller.all_bounds(), terms,
                 designer.grid, settings.per_decade, settings.stability_level)
    assert res.success
    # the polish's own bounds are tighter by about 1e-8 (2e-4 on squares against (1 - 1e-4)^2): equal to 1e-6
    assert res.objective_value <= conv.objective_value * (1 + 1e-6)
    assert res.objective_value == pytest.approx(conv.objective_value, rel=1e-6)
    for name, value in conv.controller.parameters.items():
        assert res.controller.parameters[name] == pytest.approx(value, rel=1e-4, abs=1e-6 * max(1.0, abs(value)))

    result = design_convex(spec)
    assert result.feasible and result.certificate.passed
    assert "nlp" not in result.extras["synthesis"] and "nlp_skipped" in result.extras["synthesis"]
    assert result.extras["synthesis"]["chosen"] == "convex"
    assert "NLP polish skipped" in result.method


@pytest.mark.parametrize("case", [
    # margins: the convex half-plane is an inner approximation, the NLP imposes them exactly
    ("PI", "{kp: [0, 10], ki: [0, 200]}", 0.02, "",
     "[{type: margins, gain_margin_db: 6, phase_margin_deg: 45}]", "integral_gain"),
    # a free derivative filter: the convex stage holds it at three values, the NLP frees it
    ("PID", "{kp: [0, 10], ki: [0, 200], kd: [0, 0.5], tf: [0.002, 0.02]}", 0.02, "",
     "[{type: peak_sensitivity, max_db: 6}]", "integral_gain"),
], ids=["margins", "free-tf"])
def test_polish_runs_where_it_may_improve(case):
    spec = _spec(*case)
    result = design_convex(spec)
    assert "nlp" in result.extras["synthesis"] and "nlp_skipped" not in result.extras["synthesis"]
