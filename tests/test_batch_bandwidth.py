"""``batch_bandwidths`` against ``Loop.bandwidth`` loop by loop, on random plants and controllers of every kind
(unstable and integrating plants, lightly damped modes, biproper plants, delays): the screen of a design ranks
its points by the batch form, the certificate judges the design by the loop's own."""

import numpy as np
import pytest

from benchmarks.batch_bandwidth_speed import KINDS, random_controller, random_plant
from synth.batch_bandwidth import CHUNK, batch_bandwidths
from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant


@pytest.mark.parametrize("seed", range(4))
def test_batch_bandwidths_are_each_loops_own(seed):
    rng = np.random.default_rng(seed)
    for kind in KINDS:
        plant = random_plant(rng)
        controllers = [random_controller(rng, kind) for _ in range(CHUNK // 4 + 7)]
        with np.errstate(all="ignore"):
            batch = batch_bandwidths(LoopBatch(plant, controllers))
            own = np.array([Loop(plant, c).bandwidth() for c in controllers])
        assert np.array_equal(np.isnan(batch), np.isnan(own)), (plant, kind)
        assert np.array_equal(np.isinf(batch), np.isinf(own)), (plant, kind)
        finite = np.isfinite(own)
        assert batch[finite] == pytest.approx(own[finite], rel=1e-9, abs=0.0), (plant, kind)


def test_more_loops_than_a_chunk_keep_their_order():
    plant = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    gains = np.geomspace(0.01, 20.0, 2 * CHUNK + 3)[::-1]  # grid lengths vary with the gain: rows get sorted
    controllers = [Controller("PI", {"kp": float(k), "ki": float(2 * k)}) for k in gains]
    batch = batch_bandwidths(LoopBatch(plant, controllers))
    for i in (0, CHUNK - 1, CHUNK, 2 * CHUNK + 2):
        assert batch[i] == pytest.approx(Loop(plant, controllers[i]).bandwidth(), rel=1e-12)
    assert np.all(np.diff(batch) < 0)  # lower gains, lower bandwidths, in the order given
