"""``batch_bandwidths`` against ``Loop.bandwidth`` loop by loop, on random plants and controllers of every kind
(unstable and integrating plants, lightly damped modes, biproper plants, delays): the screen of a design ranks
its points by the batch form, the certificate judges the design by the loop's own."""

import numpy as np
import pytest

from synth.batch_bandwidth import CHUNK, batch_bandwidths
from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant


def _random_plant(rng: np.random.Generator) -> Plant:
    order = int(rng.integers(1, 5))
    poles = -(10 ** rng.uniform(-1.5, 2, order)) * np.where(rng.random(order) < 0.15, -1, 1)
    if rng.random() < 0.2:
        poles[0] = 0.0
    den = np.real(np.poly(poles))
    if order >= 2 and rng.random() < 0.3:
        wn, zeta = 10 ** rng.uniform(-0.5, 2), 10 ** rng.uniform(-2, -0.3)
        den = np.polymul(np.real(np.poly(poles[:-2])), [1.0, 2 * zeta * wn, wn * wn])
    zeros = int(rng.integers(0, order + 1 if rng.random() < 0.2 else order))
    num = 10 ** rng.uniform(-1, 2) * np.real(np.poly(-(10 ** rng.uniform(-1, 2, zeros))
                                                      * np.where(rng.random(zeros) < 0.2, -1, 1)))
    return Plant(num, den, delay=0.0 if rng.random() < 0.5 else 10 ** rng.uniform(-3, -0.5))


def _random_controller(rng: np.random.Generator, kind: str) -> Controller:
    def g(lo: float, hi: float) -> float:
        return float(10 ** rng.uniform(lo, hi))

    if kind == "P":
        return Controller("P", {"kp": g(-3, 2)})
    if kind == "PI":
        return Controller("PI", {"kp": g(-3, 2), "ki": g(-3, 2) * float(rng.random() > 0.1)})
    if kind == "PID":
        return Controller("PID", {"kp": g(-3, 2), "ki": g(-3, 2), "kd": g(-4, 1), "tf": g(-4, -1)})
    return Controller("leadlag", {"k": g(-3, 2), "z": g(-1, 3), "p": g(-1, 3)})


@pytest.mark.parametrize("seed", range(4))
def test_batch_bandwidths_are_each_loops_own(seed):
    rng = np.random.default_rng(seed)
    for kind in ("P", "PI", "PID", "leadlag"):
        plant = _random_plant(rng)
        controllers = [_random_controller(rng, kind) for _ in range(CHUNK // 4 + 7)]
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
