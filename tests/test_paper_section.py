"""The X-4 paper's section of the design report (issue 19, items 1-3): numbers, HTML, spec key."""

from __future__ import annotations

import json

import pytest
import yaml

from synth.design import design
from synth.errors import SpecError
from synth.report.design_report import write_design_report
from synth.report.paper_section import x4_paper_section
from synth.spec import parse_spec


@pytest.fixture(scope="module")
def section():
    return x4_paper_section()


def _spec(paper="x4"):
    data = yaml.safe_load(open("specs/x4_rotor.yaml"))
    data.pop("simulation")  # the nonlinear loop is not this section's business (and slow)
    data["analysis"] = {**data["analysis"], "paper": paper}
    if paper is None:
        data["analysis"].pop("paper")
    return parse_spec(data)


def test_disturbance_chain_on_the_synthetic_record(section):
    d = section.to_dict()
    assert d["synthetic"] and "SYNTHETIC" in d["record_source"]
    chain = {s["quantity"]: s for s in d["chain"]}
    # the paper's chain: spectrum -> -15 dB below ~30 rad/s -> bandwidth 60-80 rad/s
    assert chain["sensitivity level needed"]["paper"] == "-15"
    assert chain["sensitivity level needed"]["synth"] == pytest.approx(-15.0, abs=0.3)
    assert chain["disturbance power lies below (plateau corner)"]["synth"] == pytest.approx(30.0, rel=0.03)
    assert 60 <= chain["bandwidth floor (acceptable)"]["synth"] <= 80
    assert chain["bandwidth floor (acceptable)"]["synth"] == pytest.approx(65.3, abs=0.05)
    assert chain["bandwidth (ideal)"]["synth"] == pytest.approx(80.0, rel=0.02)
    assert chain["sensor noise floor"]["synth"] == pytest.approx(-30.0, abs=0.1)
    assert "157, 220, 283" in chain["supply spikes"]["how"]
    assert d["disturbance"]["spec_entries"] == [{"type": "sensitivity", "max_db": -15.3, "band": [0, 29.7]},
                                                {"type": "bandwidth", "min": 65.3}]


def test_sizing_numbers(section):
    s = section.to_dict()["sizing"]
    assert s["thrust"]["value"] == pytest.approx(12.749, abs=1e-3)
    assert s["induced_power"]["value"] == pytest.approx(99.44, abs=0.01)
    assert s["shaft_power"]["value"] == pytest.approx(139.92, abs=0.01)  # 0.1749 N m x 800 rad/s
    assert s["torque_constant"]["value"] == pytest.approx(0.1749 / 22)
    assert s["battery_current"]["value"] == 24.0 and s["current_limit"]["value"] == 22.0
    rows = {r["quantity"]: r for r in section.to_dict()["sizing_rows"]}
    assert rows["thrust per rotor"]["status"] == "reconciles"
    assert rows["induced power for 12.7 N"]["synth"] == pytest.approx(98.87, abs=0.01)
    assert rows["air density implied by 101.2 W"]["synth"] == pytest.approx(1.169, abs=1e-3)


def test_one_table_of_every_unreconciled_number(section):
    rows = {r["quantity"]: r for r in section.to_dict()["disagreements"]}
    assert all(r["status"] == "does not reconcile" for r in rows.values())
    assert len(rows) == len(section.table.disagreements()) == 25
    # the three of section 3 named by the issue
    assert rows["top shaft power at 800 rad/s"]["paper"] == "131"
    assert rows["shaft power 131 W / 0.1749 N m: speed"]["synth"] == pytest.approx(749.0, abs=0.1)
    assert rows["induced power for 12.7 N"]["paper"] == "101.2"
    assert rows["current limit"]["paper"] == "22" and rows["current limit"]["synth"] == 24
    # eq. 15's slow pair, which the X-4 report did not flag before
    assert rows["eq. 15 slow pole (measured)"]["paper"] == "0.0042"
    assert rows["eq. 15 slow pole (measured)"]["synth"] == pytest.approx(0.4429, abs=1e-4)
    assert rows["eq. 15 zero (measured)"]["paper"] == "0.0046"
    assert rows["eq. 15 zero (measured)"]["synth"] == pytest.approx(0.43)
    assert all(r["reconcile"] for r in rows.values())


def test_design_report_section_html_json_and_figure(tmp_path):
    spec = _spec()
    files = write_design_report(spec, design(spec), tmp_path / "rep")
    assert files.figures["paper_disturbance"].name == "paper_disturbance_requirements.png"
    assert files.figures["paper_disturbance"].stat().st_size > 10_000
    data = json.loads(files.result_json.read_text())
    assert len(data["paper_section"]["disagreements"]) == 25
    html = files.html.read_text()
    assert "Disturbance record &rarr; requirements (SYNTHETIC record)" in html
    assert "Rotor and drive sizing" in html
    assert "Every paper number that does not reconcile (25 of 38 checked)" in html
    assert "eq. 15 slow pole (measured)" in html and "0.0042" in html
    assert "{type: sensitivity, max_db: -15.3, band: [0, 29.7]}" in html
    assert 'src="paper_disturbance_requirements.png"' in html


def test_no_section_unless_asked(tmp_path):
    spec = _spec(None)
    files = write_design_report(spec, design(spec), tmp_path / "rep")
    assert "paper_disturbance" not in files.figures
    assert "paper_section" not in json.loads(files.result_json.read_text())
    assert "does not reconcile" not in files.html.read_text()


def test_unknown_paper_is_a_spec_error():
    with pytest.raises(SpecError, match=r"analysis\.paper: Input should be 'x4'"):
        _spec("x5")
