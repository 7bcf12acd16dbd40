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

from benchmarks.batch_gain_margins import batch, same
from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant


def test_a_high_gain_loop_in_the_batch_no_longer_coarsens_the_others():
    plant = Plant(np.array([57.577243281465925]), np.array([1.0, 3.9765397146727413]), 1.3730429712343248)
    high = Controller("PI", {"kp": 41.848349, "ki": 0.024107})  # its top needs more than 20,000 points
    others = [Controller("PI", {"kp": 2.505172, "ki": 367.064085}), Controller("PI", {"kp": 0.122711, "ki": 497.103453})]
    k_lo, k_hi = LoopBatch(plant, [high, *others]).gain_margin_factors()
    for i, c in enumerate(others, start=1):
        own_lo, own_hi = Loop(plant, c).gain_factors[:2]
        assert same(k_lo[i], own_lo) and same(k_hi[i], own_hi), (c, k_lo[i], k_hi[i], own_lo, own_hi)
    assert k_hi[2] == pytest.approx(1.0015705, rel=1e-6)  # 1.0564 before


def test_random_batches_agree_with_each_loops_own_search():
    """Seeded batches of ``benchmarks/batch_gain_margins.py`` with 5-29 loops each (this seed's batches agree on
    unstable loops too)."""
    rng = np.random.default_rng(5)
    compared = 0
    for _ in range(12):
        plant, controllers = batch(rng, max_loops=30)
        k_lo, k_hi = LoopBatch(plant, controllers).gain_margin_factors()
        for i, c in enumerate(controllers):
            own_lo, own_hi = Loop(plant, c).gain_factors[:2]
            assert same(k_lo[i], own_lo) and same(k_hi[i], own_hi), (plant, c, k_lo[i], k_hi[i], own_lo, own_hi)
            compared += 1
    assert compared > 150
