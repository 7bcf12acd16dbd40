"""One-parameter designs whose stabilizing interval is a sliver of the bounds (the design benchmark's seed 8
#154: an integrating plant of gain 2e5 behind 0.23 s of delay, stable only for kp < 1.7e-4 of [0, 17.8]).

Three faults made the design without integral action answer "no kp stabilizes": a PI over kp with ki = 0 is
kp s / s at kp = 0 but kp / 1 above, so the family did not look affine and its stabilizing set came from a
grid that had no point inside the sliver; the requirements were bracketed on the whole range's grid, none
of whose points lay inside it; and a design at the interval's end was moved inward by 1e-6 absolute
(2 % of kp = 5e-5)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import synth
from benchmarks.design_problems import generate
from synth.controllers import Controller
from synth.design import design
from synth.loop import Loop
from synth.plant import Plant
from synth.synthesis.gainset import ScalarFamily, stability_set
from synth.synthesis.integral_action import without_integral_action

PLANT = "193649*(1-s/25.2978)/(s*(s+0.402729)*(s+4.15013)*(s+67.4339)*(s+0.47593))"
REFERENCE_KP = 5.156566213774724e-05  # the benchmark's stored reference optimum (300 starts + Nelder-Mead)


def _stable(plant: Plant, kp: float) -> bool:
    return Loop(plant, Controller("P", {"kp": kp})).stability().stable  # Nyquist count, not D-decomposition


@pytest.mark.parametrize("kind", ["PI", "PID"])
def test_stabilizing_sliver_of_a_pi_or_pid_without_integral_action(kind):
    plant = Plant.from_string(PLANT, delay=0.227045)
    fixed = {"ki": 0.0} | ({"kd": 0.0, "tf": 0.01} if kind == "PID" else {})
    (lo, hi), = stability_set(ScalarFamily(kind, "kp", {"kp": 1.0, **fixed}), [plant], 0.0, 17.7641)
    assert lo < 1e-8 and 1.6e-4 < hi < 1.8e-4
    assert _stable(plant, 0.999 * hi) and not _stable(plant, 1.001 * hi)


def test_random_slivers_against_the_nyquist_count():
    # plants with an integrator and a delay, scaled so that the stabilizing kp interval is 1e-6 to 1e-4 of
    # the bounds; its upper end is found by bisection on the Nyquist count (independent of the D-decomposition)
    rng = np.random.default_rng(21)
    for _ in range(6):
        poles = rng.uniform(0.2, 20.0, size=int(rng.integers(1, 4)))
        plant = Plant(np.array([1.0]), np.poly(np.r_[0.0, -poles]), delay=float(rng.uniform(0.01, 0.5)))
        top = 1.0
        while _stable(plant, top):
            top *= 2.0
        a, b = (top / 2 if top > 1.0 else 0.0), top  # stable at top / 2: the last doubling passed
        while b - a > 1e-12 * b:  # to 1e-12 relative, a million times finer than the check below
            a, b = ((a + b) / 2, b) if _stable(plant, (a + b) / 2) else (a, (a + b) / 2)
        scale = b / float(10 ** rng.uniform(-6, -4))  # the bounds [0, 1] then hold the sliver [0, 1e-6..1e-4]
        scaled = Plant(plant.num * scale, plant.den, delay=plant.delay)
        ivs = stability_set(ScalarFamily("PI", "kp", {"kp": 1.0, "ki": 0.0}), [scaled], 0.0, 1.0)
        assert len(ivs) == 1 and ivs[0][1] == pytest.approx(b / scale, rel=1e-6)


def test_design_without_integral_action_reaches_the_reference():
    spec = synth.parse_spec(generate(155, 8)[154].spec)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = design(without_integral_action(spec))
    assert result.feasible
    (lo, hi), = result.gain_set.as_list()
    assert lo < 1e-8  # the stabilizing set starts at the stability floor above kp = 0
    assert hi == pytest.approx(REFERENCE_KP, rel=2e-3)  # the peak |S| bound ends the sliver
    assert result.controller.parameters["kp"] == pytest.approx(hi, rel=1e-5)  # moved inward relatively
