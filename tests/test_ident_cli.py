"""synth identify: JSON contract, figures, and one-line errors with exit code 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.ident.simulate import simulate_plant
from synth.plant import Plant


@pytest.fixture
def step_csv(tmp_path):
    t = np.arange(0, 3, 0.01)
    u = np.where(t >= 0.5, 5.0, 1.0)
    y = 10 + simulate_plant(Plant.from_string("3/(0.4*s+1)", delay=0.03), t, u)
    path = tmp_path / "step.csv"
    lines = ["t,volt,speed"] + [f"{a:.4f},{b:.6g},{c:.10g}" for a, b, c in zip(t, u, y)]
    path.write_text("\n".join(lines) + "\n")
    return path


def _args(path, out, *extra):
    return ["identify", "--data", str(path), "--time", "t", "--input", "volt", "--output", "speed",
            "--structure", "K/(T*s+1)", "--delay", "fit", "--out", str(out), *extra]


def test_json_contract_and_files(run_cli, step_csv, tmp_path):
    out = tmp_path / "rep"
    res = run_cli(*_args(step_csv, out, "--json", str(tmp_path / "r.json")))
    assert res.code == 0, res.err
    data = json.loads((tmp_path / "r.json").read_text())
    assert {"parameters", "std", "fit_percent", "tf", "ci95", "covariance"} <= set(data)
    assert set(data["parameters"]) == {"K", "T", "delay"}
    assert data["parameters"]["K"] == pytest.approx(3.0, rel=1e-5)
    assert data["parameters"]["delay"] == pytest.approx(0.03, abs=1e-6)
    assert {p.name for p in out.iterdir()} >= {"identify.json", "fit.png", "train.png"}
    assert "K" in res.out and "fit 100.00 %" in res.out


def test_does_not_overwrite_user_files(run_cli, step_csv, tmp_path):
    out = tmp_path / "rep"
    out.mkdir()
    (out / "fit.png").write_text("mine")
    res = run_cli(*_args(step_csv, out, "--no-figures"))
    assert res.code == 0  # figures skipped: nothing to clash with
    res = run_cli(*_args(step_csv, out))
    assert res.code == 2 and "not overwriting" in res.err
    assert (out / "fit.png").read_text() == "mine"


def _csv(tmp_path, header, rows):
    path = tmp_path / "bad.csv"
    path.write_text(header + "\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("case, message", [
    ("missing", "output column 'speed' not found"),
    ("nan", "NaN or inf"),
    ("constant", "input is constant"),
    ("formula", "--structure"),
    ("time", "time is not strictly increasing at sample 20"),
    ("length", "columns have different lengths"),
    ("flat", "the output never responds"),
])
def test_bad_input_exit_2_one_line(run_cli, tmp_path, case, message):
    rows = [f"{i * 0.01:.2f},{1.0 if i > 5 else 0.0},{np.tanh(i / 10):.6f}" for i in range(50)]
    header = "t,volt,speed"
    structure = "K/(T*s+1)"
    if case == "missing":
        header = "t,volt,sped"
    if case == "nan":
        rows[10] = "0.10,1.0,nan"
    if case == "constant":
        rows = [f"{i * 0.01:.2f},1.0,{np.tanh(i / 10):.6f}" for i in range(50)]
    if case == "formula":
        structure = "K/(T*s+1"
    if case == "time":
        rows[20] = "0.18" + rows[20][4:]
    if case == "length":
        rows[30] = rows[30].rsplit(",", 1)[0]
    if case == "flat":
        rows = [f"{i * 0.01:.2f},{1.0 if i > 5 else 0.0},0.5" for i in range(50)]
    path = _csv(tmp_path, header, rows)
    res = run_cli("identify", "--data", str(path), "--time", "t", "--input", "volt", "--output", "speed",
                  "--structure", structure, "--out", str(tmp_path / "o"))
    assert res.code == 2
    assert message in res.err
    assert res.err.strip().count("\n") == 0 and "Traceback" not in res.err


def test_missing_structure(run_cli, step_csv):
    res = run_cli("identify", "--data", str(step_csv))
    assert res.code == 2 and "--structure" in res.err
