"""The random screen hands the NLP distinct starts: a pinned copy whose draw pinned no parameter is its
original again, and polishing it twice repeats the same IPOPT run (seed 8 #135 of the design benchmark spent
one of its two screen polishes, 3 s, on such a copy)."""

import numpy as np
import pytest

from synth.spec import parse_spec
from synth.synthesis.integral_action import objective_terms
from synth.synthesis.screen import screen_improving, screen_points, screen_starts

RATIONAL_135 = {
    "name": "rand_8_135",
    "plant": {"tf": "0.165213*1/((s+1.4781)*(s+0.0885526)*(s+0.521466))", "delay": 0.0},
    "controller": {"type": "rational", "order": [0, 3],
                   "bounds": {"b0": [-0.221228, 0.221228], "a0": [0.0, 7.94018], "a1": [0.0, 43.9877],
                              "a2": [0.0, 243.687]}},
    "requirements": [{"type": "sensitivity_static", "max_db": -12.7462, "plant_gain": 1.63965},
                     {"type": "peak_control_sensitivity", "max_db": 27.7767}],
    "objective": {"maximize": "bandwidth"},
}


def _keys(controllers):
    return [tuple(sorted(c.parameters.items())) for c in controllers]


def test_the_screen_of_135_has_a_copy_equal_to_its_original_and_hands_it_over_once():
    spec = parse_spec(RATIONAL_135)
    keys = _keys(screen_points(spec))
    assert len(set(keys)) < len(keys)  # the situation this guards against is present in this screen
    starts = screen_improving(spec, objective_terms(spec), 0.184)  # the convex design's 0.182 rad/s + 1 %
    assert len(starts) >= 1
    assert len(set(_keys(starts))) == len(starts)  # before: the same controller twice


@pytest.mark.parametrize("seed", range(6))
def test_random_specs_get_distinct_starts(seed):
    rng = np.random.default_rng(seed)
    poles = -np.sort(rng.uniform(0.2, 20.0, 2))
    kind = ["PID", "rational", "leadlag"][seed % 3]
    bounds = {"PID": {"kp": [0, 10], "ki": [0, 10], "kd": [0, 1], "tf": [0.01, 0.01]},
              "rational": {"b0": [-5, 5], "b1": [-5, 5], "a0": [0, 10], "a1": [0, 10]},
              "leadlag": {"k": [0, 20], "z": [0.1, 10], "p": [1, 100]}}[kind]
    controller = {"type": kind, "bounds": bounds, **({"order": [1, 2]} if kind == "rational" else {})}
    spec = parse_spec({"name": f"r{seed}", "plant": {"tf": f"5/((s+{-poles[0]:.4f})*(s+{-poles[1]:.4f}))"},
                       "controller": controller,
                       "requirements": [{"type": "peak_sensitivity", "max_db": 8.0}],
                       "objective": {"maximize": "bandwidth"}})
    for starts in (screen_starts(spec, keep=3), screen_improving(spec, objective_terms(spec), 0.0, keep=3)):
        assert len(set(_keys(starts))) == len(starts)
