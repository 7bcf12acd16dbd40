"""The NLP's phase crossovers (synth.synthesis.nlp_problem.phase_crossings) on loops with long delays, against
a dense evaluation written here: every crossing of the negative real axis inside the unit circle above the
floor is found, none is invented, and each one's interval holds no other zero of Im L."""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.synthesis.nlp_problem import PHASE_CROSSOVER_FLOOR, phase_crossings


def _case(seed: int) -> Loop:
    rng = np.random.default_rng(seed)
    poles = rng.uniform(0.3, 20.0, rng.integers(1, 3))
    num = np.array([float(np.prod(poles))])
    if poles.size == 2 and rng.random() < 0.7:  # a zero: relative degree one, |L| fades slowly
        num = np.polymul(num, [1.0 / rng.uniform(0.3, 20.0), 1.0])
    plant = Plant(num, np.poly(-poles), delay=float(rng.uniform(0.05, 5.0)))
    return Loop(plant, Controller("P", {"kp": float(rng.uniform(0.3, 3.0))}))


@pytest.mark.parametrize("seed", range(10))
def test_phase_crossings_match_a_dense_grid(seed: int) -> None:
    loop = _case(seed)
    floor = PHASE_CROSSOVER_FLOOR / 2 if seed % 2 else PHASE_CROSSOVER_FLOOR
    w, lo, hi = phase_crossings(loop, floor)
    tau = loop.delay
    # the dense reference: 64 points per half-turn of the delay's phase, up to where |L| < floor / 2 for good
    top = 1.0
    while np.abs(loop.L(np.array([top])))[0] >= floor / 2 or top < 10 / tau:
        top *= 2
    dense = np.linspace(1e-4, top, int(64 * top * tau / np.pi) + 2)
    L = loop.L(dense)
    i = np.flatnonzero(np.sign(L.imag[:-1]) != np.sign(L.imag[1:]))
    zeros = dense[i] - L.imag[i] * (dense[i + 1] - dense[i]) / (L.imag[i + 1] - L.imag[i])
    Lz = loop.L(zeros)
    inside = (Lz.real < 0) & (np.abs(Lz) < 1)
    clear = inside & (np.abs(np.abs(Lz) / floor - 1) > 0.01) & (np.abs(np.abs(Lz) - 1) > 0.01)
    expected = zeros[clear & (np.abs(Lz) >= floor)]
    assert expected.size >= 1
    near = [float(np.min(np.abs(w - x))) / x for x in expected]
    assert max(near) < 1e-4, (expected, w)
    for x in w:  # nothing invented: each found crossing is a dense one (or within 1 % of the floor or the circle)
        assert np.min(np.abs(zeros[inside] - x)) / x < 1e-4
    for a, b, x in zip(lo, hi, w):
        between = zeros[(zeros >= a) & (zeros <= b)]
        assert between.size == 1 and abs(between[0] - x) / x < 1e-4


def test_the_margins_form_holds_the_crossings_near_its_bound_each_in_its_own_interval() -> None:
    """A biproper controller behind a 20 ms delay: ``|L|`` fades as 1/w, so the negative real axis is crossed
    every pi/0.02 rad/s for thousands of rad/s. The form holds those within 10 dB of -1/g (at most
    MAX_HELD_CROSSINGS, the closest to -1/g), each in an interval holding no other zero of Im L (before: every
    crossing a log grid found, aliased, in boxes of a factor 3 holding dozens of zeros)."""
    from synth.requirements import MarginsRequirement
    from synth.synthesis.nlp_forms import MAX_HELD_CROSSINGS, NLP_FORMS, NLPContext
    from synth.synthesis.nlp_problem import NLPBuilder, SymbolicController

    plant = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    start = Controller("leadlag", {"k": 150.0, "z": 5.0, "p": 50.0})
    req = MarginsRequirement(type="margins", gain_margin_db=6)
    b = NLPBuilder(SymbolicController("leadlag", start, {"k": (0, 500), "z": (0.1, 100), "p": (1, 1000)}))
    NLP_FORMS.entry(req).build(b, req, plant, NLPContext(np.geomspace(0.01, 1e4, 241), np.array([]), 40, start))
    held = [(float(x0[0]), float(lo[0]), float(hi[0])) for v, x0, lo, hi in zip(b.x, b.x0, b.lbx, b.ubx)
            if v.name() == "wp"]
    loop = Loop(plant, start)
    g = 10 ** (6 / 20)
    w = np.linspace(1.0, 2e4, 2_000_000)
    L = loop.L(w)
    i = np.flatnonzero(np.sign(L.imag[:-1]) != np.sign(L.imag[1:]))
    zeros = w[i]
    Lz = loop.L(zeros)
    near = zeros[(Lz.real < 0) & (np.abs(Lz) < 1) & (np.abs(Lz) >= 1 / (g * np.sqrt(10)))]
    assert near.size > MAX_HELD_CROSSINGS and len(held) == MAX_HELD_CROSSINGS
    assert np.allclose([x for x, _, _ in held], near[:MAX_HELD_CROSSINGS], rtol=1e-4)  # the closest to -1/g
    for x, lo, hi in held:
        inside = zeros[(zeros >= lo) & (zeros <= hi)]
        assert inside.size == 1 and abs(inside[0] - x) <= 1e-4 * x
