"""A batch's gain-margin factors behind a delay are each loop's own (``synth.stability_sets.gain_margin_factors``,
a separate search by D-decomposition), whatever else is in the batch.

The batch sampled every loop's ``Im L`` on one even grid up to the highest loop's top frequency, at most 20,000
points: a loop of high gain in the batch stretched that grid beyond a point every 0.3 rad of the delay's phase
for the others, which then missed crossings (a PI behind 1.37 s, closed-loop unstable: k_hi 1.0564 where its own
search gives 1.0016), and made a screen of PIs behind 10 ms evaluate 5.4 times the points it needs. Each loop now
gets the points its own top needs (groups of loops needing about as many). On closed-loop stable loops, where
the margins are used, the batch and the single-loop search agreed before and agree now
(``benchmarks/batch_gain_margins.py``)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant


def _same(a: float, b: float) -> bool:
    return (np.isinf(a) and np.isinf(b)) or bool(np.isclose(a, b, rtol=1e-8, atol=1e-12))


def test_a_high_gain_loop_in_the_batch_no_longer_coarsens_the_others():
    plant = Plant(np.array([57.577243281465925]), np.array([1.0, 3.9765397146727413]), 1.3730429712343248)
    high = Controller("PI", {"kp": 41.848349, "ki": 0.024107})  # its top needs more than 20,000 points
    others = [Controller("PI", {"kp": 2.505172, "ki": 367.064085}), Controller("PI", {"kp": 0.122711, "ki": 497.103453})]
    k_lo, k_hi = LoopBatch(plant, [high, *others]).gain_margin_factors()
    for i, c in enumerate(others, start=1):
        own_lo, own_hi = Loop(plant, c).gain_factors[:2]
        assert _same(k_lo[i], own_lo) and _same(k_hi[i], own_hi), (c, k_lo[i], k_hi[i], own_lo, own_hi)
    assert k_hi[2] == pytest.approx(1.0015705, rel=1e-6)  # 1.0564 before


def test_random_batches_agree_with_each_loops_own_search():
    """Seeded: plants of order 1-3 (a lightly damped pair in a third), delays 1 ms-2 s, P/PI/PID over five
    decades of gain, 5-30 loops a batch (this seed's batches agree on unstable loops too)."""
    rng = np.random.default_rng(5)
    compared = 0
    for _ in range(12):
        poles = -np.exp(rng.uniform(np.log(0.05), np.log(50), rng.integers(1, 4)))
        den, k = np.poly(poles), np.exp(rng.uniform(np.log(0.1), np.log(100)))
        if rng.random() < 0.3:
            wn, zeta = np.exp(rng.uniform(0, 3)), rng.uniform(0.01, 0.3)
            den, k = np.polymul(den, [1, 2 * zeta * wn, wn * wn]), k * wn * wn
        plant = Plant(np.array([k * abs(np.prod(poles))]), den, float(np.exp(rng.uniform(np.log(0.001), np.log(2.0)))))
        kind = rng.choice(["P", "PI", "PID"])
        controllers = []
        for _ in range(int(rng.integers(5, 30))):
            g = {"kp": float(np.exp(rng.uniform(np.log(1e-3), np.log(50))))}
            if kind != "P":
                g["ki"] = float(np.exp(rng.uniform(np.log(1e-3), np.log(500 if kind == "PI" else 50))))
            if kind == "PID":
                g.update(kd=float(np.exp(rng.uniform(np.log(1e-4), np.log(5)))), tf=0.01)
            controllers.append(Controller(kind, g))
        k_lo, k_hi = LoopBatch(plant, controllers).gain_margin_factors()
        for i, c in enumerate(controllers):
            own_lo, own_hi = Loop(plant, c).gain_factors[:2]
            assert _same(k_lo[i], own_lo) and _same(k_hi[i], own_hi), (plant, c, k_lo[i], k_hi[i], own_lo, own_hi)
            compared += 1
    assert compared > 150
