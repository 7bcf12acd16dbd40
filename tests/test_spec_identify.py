"""Specs whose plant is identified from a record: the fit, the uncertainty plants, and errors."""

from __future__ import annotations

import numpy as np
import pytest

from synth.check import check
from synth.errors import SpecError
from synth.ident.simulate import simulate_plant
from synth.plant import Plant
from synth.spec import load_spec

TRUE = Plant.from_string("4/((s+2)*(s+5))", delay=0.03)
SPEC = """name: from_data
plant:
  identify:
    data: {data}
    time: t
    input: u
    output: y
    structure: "k/((s+a)*(s+b))"
    delay: fit
    in_loop_delay: {in_loop}
  input: {{name: voltage, unit: V}}
  output: {{name: speed, unit: rad/s}}
controller: {{type: P, bounds: {{kp: [0, 50]}}}}
requirements:
  - {{type: margins, gain_margin_db: 6, phase_margin_deg: 45}}
"""


@pytest.fixture
def record_csv(tmp_path):
    """A step train through TRUE with a little noise, as a CSV next to the spec."""
    t = np.arange(0, 24, 0.002)
    u = 1.0 + np.where((t % 4.0) >= 2.0, 1.0, 0.0)
    y = simulate_plant(TRUE, t, u) + 0.002 * np.random.default_rng(1).standard_normal(t.size)
    path = tmp_path / "run.csv"
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="t,u,y", comments="")
    return path


def _spec(tmp_path, data="run.csv", in_loop="true"):
    path = tmp_path / "spec.yaml"
    path.write_text(SPEC.format(data=data, in_loop=in_loop))
    return path


def test_identified_plant_and_uncertainty_plants(tmp_path, record_csv):
    spec = load_spec(_spec(tmp_path))  # data is found relative to the spec file, not the working folder
    plants = spec.plants()
    nominal = plants[0]
    w = np.array([0.5, 2.0, 8.0])
    assert np.allclose(nominal.freqresp(w), TRUE.freqresp(w), rtol=0, atol=2e-3)  # |G| is 0.05-0.4 here
    assert nominal.delay == pytest.approx(0.03, abs=5e-4)
    assert nominal.input.unit == "V" and nominal.output.unit == "rad/s"
    # k, a, b and the delay fitted: both ends of 4 ellipsoid axes, each a small move from the nominal plant
    labels = [p.label for p in plants[1:]]
    assert len(labels) == 8 and all(lbl.startswith("identified, axis") for lbl in labels)
    spread = [abs(p.dc_gain() / nominal.dc_gain() - 1) for p in plants[1:]]
    assert 0 < max(spread) < 0.01
    # the requirements are checked on every plant: the worst case counts
    result = check(spec, "P(2)")
    assert set(result.per_plant) == {p.label for p in plants}


def test_delay_can_be_kept_out_of_the_loop(tmp_path, record_csv):
    inside = load_spec(_spec(tmp_path)).nominal_plant()
    outside = load_spec(_spec(tmp_path, in_loop="false")).nominal_plant()
    assert inside.delay > 0.02 and outside.delay == 0.0
    assert np.allclose(inside.num, outside.num) and np.allclose(inside.den, outside.den)


def test_missing_data_file_names_the_key(tmp_path):
    with pytest.raises(SpecError, match=r"spec.yaml:4: plant.identify.data: data file .*nowhere.csv.* not found"):
        load_spec(_spec(tmp_path, data="nowhere.csv"))


def test_unknown_builtin_record(tmp_path):
    with pytest.raises(SpecError, match=r"plant\.identify\.data: unknown builtin record 'x5'"):
        load_spec(_spec(tmp_path, data="builtin:x5"))


@pytest.mark.parametrize("plant, message", [
    ("{tf: '1/(s+1)', identify: {data: a.csv, structure: 'k/(s+p)'}}", "give exactly one of 'tf'"),
    ("{label: x}", "give exactly one of 'tf'"),
    ("{identify: {data: a.csv, structure: 'k/(s+p'}}", "plant.identify.structure"),
    ("{identify: {data: a.csv, structure: 'k/(s+p)', delay: soon}}", "delay must be 'fit' or a number"),
    ("{identify: {data: a.csv, structure: 'k/(s+p)', confidence: 1.5}}", "plant.identify.confidence"),
    ("{identify: {data: a.csv, structure: 'k/(s+p)', colums: [t]}}", "unknown key 'colums'"),
])
def test_bad_identify_blocks(tmp_path, plant, message):
    path = tmp_path / "bad.yaml"
    path.write_text(f"name: bad\nplant: {plant}\ncontroller: {{type: P}}\nrequirements: [{{type: bandwidth, min: 1}}]\n")
    with pytest.raises(SpecError, match=message):
        load_spec(path)


def test_cli_design_from_data_and_bad_column(tmp_path, record_csv, run_cli):
    out = tmp_path / "report"
    res = run_cli("design", str(_spec(tmp_path)), "--out", str(out), "--json", str(tmp_path / "r.json"))
    assert res.code == 0, res.err
    import json

    data = json.loads((out / "result.json").read_text())
    assert data["identification"]["parameters"]["k"] == pytest.approx(4.0, rel=0.01)
    assert "Plant identified from data" in (out / "report.html").read_text()
    bad = tmp_path / "bad.yaml"
    bad.write_text(_spec(tmp_path).read_text().replace("output: y", "output: speed"))
    res = run_cli("check", str(bad), "-c", "P(1)")
    assert res.code == 2 and "output column 'speed' not found" in res.err and "Traceback" not in res.err
