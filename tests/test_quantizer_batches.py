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


def test_the_search_shared_with_a_forked_child_finds_the_same_points(monkeypatch) -> None:
    """The dense search's passes go to :func:`synth.forked.run_beside` in jobs (taken by this process and a child on
    the other core); the points found are the same as in one process."""
    import synth.gap.effects.quantization as quantization
    from synth.forked import allow_fork, run_beside
    from synth.gap.effects.quantization import QuantizationEffect, quantizer_grid

    rng = np.random.default_rng(4)
    t = np.arange(6000) * 0.01
    u = 200.0 + 40.0 * np.sin(0.31 * t) * np.sin(1.7 * t)  # every sample a distinct value: no Gram matrix
    plant = Plant.from_string("50/((s+2)*(s+5))")
    y = QuantizationEffect().apply(plant, t, u, {"step": 7.0, "offset": 1.3}) + 0.05 * rng.normal(size=t.size)
    serial = quantizer_grid(plant, t, u, y)
    offered = []

    def counted(jobs, own_work, **kwargs):
        offered.append(len(jobs))
        return run_beside(jobs, own_work, **kwargs)

    monkeypatch.setattr(quantization, "run_beside", counted)
    monkeypatch.delenv("SYNTH_JOBS", raising=False)  # conftest turns forking off for the suite
    allow_fork(True)
    try:
        shared = quantizer_grid(plant, t, u, y)
    finally:
        allow_fork(False)
    assert shared == serial
    assert offered and max(offered) >= 2  # the coarse passes in several jobs
    assert abs(serial[0]["step"] / 7.0 - 1.0) < 0.02  # and the search finds the quantizer


def test_diagnose_with_one_worker_forks_nothing(run_cli, tmp_path, monkeypatch) -> None:
    """``synth diagnose --workers 1`` runs in one process: not even the quantizer's search forks a child (it
    did before: only ``SYNTH_JOBS=1`` kept it in); with two workers the search does fork. A worker count below 1
    is bad input."""
    import os

    import synth.forked as forked
    from synth.forked import allow_fork
    from synth.gap.effects.quantization import QuantizationEffect

    t = np.arange(3000) * 0.01
    u = 200.0 + 40.0 * np.sin(0.31 * t) * np.sin(1.7 * t)
    plant = Plant.from_string("50/((s+2)*(s+5))")
    y = QuantizationEffect().apply(plant, t, u, {"step": 7.0, "offset": 1.3})
    y = y + 0.05 * np.random.default_rng(4).normal(size=t.size)
    path = tmp_path / "q.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    forks = []
    real_fork = os.fork

    def counted_fork() -> int:
        forks.append(1)
        return real_fork()

    monkeypatch.setattr(forked.os, "fork", counted_fork)
    monkeypatch.delenv("SYNTH_JOBS", raising=False)  # conftest turns forking off for the suite
    args = ["diagnose", "--plant", "50/((s+2)*(s+5))", "--data", str(path), "--time", "t", "--input", "u",
            "--output", "y", "--candidates", "quantization", "--no-report", "--quiet"]
    try:
        one = run_cli(*args, "--workers", "1")
        assert one.code == 0, one.err
        assert forks == []
        two = run_cli(*args, "--workers", "2")
        assert two.code == 0, two.err
        assert forks  # the search's passes shared with a child
        bad = run_cli(*args, "--workers", "0")
    finally:
        allow_fork(False)
    assert bad.code == 2 and "--workers" in bad.err and "at least 1" in bad.err
    assert len(bad.err.strip().splitlines()) == 1
