"""Power slower than one Welch segment is not in the share frequency: the analysis says how much that is.

A black-box test's DC motor speed record: the default 0.65 s segments resolved 16.0 of its 47.7 rpm^2 mean square,
and "90 % of disturbance power below 25.5 rad/s" (and the bandwidth floor from it) counted that third only, without
a word. Random records: white noise plus a sine slower than a segment (the noise 4-30 % of the mean square) get the
note, the resolved share at least the noise's and at most half; white noise alone does not.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.ident.psd import analyze_psd


@pytest.mark.parametrize("seed", range(4))
def test_a_sine_slower_than_a_segment_is_named_as_unresolved(seed: int) -> None:
    rng = np.random.default_rng(seed)
    dt = 0.01
    t = np.arange(0, rng.uniform(300, 900), dt)
    noise = rng.uniform(0.5, 2.0) * rng.normal(size=t.size)
    segment = 2 * np.pi / 0.08   # the default segment of such a record (w_min 0.08 rad/s), checked below
    amplitude = rng.uniform(2.0, 8.0)
    x = noise + amplitude * np.sin(2 * np.pi * t / (rng.uniform(2.5, 4.0) * segment) + rng.uniform(0, 6))
    a = analyze_psd([x], dt)
    assert a.segment_length < t[-1] / 3
    noise_share = np.var(noise) / np.var(x)   # resolved; of the slow sine only what leaks into the lowest bins
    note = next(n for n in a.notes if "of the records' mean square" in n)
    stated = float(note.split("hold ")[1].split(" %")[0])
    assert 100 * noise_share - 1 <= stated <= 50, (stated, 100 * noise_share)


def test_white_noise_has_no_unresolved_power_note() -> None:
    x = np.random.default_rng(9).normal(size=60_000)
    assert not any("of the records' mean square" in n for n in analyze_psd([x], 0.01).notes)
