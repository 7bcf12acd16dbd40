"""``synth psd --requirements``: the X-4 paper's disturbance chain from files (issue 19, item 1)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from synth.ident.disturbance_synthetic import synthetic_disturbance_record, synthetic_noise_record
from synth.spec import parse_spec


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """The SYNTHETIC X-4 disturbance record and sensor-noise record (70 s at 1 kHz) as CSV files."""
    folder = tmp_path_factory.mktemp("psd_req")
    paths = {}
    for name, rec in (("disturbance", synthetic_disturbance_record()), ("noise", synthetic_noise_record())):
        t = np.arange(rec.x.size) * rec.dt
        paths[name] = folder / f"{name}.csv"
        np.savetxt(paths[name], np.column_stack([t, rec.x]), delimiter=",", header="t,speed", comments="", fmt="%.9g")
    return paths


def _args(records, *extra):
    return ("psd", "--data", str(records["disturbance"]), "--noise-data", str(records["noise"]), "--time", "t",
            "--signal", "speed", "--unit", "rad/s", *extra)


def test_the_papers_chain_printed_and_written(run_cli, records, tmp_path):
    out = tmp_path / "rep"
    r = run_cli(*_args(records, "--resolution", "1.2", "--out", str(out)))
    assert r.code == 0, r.err
    # the seed's numbers: -15 dB below 30 rad/s, bandwidth between 60 and 80 rad/s
    assert "{type: sensitivity, max_db: -15.3, band: [0, 29.7]}" in r.out  # this seed; -15 and 30 are the shape's
    assert "{type: bandwidth, min: 65.3}" in r.out and "meets it at 79.1 rad/s" in r.out
    assert "resolution 1.2 rad/s -44.2 dB" in r.out  # the resolution's floor lies 14 dB below the noise record's
    block = yaml.safe_load((out / "requirements.yaml").read_text())
    assert block["requirements"] == [{"type": "sensitivity", "max_db": -15.3, "band": [0, 29.7]},
                                      {"type": "bandwidth", "min": 65.3}]
    d = json.loads((out / "psd.json").read_text())
    req = d["requirements"]
    assert req["max_db"] == pytest.approx(-15.0, abs=0.3)
    assert req["band"][1] == pytest.approx(30.0, rel=0.05)
    assert 60 <= req["min_bandwidth"] <= 80 and req["ideal_bandwidth"] == pytest.approx(80.0, rel=0.05)
    assert req["sensor_floor_source"] == "noise record"
    assert [round(e["value"]) for e in req["evidence"] if e["name"] == "spike"] == [157, 220, 283]
    assert (out / "disturbance_requirements.png").stat().st_size > 10_000
    # the block is ready: it drops into a spec as written
    spec = yaml.safe_load(open("specs/x4_rotor.yaml"))
    parsed = parse_spec(spec | block)
    assert [type(q).__name__ for q in parsed.requirements] == ["Sensitivity", "Bandwidth"]


def test_resolution_alone_without_noise_record(run_cli, records):
    r = run_cli("psd", "--data", str(records["disturbance"]), "--time", "t", "--signal", "speed", "--unit", "rad/s",
                "--resolution", "1.2", "--json", "-")
    assert r.code == 0, r.err
    req = json.loads(r.out)["requirements"]
    assert req["sensor_floor_source"] == "median of the upper half"  # -30 dB measured floor beats -44 dB resolution
    assert req["max_db"] == pytest.approx(-15.0, abs=0.5)


def test_without_the_option_no_requirements(run_cli, records):
    r = run_cli(*_args(records, "--json", "-"))
    assert r.code == 0, r.err
    assert "requirements" not in json.loads(r.out)


@pytest.mark.parametrize("extra, words", [
    (("--resolution", "-1"), "--resolution: disturbance requirements: resolution must be > 0"),
    (("--requirements", "--margin-db", "-2"), "--margin-db: disturbance requirements: margin_db must be >= 0"),
    (("--margin-db", "2"), "--margin-db: used only with --requirements"),
])
def test_bad_input_one_line_exit_2(run_cli, records, extra, words):
    r = run_cli(*_args(records, *extra))
    assert r.code == 2
    assert words in r.err and len(r.err.strip().splitlines()) == 1


def test_never_overwrites_a_users_file(run_cli, records, tmp_path):
    out = tmp_path / "rep"
    out.mkdir()
    (out / "requirements.yaml").write_text("my own notes\n")
    r = run_cli(*_args(records, "--requirements", "--out", str(out)))
    assert r.code == 2 and "requirements.yaml" in r.err
    assert (out / "requirements.yaml").read_text() == "my own notes\n"
