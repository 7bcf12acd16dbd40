"""The bandwidth is the first fall of |T| below its -3 dB level, also inside a dip narrower than the grid.

The reference is a brute-force scan of |T| on 400,000 log-spaced frequencies, written here independently of
synth.freqgrid; the batch form (screens, gain sets, feasibility maps) must agree with it too."""

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import BANDWIDTH_LEVEL, Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant
from synth.requirements import Bandwidth


def brute_force_bandwidth(loop: Loop, w_lo: float, w_hi: float) -> float:
    w = np.geomspace(w_lo, w_hi, 400_000)
    t = np.abs(loop.T(w))
    below = np.flatnonzero(t < abs(loop.T0()) * BANDWIDTH_LEVEL)
    return float(w[below[0]]) if below.size else np.inf


def test_a_dip_between_grid_points_is_the_bandwidth():
    # seed 5 problem 20 of benchmarks/design_verification.py: a 4.27 s delay; |T| dips below the level on
    # [0.2699, 0.2744] rad/s, 1.6 % wide, between the points of the 80-per-decade grid; it comes back above
    # the level and falls for good at 0.939 rad/s, which the bandwidth used to be
    G = Plant.from_string("0.285469*(s+1.77972)*(s+3.47695)/((s+2.44803)*(s+0.62853)*(s+0.45201))", delay=4.26912)
    loop = Loop(G, Controller("PID", {"kp": 0.362935, "ki": 0.0876981, "kd": 1.40215, "tf": 0.146668}))
    truth = brute_force_bandwidth(loop, 0.01, 3.0)
    assert truth == pytest.approx(0.26994, rel=1e-4)
    assert loop.bandwidth() == pytest.approx(truth, rel=1e-4)
    req = Bandwidth(type="bandwidth", min=0.5)
    assert req.slack(loop) < 0  # a floor of 0.5 rad/s is not met
    batch = LoopBatch(G, [loop.controller])
    assert req.batch_slack(batch)[0] == pytest.approx(np.log(truth / 0.5), abs=1e-4)


def test_a_notch_narrower_than_the_grid_in_every_row_of_a_batch():
    # |f| = notch of width ~0.3 % at w0, times a first-order roll-off at 50 rad/s; 10 points per decade
    from synth.freqgrid import batch_first_crossing, first_fall, log_grid

    w0 = np.array([[2.05], [3.0], [5.0]])

    def f(w):
        return np.abs((w0**2 - w**2 + 1e-4j * w) / (w0**2 - w**2 + 0.02j * w)) / np.abs(1 + 1j * w / 50)

    grid = log_grid(0.01, 1000.0, 10)
    got, below = batch_first_crossing(f, np.full(3, 0.5), np.tile(grid, (3, 1)))
    for i in range(3):
        w = np.geomspace(0.5 * w0[i, 0], 2 * w0[i, 0], 2_000_001)
        row = np.abs((w0[i, 0] ** 2 - w**2 + 1e-4j * w) / (w0[i, 0] ** 2 - w**2 + 0.02j * w)) / np.abs(1 + 1j * w / 50)
        truth = float(w[np.argmax(row < 0.5)])
        assert got[i] == pytest.approx(truth, rel=1e-5)
        assert first_fall(lambda x, i=i: f(np.broadcast_to(x, (3, *np.shape(x))))[i], 0.5, grid) == pytest.approx(
            truth, rel=1e-5)
    assert not below.any()
