"""The delayed loop a delay's length at a time against the same loop stepped one sample at a time (the compiled
loop, a second algorithm: another order of operations, no block maps, no convolutions), on random discrete
plants and controllers: static, biproper, open-loop unstable; delays below and above the FFT threshold; runs
that end inside a block. The continuous-time accuracy is checked against solve_ivp in
tests/test_delayed_step_against_method_of_steps.py."""

import numpy as np
import pytest

from synth.delayed_blocks import FFT_FROM, delayed_loop_augmented, delayed_loop_in_blocks
from synth.delayed_step import delayed_loop
from synth.statespace import STEP_BLOCK, step_from_rest, tf_to_ss, zoh
from synth.timeresp import AUGMENTED_UP_TO


def _discrete(num: np.ndarray, den: np.ndarray, dt: float):
    num, den = np.atleast_1d(num), np.atleast_1d(den)
    if len(den) == 1:
        return np.zeros((0, 0)), np.zeros(0), np.zeros(0), float(num[-1] / den[0])
    A, B, C, D = tf_to_ss(num, den)
    Ad, Bd = zoh(A, B, dt)
    return Ad, Bd[:, 0], np.asarray(C, float).ravel(), float(np.ravel(D)[0])


def _case(seed: int, delays: tuple[int, ...] = (4, 7, 60, FFT_FROM - 1, FFT_FROM, 1500)):
    rng = np.random.default_rng(seed)
    n_plant, n_ctrl = int(rng.integers(0, 4)), int(rng.integers(0, 3))
    plant_poles = -rng.uniform(0.2, 20.0, n_plant)
    if n_plant and seed % 4 == 0:
        plant_poles[0] = rng.uniform(0.1, 1.0)  # open-loop unstable
    plant_num = np.poly(-rng.uniform(0.1, 30.0, int(rng.integers(0, n_plant + 1)))) * rng.uniform(0.2, 3.0)
    ctrl_num = np.poly(-rng.uniform(0.1, 30.0, int(rng.integers(0, n_ctrl + 1)))) * rng.uniform(0.05, 1.0)
    ctrl_den = np.poly(np.r_[0.0, -rng.uniform(1.0, 50.0, n_ctrl - 1)] if n_ctrl else [])
    dt = float(rng.uniform(1e-4, 2e-3))
    m = int(rng.choice(delays))
    steps = int(rng.integers(m // 2, 12_000))
    return (*_discrete(ctrl_num, ctrl_den, dt), *_discrete(plant_num, np.poly(plant_poles), dt), m, steps)


@pytest.mark.parametrize("seed", range(24))
def test_blocks_agree_with_the_loop_stepped_sample_by_sample(seed: int):
    args = _case(seed)
    with np.errstate(over="ignore", invalid="ignore"):
        stepped = np.asarray(delayed_loop(*args))
        blocks = delayed_loop_in_blocks(*args)
    assert blocks.shape == stepped.shape == (args[-1] + 1,)
    m = args[-2]
    assert np.all(blocks[:m] == stepped[:m]) and np.all(blocks[: min(m, blocks.size)] == 0.0)  # nothing before the delay
    finite = np.isfinite(stepped) & (np.abs(stepped) < 1e8)
    scale = max(1.0, float(np.max(np.abs(stepped[finite]))))
    assert np.max(np.abs(blocks[finite] - stepped[finite])) <= 1e-9 * scale, seed
    # where the stepped loop diverged to huge or non-finite values the blocks diverge too
    assert np.all(~np.isfinite(blocks[~finite]) | (np.abs(blocks[~finite]) >= 1e7))


def test_a_static_loop_settles_at_its_closed_form():
    # a static gain g = 0.5 behind 10 steps of delay: y is constant over each block of 10 and
    # y_k = g (1 - y_{k-1}), so y_k = (1 - (-g)^k) / 3, settling at g / (1 + g) = 1/3
    y = delayed_loop_in_blocks(np.zeros((0, 0)), np.zeros(0), np.zeros(0), 0.5, np.zeros((0, 0)), np.zeros(0),
                               np.zeros(0), 1.0, 10, 2000)
    blocks = y[: 2000 // 10 * 10].reshape(-1, 10)
    assert np.all(blocks == blocks[:, :1])  # constant within each block
    expected = np.array([(1 - (-0.5) ** k) / 3 for k in range(blocks.shape[0])])
    assert np.allclose(blocks[:, 0], expected, atol=1e-15)


@pytest.mark.parametrize("seed", range(24))
def test_the_augmented_loop_agrees_with_the_loop_stepped_sample_by_sample(seed: int):
    """Short delays (1 step up to the longest that runs augmented), runs shorter and longer than one block."""
    args = _case(seed, (1, 2, 3, 5, STEP_BLOCK - 1, STEP_BLOCK + 1, AUGMENTED_UP_TO))
    with np.errstate(over="ignore", invalid="ignore"):
        stepped = np.asarray(delayed_loop(*args))
        augmented = delayed_loop_augmented(*args)
    assert augmented.shape == stepped.shape == (args[-1] + 1,)
    assert np.all(augmented[: args[-2]] == 0.0)  # nothing before the delay
    finite = np.isfinite(stepped) & (np.abs(stepped) < 1e8)
    scale = max(1.0, float(np.max(np.abs(stepped[finite]))))
    assert np.max(np.abs(augmented[finite] - stepped[finite])) <= 1e-9 * scale, seed
    assert np.all(~np.isfinite(augmented[~finite]) | (np.abs(augmented[~finite]) >= 1e7))


@pytest.mark.parametrize("size", [1, 2, STEP_BLOCK, STEP_BLOCK + 1, 3 * STEP_BLOCK + 7])
def test_step_from_rest_is_the_recursion(size: int):
    rng = np.random.default_rng(size)
    F = rng.normal(size=(4, 4))
    F *= 0.95 / max(abs(np.linalg.eigvals(F)))  # stable
    g, h, d = rng.normal(size=4), rng.normal(size=4), float(rng.normal())
    z, expected = np.zeros(4), []
    for _ in range(size):
        expected.append(h @ z + d)
        z = F @ z + g
    assert np.allclose(step_from_rest(F, g, h, d, size), expected, rtol=1e-12, atol=1e-12)
