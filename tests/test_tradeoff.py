"""Trade-off sweeps: values, warm starts, Pareto front, report files, local pool and Dask."""

import csv
import io
import json

import pytest

from synth.errors import SpecError
from synth.spec import load_spec, parse_spec
from synth.synthesis.tradeoff import Sweep, set_value, tradeoff

X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"
SLEW = "requirements.slew_rate.rate_limit"


def _spec():
    return parse_spec(f"""
name: sweep
plant: {{tf: "{X4}"}}
controller: {{type: P, bounds: {{kp: [0, 20]}}}}
requirements:
  - {{type: sensitivity_static, max_db: -15, plant_gain: 1.8}}
  - {{type: slew_rate, rate_limit: 10000, max_error: 5, band: [0.1, 100]}}
objective: {{maximize: bandwidth}}
""")


def test_sweep_parsing_and_paths():
    assert Sweep.parse("a.b=1:3:3").values == [1.0, 2.0, 3.0]
    assert Sweep.parse("a=0.5,2").values == [0.5, 2.0]
    for bad in ["nope", "a=1:2", "a=x,y", "a=1:2:0"]:
        with pytest.raises(SpecError):
            Sweep.parse(bad)
    data = {"requirements": [{"type": "bandwidth", "min": 1}, {"type": "margins", "label": "robust"}]}
    assert set_value(data, "requirements.robust.phase_margin_deg", 45.0)["requirements"][1]["phase_margin_deg"] == 45
    assert set_value(data, "requirements.0.min", 5.0)["requirements"][0]["min"] == 5.0
    with pytest.raises(SpecError, match="no requirements with label or type 'sensitivity'"):
        set_value(data, "requirements.sensitivity.max_db", 1.0)


def test_slew_sweep_follows_closed_form_and_marks_the_front():
    # P control: the slew bound 5 K w <= B at w = 100 caps K at B/500, the design maximizes bandwidth
    result = tradeoff(_spec(), [Sweep.parse(f"{SLEW}=2000:10000:5")], workers=1)
    for p in result.points:
        assert p.feasible
        assert p.controller["kp"] == pytest.approx(min(20.0, p.values[SLEW] / 500), rel=1e-5)
        assert "slew_rate" in p.binding
    values = [p.objective for p in result.points]
    assert values == sorted(values)  # a looser slew limit never hurts
    # the strictest demand that still reaches each objective: every point is on the front here
    assert all(p.pareto for p in result.points)


def test_infeasible_points_name_the_conflict():
    result = tradeoff(_spec(), [Sweep.parse(f"{SLEW}=500:2000:2")], workers=1)
    low = result.points[0]  # K <= 1 but -15 dB needs K >= 2.57
    assert not low.feasible and set(low.binding) >= {"sensitivity_static", "slew_rate"}
    assert result.points[1].feasible


def test_two_sweeps_local_pool_and_report(tmp_path, run_cli):
    spec = tmp_path / "s.yaml"
    spec.write_text(_spec().model_dump_json())
    res = run_cli("tradeoff", str(spec), "--sweep", f"{SLEW}=2000:10000:3", "--sweep",
                  "requirements.sensitivity_static.max_db=-20:-10:2", "--out", str(tmp_path / "r"), "--workers", "2",
                  "--quiet")
    assert res.code == 0, res.err
    rows = list(csv.DictReader(io.StringIO((tmp_path / "r" / "tradeoff.csv").read_text())))
    assert len(rows) == 6
    for name in ["tradeoff.json", "tradeoff.html", "tradeoff.png"]:
        assert (tmp_path / "r" / name).stat().st_size > 500
    data = json.loads((tmp_path / "r" / "tradeoff.json").read_text())
    assert data["scheduler"].startswith("local process pool")
    # -20 dB needs K >= 5.0; B = 2000 caps K at 4: infeasible there, feasible everywhere else
    bad = [r for r in rows if r["feasible"] == "False"]
    assert len(bad) == 1 and float(bad[0][SLEW]) == 2000 and float(bad[0]["requirements.sensitivity_static.max_db"]) == -20


def test_dask_local_cluster_gives_the_same_points():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            on_dask = tradeoff(_spec(), [Sweep.parse(f"{SLEW}=2000:10000:4")], scheduler=client)
    local = tradeoff(_spec(), [Sweep.parse(f"{SLEW}=2000:10000:4")], workers=1)
    assert on_dask.scheduler.startswith("dask cluster")
    assert [p.controller for p in on_dask.points] == [p.controller for p in local.points]


def test_bad_scheduler_address_is_a_clean_error(run_cli, tmp_path, monkeypatch):
    monkeypatch.setenv("SYNTH_DASK_CONNECT_TIMEOUT", "1s")  # the refusal, not the default 10 s wait, is tested
    res = run_cli("tradeoff", "specs/x4_rotor.yaml", "--sweep", "requirements.bandwidth.min=60:70:2",
                  "--scheduler", "tcp://127.0.0.1:1", "--out", str(tmp_path / "r"), "--quiet")
    assert res.code == 2 and "cannot reach the Dask scheduler" in res.err


def test_x4_spec_loads_for_sweeps():
    assert load_spec("specs/x4_rotor.yaml").requirements[1].type == "bandwidth"


@pytest.mark.parametrize("sweep, message", [
    ("plant.delay=-0.1,0.1", "--sweep plant.delay=-0.1: plant.delay: must be >= 0.0, got -0.1"),
    ("controller.bounds.kp.1=-1,2", "--sweep controller.bounds.kp.1=-1: controller.bounds: kp: lower bound 0 is above"),
])
def test_a_swept_value_the_spec_forbids_is_bad_input(run_cli, tmp_path, sweep, message):
    """Found by a black-box test: such a point was a row "not designed: 1 validation error for Spec" (no field, no
    reason), exit 0. Now the spec's own message, exit 2, before any design and without writing anything."""
    res = run_cli("tradeoff", "specs/x4_rotor.yaml", "--sweep", sweep, "--out", str(tmp_path / "r"), "--quiet")
    assert res.code == 2 and res.err.strip().splitlines() == [res.err.strip()] and message in res.err, res.err
    assert not (tmp_path / "r").exists()


def test_the_json_file_is_the_same_bytes_on_a_rerun(run_cli, tmp_path):
    """--json FILE held the run's wall-clock seconds: two runs of the same command differed."""
    files = []
    for k in range(2):
        res = run_cli("tradeoff", "specs/x4_rotor.yaml", "--sweep", "requirements.bandwidth.min=60:70:2",
                      "--out", str(tmp_path / f"r{k}"), "--quiet", "--workers", "1", "--json", str(tmp_path / f"{k}.json"))
        assert res.code == 0, res.err
        files.append((tmp_path / f"{k}.json").read_bytes())
    assert files[0] == files[1] and b'"seconds"' not in files[0]
    assert files[0] == (tmp_path / "r0" / "tradeoff.json").read_bytes()


def test_a_bad_sweep_is_one_line_without_a_progress_bar(run_cli, tmp_path):
    """The bar was drawn before the sweep was validated: its empty line came with the error."""
    res = run_cli("tradeoff", "specs/x4_rotor.yaml", "--sweep", "controller.bounds.kp.0=0:30:3",
                  "--out", str(tmp_path / "r"), "--workers", "1")
    assert res.code == 2
    assert res.err.strip().splitlines() == [
        "synth tradeoff: error: --sweep controller.bounds.kp.0=30: controller.bounds: kp: lower bound 30 is above "
        "upper bound 20"]
