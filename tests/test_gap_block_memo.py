"""run_block: the memory of recent block runs gives the block's own answer, never a stale or shared one."""

import numpy as np

from synth.gap.effects import block_memo
from synth.gap.effects.block_memo import run_block
from synth.sim.blocks import Backlash, DeadZone, RateLimit


def test_remembered_runs_equal_fresh_runs_and_are_private_copies():
    rng = np.random.default_rng(4)
    u = np.cumsum(rng.normal(size=2000))
    for block in (DeadZone(0.7, 0.1), Backlash(0.5), RateLimit(3.0)):
        fresh = np.asarray(block.apply(u, 0.01), float)
        first, again = run_block(block, u, 0.01), run_block(block, u, 0.01)
        assert np.array_equal(first, fresh) and np.array_equal(again, fresh)
        again[:] = 0.0  # a caller that writes into its result does not change the next answer
        assert np.array_equal(run_block(block, u, 0.01), fresh)


def test_another_command_step_or_parameter_is_another_run():
    u = np.where(np.arange(500) >= 10, 10.0, 0.0)  # a step the rate limit turns into a ramp
    base = run_block(RateLimit(5.0), u, 0.01)
    assert not np.array_equal(run_block(RateLimit(5.0), u, 0.02), base)  # the step changes the ramp
    assert not np.array_equal(run_block(RateLimit(6.0), u, 0.01), base)
    v = u.copy()
    v[-1] += 1.0  # one sample differs
    assert run_block(DeadZone(1.0, 0.0), v, 0.01)[-1] == run_block(DeadZone(1.0, 0.0), u, 0.01)[-1] + 1.0


def test_the_memory_stays_bounded():
    u = np.arange(100.0)
    for k in range(3 * block_memo.MEMO_SIZE):
        run_block(DeadZone(0.1 * (k + 1), 0.0), u, 1.0)
    assert len(block_memo._memo) == block_memo.MEMO_SIZE
