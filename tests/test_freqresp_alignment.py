"""A long delay behind a sweep: the output moved back before windowing (synth.ident.output_alignment).

Session 62's black-box case: ``e^(-2 s)/(s + 1)`` behind an exponential 0.1-5 rad/s sweep of 300 s (5 s of rest
either side, 50 Hz, output noise 0.01); the band's top was 2-4 dB low and 7-47 deg off (random errors 1.4-3 deg)
and the fitted delay 10 std short. The record is simulated here with scipy (``lsim``, the input held between
samples); the truth is ``G`` times the hold's ``(1 - e^(-s dt)) / (s dt)``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.ident.spectra import frequency_response

DT, DELAY = 0.02, 2.0


def _record(seed: int):
    t = np.arange(0.0, 310.0, DT)
    inside = (t >= 5.0) & (t <= 305.0)
    u = np.where(inside, signal.chirp(t - 5.0, 0.1 / (2 * np.pi), 300.0, 5.0 / (2 * np.pi), method="logarithmic"), 0.0)
    y = signal.lsim(([1.0], [1.0, 1.0]), u, t, interp=False)[1]
    k = round(DELAY / DT)
    y = np.r_[np.zeros(k), y[:-k]] + np.random.default_rng(seed).normal(0.0, 0.01, t.size)
    return record_from_arrays(t, u, y)


def _truth(w: np.ndarray) -> np.ndarray:
    s = 1j * w
    return np.exp(-s * DELAY) / (s + 1.0) * (1.0 - np.exp(-s * DT)) / (s * DT)


@pytest.mark.parametrize("seed", [0, 1])
def test_the_top_of_a_sweep_behind_a_long_delay_is_not_biased(seed: int) -> None:
    resp = frequency_response(_record(seed))
    assert any(n.startswith("the output was moved 2") for n in resp.notes), resp.notes
    top = resp.band.contains(resp.w) & (resp.w >= resp.band.w_max / 10**0.25)  # the band's top quarter decade
    ratio = resp.H[top] / _truth(resp.w[top])
    assert top.sum() >= 8
    # before: -1.5 to -3.8 dB and +7 to +47 deg over these points
    assert np.max(np.abs(20 * np.log10(np.abs(ratio)))) < 1.0
    assert np.max(np.abs(np.degrees(np.angle(ratio)))) < 4.0


def test_a_seeded_sample_of_random_sweeps_behind_delays_comes_closer_to_the_truth() -> None:
    """Four of ``benchmarks/freqresp_alignment.py --seed 1``'s cases the rule realigns (second-order plants behind
    0.7-2.7 s, log sweeps of 240-300 s): the largest magnitude error over the band, before (the runs as they are)
    and after. Before: 2.38, 2.40, 2.25 and 2.43 dB; since the band's ends are tested on the longest window's
    input spectrum (session 68), 0.79, 2.40, 0.72 and 2.43 dB before, 0.06, 1.82, 0.24 and 0.25 dB after."""
    from benchmarks.freqresp_alignment import case, record, score
    from synth.ident import spectra

    rng = np.random.default_rng(1)
    cases = [case(rng) for _ in range(51)]
    for index in (19, 28, 38, 50):
        r = record(cases[index])
        before = spectra.frequency_response(r, align=False)
        after = frequency_response(r)
        assert any("output was moved" in n for n in after.notes)
        assert after.band.w_max <= before.band.w_max  # the move does not widen the band past the input's
        (_, worst_before), (_, worst_after) = score(before, cases[index]), score(after, cases[index])
        assert worst_before > 0.5 and worst_after < 0.8 * worst_before, (index, worst_before, worst_after)
