import json
import subprocess
import sys
from pathlib import Path

import pytest


def test_check_x4_p3_exits_0_and_json(run_cli, tmp_path):
    out = tmp_path / "check.json"
    res = run_cli("check", "specs/x4_rotor.yaml", "--controller", "P(3)", "--json", str(out))
    assert res.code == 0, res.err
    assert "all requirements met" in res.out
    data = json.loads(out.read_text())
    assert data["feasible"] is True
    assert data["controller"]["type"] == "P" and data["controller"]["parameters"] == {"kp": 3.0}
    req = {r["type"]: r for r in data["requirements"]}
    assert set(req) == {"stability", "sensitivity_static", "bandwidth", "slew_rate"}
    for r in data["requirements"]:
        assert {"type", "value", "bound", "slack", "binding_frequency"} <= set(r)
    assert req["sensitivity_static"]["value"] == pytest.approx(-16.12, abs=0.02)


def test_check_failing_controller_exits_1(run_cli):
    res = run_cli("check", "specs/x4_rotor.yaml", "--controller", "P(2)")
    assert res.code == 1
    assert "NOT met: sensitivity_static" in res.out


def test_design_x4_contains_k3(run_cli, tmp_path):
    out = tmp_path / "rep"
    js = tmp_path / "design.json"
    # the X-4 spec without its nonlinear-simulation block: the design and its figures are what is checked
    # here (tests/test_report.py regenerates the committed report with the simulation and the gap case)
    spec = tmp_path / "x4_rotor.yaml"
    text = Path("specs/x4_rotor.yaml").read_text()
    spec.write_text(text[:text.index("\nsimulation:")] + "\n")
    res = run_cli("design", str(spec), "--out", str(out), "--json", str(js))
    assert res.code == 0, res.err
    data = json.loads(js.read_text())
    assert data["feasible"] and data["controller"]["type"] == "P"
    assert any(lo <= 3.0 <= hi for lo, hi in data["gain_set"])
    assert data["gain_set"][0][0] == pytest.approx(2.5686, abs=1e-4)
    for name in ["result.json", "report.html", "bode_slew_bound.png", "sensitivity.png", "step_response.png",
                 "gain_set.png", "critical_gain_vs_delay.png"]:
        assert (out / name).stat().st_size > 1000, name


def test_design_strict_reports_infeasible_with_reason(run_cli, tmp_path):
    js = tmp_path / "strict.json"
    res = run_cli("design", "specs/x4_rotor_strict.yaml", "--out", str(tmp_path / "r"), "--json", str(js))
    assert res.code == 1
    assert "INFEASIBLE" in res.out and "sensitivity is met by no kp" in res.out
    data = json.loads(js.read_text())
    assert data["feasible"] is False and data["gain_set"] == []
    ref = {r["type"]: r for r in data["reference_check"]["requirements"]}
    assert ref["sensitivity"]["details"]["met_up_to"] == pytest.approx(10.3, abs=0.1)
    assert "holds only up to 10.34 rad/s" in data["verdict"]
    comp = {r["type"]: r for r in data["compromise"]["requirements"]}
    assert comp["sensitivity"]["met"] is False and comp["sensitivity"]["binding_frequency"] == pytest.approx(30)


def test_never_overwrites_user_files(run_cli, tmp_path):
    mine = tmp_path / "notes.json"
    mine.write_text("my own notes")
    res = run_cli("check", "specs/x4_rotor.yaml", "--controller", "P(3)", "--json", str(mine))
    assert res.code == 2 and "not written by synth" in res.err
    assert mine.read_text() == "my own notes"
    out = tmp_path / "rep"
    out.mkdir()
    (out / "report.html").write_text("hand-written")
    res = run_cli("design", "specs/x4_rotor.yaml", "--out", str(out))
    assert res.code == 2 and "not written by synth" in res.err
    assert (out / "report.html").read_text() == "hand-written"
    # synth's own output may be regenerated
    res = run_cli("check", "specs/x4_rotor.yaml", "--controller", "P(3)", "--json", str(tmp_path / "a.json"))
    res = run_cli("check", "specs/x4_rotor.yaml", "--controller", "P(4)", "--json", str(tmp_path / "a.json"))
    assert res.code == 0 and json.loads((tmp_path / "a.json").read_text())["controller"]["parameters"]["kp"] == 4


@pytest.mark.parametrize("sub", [[], ["check"], ["design"]])
def test_help(run_cli, sub):
    res = run_cli(*sub, "--help")
    assert res.code == 0 and "usage: synth" in res.out


def test_console_script_whole_process():
    res = subprocess.run([sys.executable, "-m", "synth", "check", "specs/x4_rotor.yaml", "--controller", "P(3)"],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and "all requirements met" in res.stdout
