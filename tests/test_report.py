"""The committed X-4 report regenerates to the same numbers."""

import json
from pathlib import Path

import pytest

from synth.design import design
from synth.outputs import dump_json
from synth.report.design_report import report_data
from synth.spec import load_spec


def _compare(a, b, path="$"):
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), f"{path}: keys differ: {set(a) ^ set(b)}"
        for k in a:
            if k in {"generator", "solve_time"}:  # who wrote it, and wall-clock seconds
                continue
            _compare(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: lengths differ"
        for i, (x, y) in enumerate(zip(a, b)):
            _compare(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and isinstance(b, (int, float)):
        assert b == pytest.approx(a, rel=1e-6, abs=1e-9), f"{path}: {a} != {b}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


# x4_rotor_from_data, x4_rotor and x4_rotor_pi are not here: tests/test_outputs_reproducible.py and
# tests/test_forked.py compare every file their design command writes, result.json included, byte for byte with
# the committed report
@pytest.mark.parametrize("name", ["x4_rotor_strict", "x4_rotor_robust", "dcmotor_leadlag"])
def test_committed_report_regenerates(name):
    committed = Path("reports") / name / "result.json"
    assert committed.exists(), f"run `synth design specs/{name}.yaml` and commit reports/{name}"
    spec = load_spec(f"specs/{name}.yaml")
    # result.json is exactly dump_json(report_data(...)); the figures are not redrawn here (they cost
    # far more than the numbers, and write_design_report itself is exercised by its doctest and the CLI tests)
    _compare(json.loads(committed.read_text()), json.loads(dump_json(report_data(spec, design(spec)))))


def test_x4_report_shows_seed_comparisons():
    html = (Path("reports") / "x4_rotor" / "report.html").read_text()
    data = json.loads((Path("reports") / "x4_rotor" / "result.json").read_text())
    loops = data["analysis"]["loops"]
    assert loops["reference"]["closed_loop_poles"] == ["-0.4429", "-78.7"]
    published = data["analysis"]["reference"]["published_closed_loops"]
    assert [p["poles"] for p in published] == [["-0.43", "-78.54"], ["-0.0042", "-99"]]
    slew = data["analysis"]["slew_rate"][0]
    assert slew["crossing_frequency"] == pytest.approx(666.667, rel=1e-5)
    assert slew["implied_bound_over_error"] == pytest.approx(15.0, rel=1e-9)
    for text in ["eq. 14", "eq. 15", "666.7 rad/s", "reports 5 rad/s", "do not reconcile", "B/De = 15 1/s"]:
        assert text in html, text
    delays = {round(r["delay"], 3): r["critical_gain"] for r in data["analysis"]["delay_table"]}
    assert delays[0.015] == pytest.approx(4.83, abs=0.01) and delays[0.02] == pytest.approx(3.69, abs=0.01)
