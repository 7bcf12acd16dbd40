"""The designed optimum equals a dense brute-force search within 0.5 % of the objective, for P and PI,
on several spec variants of the X-4 rotor loop (delays of 10-20 ms make them non-trivial)."""

import itertools

import numpy as np
import pytest

from synth.design import design
from synth.spec import parse_spec

from .bruteforce import best_p, best_pi

X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"

# (delay, requirements YAML, the same for the brute force, objective, sense)
PI_VARIANTS = [
    (0.02, "[{type: peak_sensitivity, max_db: 6}]", {"Ms": 6}, "integral_gain", "maximize"),
    (0.01, "[{type: peak_sensitivity, max_db: 4}, {type: peak_complementary, max_db: 2}]",
     {"Ms": 4, "Mt": 2}, "integral_gain", "maximize"),
    (0.02, "[{type: peak_sensitivity, max_db: 6}, {type: slew_rate, rate_limit: 1000, max_error: 5, "
     "band: [0.1, 100]}]", {"Ms": 6, "slew": (1000, 5, (0.1, 100))}, "integral_gain", "maximize"),
    (0.015, "[{type: peak_sensitivity, max_db: 6}, {type: peak_control_sensitivity, max_db: 12}]",
     {"Ms": 6, "KS": 12}, "integral_gain", "maximize"),
    (0.02, "[{type: bandwidth, min: 40}]", {"bw_min": 40}, "peak_sensitivity", "minimize"),
    (0.02, "[{type: peak_sensitivity, max_db: 6}]", {"Ms": 6}, "bandwidth", "maximize"),
]

P_VARIANTS = [
    (0.02, "[{type: peak_sensitivity, max_db: 6}]", {"Ms": 6}, "bandwidth", "maximize"),
    (0.01, "[{type: peak_complementary, max_db: 2}]", {"Mt": 2}, "low_frequency_gain", "maximize"),
    (0.0, "[{type: sensitivity_static, max_db: -15, plant_gain: 1.8}, {type: slew_rate, rate_limit: 10000, "
     "max_error: 5, band: [0.1, 100]}]", {"static": (-15, 1.8), "slew": (10000, 5, (0.1, 100))},
     "bandwidth", "maximize"),
    (0.015, "[{type: bandwidth, min: 40}]", {"bw_min": 40}, "peak_sensitivity", "minimize"),
    (0.02, "[{type: peak_control_sensitivity, max_db: 6}]", {"KS": 6}, "crossover", "maximize"),
]


def _spec(ctype, bounds, delay, reqs, obj, sense):
    return parse_spec(f"""
name: variant
plant: {{tf: "{X4}", delay: {delay}}}
controller: {{type: {ctype}, bounds: {bounds}}}
requirements: {reqs}
objective: {{{sense}: {obj}}}""")


def _comparable(value, objective):
    # dB objectives compare as linear magnitudes (a relative error of a dB value near 0 means nothing)
    return 10 ** (value / 20) if objective == "peak_sensitivity" else value


@pytest.mark.parametrize("variant", PI_VARIANTS, ids=[f"PI-{i}" for i in range(len(PI_VARIANTS))])
def test_pi_optimum_matches_brute_force(variant):
    delay, reqs, brute_reqs, obj, sense = variant
    result = design(_spec("PI", "{kp: [0, 10], ki: [0, 200]}", delay, reqs, obj, sense))
    assert result.feasible and result.certificate.passed
    brute_value, kp, ki = best_pi(delay, brute_reqs, obj, 10.0, 200.0)
    brute_value = -brute_value if obj == "peak_sensitivity" else brute_value
    got = _comparable(result.objective["value"], obj)
    want = _comparable(brute_value, obj)
    assert got == pytest.approx(want, rel=5e-3), (result.controller, kp, ki)
    if sense == "maximize":
        assert got >= want * (1 - 5e-3)
    else:
        assert got <= want * (1 + 5e-3)


@pytest.mark.parametrize("variant", P_VARIANTS, ids=[f"P-{i}" for i in range(len(P_VARIANTS))])
def test_p_optimum_matches_brute_force(variant):
    delay, reqs, brute_reqs, obj, sense = variant
    result = design(_spec("P", "{kp: [0, 20]}", delay, reqs, obj, sense))
    assert result.feasible and result.certificate.passed
    brute_value, kp = best_p(delay, brute_reqs, obj, 20.0)
    brute_value = -brute_value if obj == "peak_sensitivity" else brute_value
    assert _comparable(result.objective["value"], obj) == pytest.approx(_comparable(brute_value, obj), rel=5e-3), \
        (result.controller, kp)
    assert abs(result.controller.parameters["kp"] - kp) <= 5e-3 * max(1.0, kp)


def test_every_iterate_stays_feasible():
    spec = _spec("PI", "{kp: [0, 10], ki: [0, 200]}", 0.02, "[{type: peak_sensitivity, max_db: 6}]",
                 "integral_gain", "maximize")
    result = design(spec)
    history = result.extras["synthesis"]["convex"][0]["history"]
    phase2 = [h for h in history if h["phase"] == 2]
    assert len(phase2) >= 2
    assert all(h["max_violation"] <= 1e-9 for h in phase2)  # every iterate meets every requirement on the grid
    for rnd in {h["round"] for h in phase2}:
        values = [h["objective"] for h in phase2 if h["round"] == rnd]
        # and the objective never gets worse (up to the solver's accuracy, about 1e-8 relative)
        assert all(b >= a - 1e-8 * abs(a) for a, b in itertools.pairwise(values))
    assert np.isfinite(phase2[-1]["objective"])
