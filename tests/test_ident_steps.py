"""Step finding and averaging: indices, SNR definition against a known noise level, periodic folding."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.errors import DataError
from synth.ident.steps import average_steps, find_steps
from synth.ident.x4_record import NOISE_STD, x4_step_train


def test_x4_steps_found_at_the_generated_edges():
    r = x4_step_train(periods=5)
    s = find_steps(r)
    assert s.index.tolist() == [3000, 6000, 9000, 12000, 15000, 18000, 21000, 24000, 27000]
    assert s.direction.tolist() == [1, -1] * 4 + [1]
    assert (s.low, s.high) == (175.0, 225.0)


def test_noisy_input_does_not_make_extra_steps():
    t = np.arange(1000) * 0.01
    u = np.where((t >= 2) & (t < 6), 1.0, 0.0) + 0.1 * np.random.default_rng(1).standard_normal(t.size)
    s = find_steps(record_from_arrays(t, u, t))
    assert s.count == 2 and s.direction.tolist() == [1, -1]


def test_cycle_average_noise_levels_match_the_generator():
    avg = average_steps(x4_step_train())
    assert avg.mode == "cycle" and avg.count == 69 and avg.dropped == 1
    assert avg.noise_std_before == pytest.approx(NOISE_STD, rel=0.02)
    # measured by split halves, not assumed: white noise gives sigma / sqrt(N)
    assert avg.noise_std_after == pytest.approx(NOISE_STD / np.sqrt(69), rel=0.1)
    assert avg.snr_after_db - avg.snr_before_db == pytest.approx(10 * np.log10(69), abs=1.0)
    # the noise-free periodic response: averaged data differs from it only by averaged noise
    clean = average_steps(x4_step_train(noise_std=0.0))
    assert np.std(avg.y - clean.y) == pytest.approx(NOISE_STD / np.sqrt(69), rel=0.1)


def test_edge_mode_sign_normalizes_down_steps():
    t = np.arange(4000) * 0.001
    u = np.where((t >= 1) & (t < 2) | (t >= 3), 2.0, 0.0)
    y = 5.0 + 1.5 * u  # instant response of gain 1.5: every window is a +3 step once down steps are flipped
    r = record_from_arrays(t, u, y + 1e-9 * np.sin(t))
    avg = average_steps(r, mode="edge")
    assert avg.count == 3 and (avg.up, avg.down) == (2, 1)
    assert avg.step_size == pytest.approx(3.0, rel=1e-6)
    assert np.allclose(avg.y[avg.up_index:], 3.0, atol=1e-6) and np.allclose(avg.y[:avg.up_index], 0.0, atol=1e-6)
    assert np.allclose(avg.u[avg.up_index:], 2.0)


def test_cycle_mode_on_a_non_periodic_train_is_refused():
    t = np.arange(3000) * 0.01
    u = np.where((t >= 1) & (t < 2) | (t >= 5) & (t < 6) | (t >= 12) & (t < 13), 1.0, 0.0)
    with pytest.raises(DataError, match="not a periodic square wave"):
        average_steps(record_from_arrays(t, u, t), mode="cycle")


def test_input_without_step():
    t = np.arange(100) * 0.01
    u = np.r_[np.zeros(99), 1.0]
    with pytest.raises(DataError):
        average_steps(record_from_arrays(t, u, t), mode="cycle")


def test_a_last_step_near_the_records_end_is_left_out_not_every_window_cut():
    """Steps 40-80 samples apart, the record ending 5 samples after the last one: the windows are the 40 samples
    between the closest two steps and the last step is dropped (the old rule cut every window to the 5 samples left
    after it and refused the record: 'steps are only 5 samples apart')."""
    rng = np.random.default_rng(3)
    edges = np.cumsum(rng.integers(40, 81, 12)) + 20
    n = int(edges[-1]) + 5
    u = np.zeros(n)
    for k, e in enumerate(edges):
        u[e:] = 1.0 if k % 2 == 0 else 0.0
    t = np.arange(n) * 0.01
    y = np.convolve(u, 1 - np.exp(-np.arange(200) * 0.01 / 0.05))[:n] * 0.01 / 0.05 * (1 - np.exp(-0.01 / 0.05))
    avg = average_steps(record_from_arrays(t, u, y), mode="edge")
    assert avg.dropped == 1 and avg.count == edges.size - 1
    assert round(avg.t[-1] / 0.01) + 1 == int(np.min(np.diff(edges)))
    assert avg.u[:-1].max() == pytest.approx(1.0) and avg.u[avg.t >= 0].min() == pytest.approx(1.0)


def test_a_step_whose_edge_falls_inside_a_sample_interval_starts_at_that_sample():
    """A resampled record holds the interval's mean command where an edge falls inside it (0.2, 0.6, 0.5 here):
    the step is at that sample, so its window's samples before the step are all at the old level."""
    t = np.arange(10) * 0.1
    steps = find_steps(record_from_arrays(t, [0, 0.2, 1, 1, 1, 0.6, 0, 0.5, 1, 1], t ** 2))
    assert steps.index.tolist() == [1, 5, 7] and steps.direction.tolist() == [1, -1, 1]
    plain = find_steps(record_from_arrays(t, [0, 0, 1, 1, 1, 0, 0, 1, 1, 1], t ** 2))
    assert plain.index.tolist() == [2, 5, 7]
