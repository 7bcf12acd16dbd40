"""Uneven time stamps: the fit's reported standard deviation is honest (issue 16, item 4).

The record: ``3/(0.3 s + 1)`` simulated exactly on stamps jittered 4-6 ms (the command held from each stamp to the
next, as a logger's zero-order hold), a random binary command changing only at stamps, output noise std 0.01. Over
12 noise-and-stamp seeds the parameters' scatter must match the standard deviation synth reports. Resampling that
moved each edge onto the grid (the command's value at each interval's middle) left a scatter 10 times the reported
one; the interval's mean command keeps the edges where they were.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.ident import identify
from tests.first_order_reference import first_order_held

TRUTH = {"K": 3.0, "T": 0.3}


def _jittered_record(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng, levels = np.random.default_rng(seed), np.random.default_rng(seed + 1000)
    t = np.cumsum(rng.uniform(0.004, 0.006, 6000))
    t -= t[0]
    u = np.zeros(t.size)
    k, value = int(np.searchsorted(t, 0.5)), 0.0  # at rest for 0.5 s, then a level every 0.1-0.4 s
    while k < t.size:
        end = int(np.searchsorted(t, t[k] + 0.1 * (1 + levels.integers(0, 4))))
        value = 1.0 if value <= 0 else -1.0
        u[k:end] = value
        k = max(end, k + 1)
    y = first_order_held(t, u, TRUTH["K"], TRUTH["T"])  # exact: each stamp's command held to the next stamp
    return t, u, y + 0.01 * rng.standard_normal(t.size)


@pytest.mark.slow
def test_reported_std_matches_the_scatter_over_jittered_records():
    results = [identify(_jittered_record(seed), "K/(T*s+1)", compare_directions=False) for seed in range(12)]
    assert all(r.average is not None and r.average.mode == "edge" for r in results)  # still found as a step train
    fits = [r.fit for r in results]
    for name, truth in TRUTH.items():
        values = np.array([f.parameters[name] for f in fits])
        reported = float(np.mean([f.std[name] for f in fits]))
        scatter = float(np.std(values, ddof=1))
        # 12 draws: the scatter's own relative error is about 20 %; the old rule gave 9.5-10x
        assert 0.6 < scatter / reported < 1.7, (name, scatter, reported)
        assert abs(values.mean() - truth) < 3.0 * scatter / np.sqrt(values.size), (name, values.mean())
        assert scatter < 0.001 * truth  # the old rule's scatter: 0.46 % (K) and 0.58 % (T)


@pytest.mark.slow
def test_an_edge_average_fit_that_fails_falls_back_to_the_whole_record():
    """Case 10 of benchmarks/uneven_stamps.py, noise seed 18 (found by that black-box benchmark): ``k/((s+p1)(s+p2))``
    with a fitted delay on bursty stamps. The 0.7 s edge average was fitted by k = -2.16e5, poles at 669 and 9,511
    rad/s (the grid's Nyquist frequency: 321 rad/s), a delay of 107 ms, and returned as the result with a reported
    std of 0.17 on p2. That fit is now a failure of the average, and the whole record is fitted instead. (Since
    SRIVC keeps its best iterate, session 48, the average's fit ends on an unstable model, a failure too.)"""
    bench = pytest.importorskip("benchmarks.uneven_stamps")
    case = bench.make_case(10)
    y = bench.clean_output(case) + np.random.default_rng([10, 7919, 18]).normal(0, case.noise_std, case.t.size)
    res = identify((case.t, case.u, y), case.structure, delay="fit", compare_directions=False)
    assert res.whole_record_note.startswith("the fit of the edge average failed")
    assert "beyond the record's Nyquist frequency" in res.whole_record_note or "is unstable" in res.whole_record_note
    assert res.fit.t.size == res.record.n  # the whole record
    for name, truth in {**case.truth, "delay": case.delay}.items():
        assert abs(res.fit.parameters[name] - truth) < 4 * res.fit.std[name], (name, res.fit.parameters[name], truth)
