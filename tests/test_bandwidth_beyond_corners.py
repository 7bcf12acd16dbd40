"""The bandwidth of a loop whose gain crossover lies beyond every corner frequency.

Seed 9 #28 of the design benchmark: on ``1.149/s`` a PI with its integral corner at 1e-3 rad/s crosses over at
1.68 rad/s, two decades above the range of corners (which ended at 0.11 rad/s); ``Loop.bandwidth`` found no
fall of ``|T|`` in that range and returned ``inf``, so the design maximizing bandwidth took the slowest
integral action in the bounds and reported "maximize bandwidth: inf rad/s" (the reference: 4.43 rad/s). The
reference here is a dense grid on ``T`` written from the polynomials, not synth's grid or root finding.
"""

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant


def _brute_bandwidth(num, den, c_num, c_den):
    w = np.geomspace(1e-7, 1e5, 600_001)
    s = 1j * w
    n = np.polyval(np.polymul(num, c_num), s)
    d = np.polyval(np.polymul(den, c_den), s)
    t = np.abs(n / (d + n))
    t0 = t[0]
    below = np.nonzero(t < t0 * 10 ** (-3 / 20))[0]
    return float(w[below[0]]) if below.size else np.inf


def test_seed9_28_pi_on_an_integrator():
    loop = Loop(Plant.from_string("1.14923*1/(s)"), Controller("PI", {"kp": 1.459, "ki": 0.0016750500035541934}))
    assert loop.bandwidth() == pytest.approx(1.67390, rel=1e-4)  # |T| = -3 dB there (brentq); before: inf


@pytest.mark.parametrize("seed", range(12))
def test_random_loops_with_slow_corners(seed):
    rng = np.random.default_rng(seed)
    gain = float(10 ** rng.uniform(-1, 1))
    fast = [float(10 ** rng.uniform(1, 3)) for _ in range(int(rng.integers(0, 2)))]
    plant = Plant.from_string(f"{gain:.6g}/(s" + "".join(f"*(s/{p:.6g}+1)" for p in fast) + ")")
    kp = float(10 ** rng.uniform(-0.5, 0.5))
    ki = kp * float(10 ** rng.uniform(-5, -2))  # the integral corner far below the crossover
    loop = Loop(plant, Controller("PI", {"kp": kp, "ki": ki}))
    if not loop.stability().stable:
        pytest.skip("unstable draw")
    c_num, c_den = loop.controller.tf()
    expected = _brute_bandwidth(plant.num, plant.den, c_num, c_den)
    assert np.isfinite(expected)
    assert loop.bandwidth() == pytest.approx(expected, rel=1e-3)
