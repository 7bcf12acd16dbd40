"""The quantizer's dense search in batches that stay below glibc's mmap threshold (synth.gap.effects.quantization).

A batch of 512 candidate inputs of a 20,000-sample record made arrays of 160 MB, each mapped fresh and zeroed by
the kernel: a 60,000-sample diagnosis spent 16-20 s in the kernel. The batches are now a few MB; each column's
least squares must give the same bits whatever batch it is in, so the search finds the same points.
"""

from __future__ import annotations

import numpy as np

from synth.gap.effects.quantization import batch_ssr, batch_width, step_responses
from synth.plant import Plant


def test_a_columns_ssr_is_the_same_bits_in_any_batch() -> None:
    n = 6000
    t = np.arange(n) * 0.01
    plant = Plant.from_string("20*(s+3)/((s+10)*(s+2))")  # two unit numerators and the constant
    steps, consts = step_responses(plant, t)
    u = 100.0 * (np.sin(0.37 * t) + 0.3 * np.sin(2.1 * t))
    y = np.random.default_rng(1).normal(size=n)
    v = np.column_stack([np.round(u / q) * q for q in np.linspace(0.5, 50.0, 96)])
    whole = batch_ssr(v, y, steps, consts)
    for width in (1, 16, batch_width(n), 64):
        parts = np.concatenate([batch_ssr(v[:, i:i + width], y, steps, consts) for i in range(0, v.shape[1], width)])
        assert np.array_equal(parts, whole), width
    assert np.all(whole > 0.0) and np.ptp(whole) > 0.0  # distinct costs: a comparison that can fail


def test_batches_stay_within_a_quarter_million_entries() -> None:
    for n in (500, 3000, 20000, 60000, 420000):
        w = batch_width(n)
        assert 16 <= w <= 512
        assert w * n <= 250_000 or w == 16
