"""Several runs of one plant: stitched validation records and the round robin over runs."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.data.record import Signal
from synth.errors import DataError, ModelError
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.attribution.roundrobin import diagnose_runs
from synth.gap.attribution.stitch import settle_time, stitch_runs
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

G = Plant.from_string("2/(0.2*s+1)")
TRUE = G.with_delay(0.05)


def _run(u0: float, u1: float, offset: float, seed: int, t_step: float = 1.0, length: float = 4.0,
         plant: Plant = TRUE):
    """One run: at rest at ``u0``, one step to ``u1``; sensor zero shifted by ``offset``."""
    t = np.arange(0, length, 0.01)
    u = np.where(t >= t_step, u1, u0)
    y = simulate_plant(plant, t, u) + offset + 0.01 * np.random.default_rng(seed).normal(size=t.size)
    return record_from_arrays(t, u, y)


def test_stitched_runs_hold_the_next_first_input_over_the_bridge():
    a, b = _run(0.0, 1.0, 0.0, 1), _run(2.0, 3.0, 0.0, 2)
    settle = settle_time(G.with_delay(0.05))
    assert settle == pytest.approx(20 * 0.2 + 0.05)
    s = stitch_runs([a, b], settle)
    bridge = s.run == -1
    assert int(bridge.sum()) == 405 and s.runs == 2
    assert np.all(s.u[bridge] == 2.0) and np.array_equal(s.u[s.run == 1], b.u)
    assert np.array_equal(s.y[s.run == 0], a.y) and s.since_start[s.run == 1][0] == 0.0
    # the model simulated over the stitched timeline reproduces each run simulated alone (to exp(-20))
    y = simulate_plant(TRUE, s.t, s.u)
    assert np.max(np.abs(y[s.run == 1] - simulate_plant(TRUE, b.t, b.u))) < 1e-7


def test_runs_that_cannot_be_joined_are_refused():
    a = _run(0.0, 1.0, 0.0, 1)
    t = np.arange(0, 4, 0.02)
    slower = record_from_arrays(t, np.where(t >= 1, 1.0, 0.0), np.where(t >= 1.1, 2.0, 0.0))
    with pytest.raises(DataError, match=r"sampled every 0\.02 s"):
        stitch_runs([a, slower], 1.0)
    volts = record_from_arrays(a.t, a.u, a.y, Signal("u", "V"), Signal("y", "rpm"))
    with pytest.raises(DataError, match="input unit 'V'"):
        stitch_runs([a, volts], 1.0)
    with pytest.raises(ModelError, match="stable model"):
        settle_time(Plant.from_string("1/(s*(s+1))"))


def test_several_validation_runs_each_keep_their_own_offset():
    train = _run(0.0, 1.0, 0.0, 1)
    runs = [_run(1.0, 2.0, 0.3, 2), _run(2.0, 0.5, -0.2, 3)]  # other operating points and sensor zeros
    dg = diagnose_effects(G, train, runs, options=DiagnoseOptions(candidates=["delay", "lag"], n_null=19))
    assert dg.verdict["effects"] == ["delay"] and dg.split["validation_runs"] == 2
    assert dg.effects[0].parameters["delay"] == pytest.approx(0.05, abs=0.003)
    # independent: each run simulated alone, its own offset removed, the squared errors pooled
    sq = []
    for r in runs:
        e = r.y - dg.refit.predict(r.t, r.u)
        sq.append((e - e.mean()) ** 2)
    assert dg.j_refit == pytest.approx(float(np.mean(np.concatenate(sq))), rel=1e-6)
    assert dg.segments.counts.size == 20 and dg.segments.runs.tolist() == [0] * 10 + [1] * 10
    # one offset for both runs would leave (0.3 - (-0.2))^2 / 4 of error in every model
    one = diagnose_effects(G, train, runs, options=DiagnoseOptions(candidates=["delay"], n_null=5, heldout_offset="carry"))
    assert one.j_refit > dg.j_refit + 0.05


def test_round_robin_pools_the_folds_and_reports_the_delay_of_each_training_run():
    runs = [_run(0.0, 1.0, 0.0, 11), _run(1.0, 2.0, 0.2, 12), _run(2.0, 0.5, -0.1, 13)]
    d = diagnose_runs(G, runs, ["delay", "lag", "drift"], names=["a", "b", "c"], n_null=19)
    assert d.verdict["effects"] == ["delay"] and d.verdict["status"] == "effect"
    best = d.effects[0]
    assert [p["delay"] for p in best.parameters] == pytest.approx([0.05] * 3, abs=0.003)
    assert best.shrinkage_ci[0] > d.threshold
    # pooled J is the folds' held-out J weighted by their held-out samples
    n = [f.split["heldout_samples"] for f in d.folds]
    assert d.j_refit == pytest.approx(sum(f.j_refit * k for f, k in zip(d.folds, n)) / sum(n), rel=1e-9)
    assert d.threshold == max(f.threshold for f in d.folds)
    js = d.to_dict()
    assert js["folds"][1]["train"] == "b" and js["folds"][1]["heldout"] == ["a", "c"]
    assert js["effects"][0]["parameters_by_run"][2]["delay"] == pytest.approx(0.05, abs=0.003)


def test_round_robin_without_an_effect_names_none():
    runs = [_run(0.0, 1.0, 0.0, 21, plant=G), _run(1.0, 2.0, 0.2, 22, plant=G), _run(2.0, 0.5, 0.0, 23, plant=G)]
    d = diagnose_runs(G, runs, ["delay", "lag"], n_null=19)
    assert d.verdict["effects"] == [] and not any(e.accepted for e in d.effects)


def test_round_robin_needs_two_runs_and_matching_names():
    with pytest.raises(ModelError, match="at least two runs"):
        diagnose_runs(G, [_run(0.0, 1.0, 0.0, 1)], ["delay"])
    with pytest.raises(ModelError, match="1 names for 2 runs"):
        diagnose_runs(G, [_run(0.0, 1.0, 0.0, 1), _run(0.0, 1.0, 0.0, 2)], ["delay"], names=["a"])


def _csv(path, rec):
    np.savetxt(path, np.c_[rec.t, rec.u, rec.y], delimiter=",", header="t,u,y", comments="")
    return str(path)


def test_cli_round_robin_writes_the_pooled_verdict_and_each_fold(run_cli, tmp_path):
    files = [_csv(tmp_path / f"run{i}.csv", r) for i, r in
             enumerate([_run(0.0, 1.0, 0.0, 31), _run(1.0, 2.0, 0.2, 32), _run(2.0, 0.5, -0.1, 33)])]
    res = run_cli("diagnose", "--plant", "2/(0.2*s+1)", "--data", files[0], "--validate", files[1],
                  "--validate", files[2], "--round-robin", "--candidates", "delay,lag",
                  "--json", str(tmp_path / "rr.json"), "--out", str(tmp_path / "rep"))
    assert res.code == 0, res.err
    d = json.loads((tmp_path / "rr.json").read_text())
    assert d["verdict"]["effects"] == ["delay"] and d["runs"] == ["run0.csv", "run1.csv", "run2.csv"]
    assert [f["train"] for f in d["folds"]] == d["runs"] and d["runs_data"] == files
    assert d["effects"][0]["parameters_by_run"][1]["delay"] == pytest.approx(0.05, abs=0.003)
    assert res.out.splitlines()[1].startswith("verdict: delay")
    for name in ("report.html", "result.json", "fold_1.png", "fold_3.png"):
        assert (tmp_path / "rep" / name).stat().st_size > 1000, name
    assert "Each fold" in (tmp_path / "rep" / "report.html").read_text()
    # two validation runs without the round robin: one diagnosis, each run its own offset
    two = run_cli("diagnose", "--plant", "2/(0.2*s+1)", "--data", files[0], "--validate", files[1],
                  "--validate", files[2], "--candidates", "delay", "--json", "-", "--no-report")
    assert two.code == 0, two.err
    d2 = json.loads(two.out)
    assert d2["validate_data"] == files[1:] and d2["attribution"]["split"]["validation_runs"] == 2
    assert d2["verdict"]["effects"] == ["delay"] and len(d2["validate"]) == 2


def test_cli_round_robin_without_a_second_run_is_refused(run_cli, tmp_path):
    f = _csv(tmp_path / "one.csv", _run(0.0, 1.0, 0.0, 1))
    res = run_cli("diagnose", "--plant", "2/(0.2*s+1)", "--data", f, "--round-robin", "--no-report")
    assert res.code == 2 and len(res.err.strip().splitlines()) == 1
    assert "--round-robin" in res.err and "--validate" in res.err
