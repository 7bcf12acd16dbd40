"""The polish holds the Nyquist curve's close approaches to -1 on the start's side once an answer has crossed:
the side's sign against a closed-form critical gain, and a polish that used to give up after its answers left
the stabilizing set, against an independent pole count (python-control, Pade approximation of the delay)."""

from __future__ import annotations

import control
import numpy as np
import pytest

from synth.controllers import Controller
from synth.plant import Plant
from synth.synthesis import nlp
from synth.synthesis.nlp_sides import close_approaches


def _critical_gain(poles: np.ndarray, gain: float, delay: float) -> tuple[float, float]:
    """``(K_u, w180)`` of ``gain / prod(s + p)`` behind ``delay`` under P control, from the closed-form phase
    ``-sum(atan(w / p)) - w delay`` (monotone: the first -180 deg crossing is the critical one)."""
    phase = lambda w: -np.sum(np.arctan(w / poles)) - w * delay  # noqa: E731
    lo, hi = 1e-9, 1.0
    while phase(hi) > -np.pi:
        hi *= 2
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if phase(mid) > -np.pi else (lo, mid)
    w = 0.5 * (lo + hi)
    magnitude = gain / np.prod(np.sqrt(w**2 + poles**2))
    return 1.0 / magnitude, w


@pytest.mark.parametrize("seed", range(12))
def test_the_side_of_minus_one_changes_at_the_critical_gain(seed: int) -> None:
    rng = np.random.default_rng(seed)
    poles = np.exp(rng.uniform(np.log(0.2), np.log(20.0), rng.integers(1, 4)))
    gain, delay = float(np.prod(poles)) * np.exp(rng.uniform(-1, 1)), float(np.exp(rng.uniform(np.log(0.02), 0.5)))
    plant = Plant(np.array([gain]), np.poly(-poles), delay=delay)
    k_u, w180 = _critical_gain(poles, gain, delay)
    sides = []
    for kp in (0.97 * k_u, 1.03 * k_u):
        near = [a for a in close_approaches(plant, Controller("P", {"kp": kp}), (1e-3, 1e3))
                if abs(np.log(a[0] / w180)) < 0.1]
        assert len(near) == 1, near  # the approach at the phase crossover
        sides.append(near[0][3])
    assert sides[0] == -sides[1]


def _pade_stable(plant: Plant, c: Controller) -> bool:
    num, den = c.tf()
    delay = control.tf(*control.pade(plant.delay, 12))
    loop = control.tf(list(num), list(den)) * control.tf(list(plant.num), list(plant.den)) * delay
    return bool(np.all(np.real(control.poles(control.feedback(loop, 1))) < 0))


def test_a_polish_whose_answers_crossed_minus_one_now_climbs_to_the_bound() -> None:
    """Third-order plant behind 86 ms, PID with a fixed filter, maximize ki within [0, 10]: the first round's
    answer (ki at its bound) is unstable. Repeated in shrinking trust regions without the hold, every answer
    crossed -1 again and the polish stopped at ki = 5.6; with the start's close approaches held on their side
    the rounds stay stable and reach ki = 10, a loop the independent pole count finds stable."""
    plant = Plant(np.array([0.61015067]), np.array([1.0, 4.18491059, 4.91132923, 1.08359981]), delay=0.08608432763464902)
    start = Controller("PID", {"kp": 0.05, "ki": 0.02, "kd": 0.01, "tf": 0.01})
    bounds = {"kp": (0.0, 10.0), "ki": (0.0, 10.0), "kd": (0.0, 5.0), "tf": (0.01, 0.01)}
    assert nlp.HOLD_SIDES == "after_unstable"
    r = nlp.polish([], [plant], start, bounds, [("integral_gain", "maximize", 1.0)], np.geomspace(0.01, 100, 250))
    assert r.history[0].get("unstable")
    assert any(h.get("held_approaches_to_minus_one") for h in r.history[1:])  # once a start came near -1
    best = max(r.candidates, key=lambda c: c.parameters["ki"])
    assert best.parameters["ki"] > 9.9
    assert _pade_stable(plant, best)
    s = 1j * np.geomspace(0.01, 100, 200_000)
    num, den = best.tf()
    loop = np.polyval(num, s) / np.polyval(den, s) * np.polyval(plant.num, s) / np.polyval(plant.den, s)
    assert np.min(np.abs(1 + loop * np.exp(-s * plant.delay))) > 0.05 * (1 - 1e-3)
