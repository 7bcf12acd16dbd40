"""Bad input a black-box helper found ending in a traceback or in a silent wrong answer (session 68).

Each case is one line naming the file, key or option, exit 2, or (where the input is valid) the right answer.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.io import savemat
from scipy.sparse import csr_matrix

from synth.data import load_record
from synth.data.readers import read_table
from synth.errors import DataError


def _step_csv(path, extra_row: int | None = None) -> None:
    t = np.arange(400) * 0.01
    u = np.where(t >= 0.5, 1.0, 0.0)
    y = np.where(t >= 0.5, 1.0 - np.exp(-(t - 0.5) / 0.3), 0.0)
    rows = [f"{a:g},{b:g},{c:.6f}" for a, b, c in zip(t, u, y)]
    if extra_row is not None:
        rows[extra_row] += ",7"
    path.write_text("t,u,y\n" + "\n".join(rows) + "\n", encoding="utf-8")


@pytest.mark.parametrize("content, says", [
    (b"t,u,y\n" + b"".join(b"%d,0,0\n" % i for i in range(300)), "cannot read as a MATLAB file ("),
    (b"", "cannot read as a MATLAB file (MatReadError"),
])
def test_a_file_named_mat_that_is_not_one(tmp_path, content, says):
    p = tmp_path / "run.mat"
    p.write_bytes(content)
    with pytest.raises(DataError, match=r"run\.mat: " + says.replace("(", r"\(")):
        read_table(p)


def test_mat_sparse_vectors_are_read_and_complex_ones_named(tmp_path):
    t = np.arange(200) * 0.01
    u = np.where(t > 0.5, 1.0, 0.0)
    p = tmp_path / "s.mat"
    savemat(p, {"t": t, "u": csr_matrix(u), "y": 2 * u, "z": (1 + 1j) * u, "names": np.array(["a", "b"])})
    tab = read_table(p)
    np.testing.assert_array_equal(tab.columns["u"], u)  # a 1 x N sparse matrix is the vector u, not u[0]
    with pytest.raises(DataError, match=r"s\.mat: MAT variable 'z' is complex, not a real numeric vector$"):
        load_record(p, "t", "z", "y")
    with pytest.raises(DataError, match=r"MAT variable 'names' is text"):
        load_record(p, "t", "names", "y")


def test_a_row_longer_than_the_header(tmp_path):
    p = tmp_path / "r.csv"
    _step_csv(p, extra_row=49)
    with pytest.raises(DataError, match=r"r\.csv: line 51 has 4 fields, the header 3: which column does '7' belong"):
        read_table(p)
    q = tmp_path / "trailing.csv"  # a trailing separator is no extra field
    q.write_text("t,u,y\n0,0,0,\n0.1,1,0.5,\n0.2,1,0.7,\n", encoding="utf-8")
    assert read_table(q).columns["y"].tolist() == [0.0, 0.5, 0.7]


def test_a_time_column_with_a_sample_interval_given(tmp_path):
    p = tmp_path / "r.csv"
    _step_csv(p)
    with pytest.raises(DataError, match=r"column 't' looks like a time column"):
        load_record(p, None, None, None, dt=0.01)
    r = load_record(p, None, "u", "y", dt=0.01)  # named: the user's choice stands
    assert r.dt == pytest.approx(0.01)


def test_psd_of_a_signal_too_small_for_double_precision(run_cli, tmp_path):
    t = np.arange(4000) * 0.005
    p = tmp_path / "tiny.csv"
    np.savetxt(p, np.c_[t, 1e-300 * np.sin(7 * t)], delimiter=",", header="t,x", comments="")
    r = run_cli("psd", "--data", str(p), "--time", "t", "--signal", "x", "--out", str(tmp_path / "o"))
    assert r.code == 2 and "Traceback" not in r.err
    assert "column 'x': its values vary by" in r.err and "underflows double precision" in r.err


def test_diagnose_negative_seed_and_tradeoff_bad_scheduler(run_cli, tmp_path):
    r = run_cli("diagnose", "--plant", "2/(s+3)", "--data", str(tmp_path / "none.csv"), "--seed", "-5")
    assert r.code == 2 and "--seed: must be an integer >= 0, got -5" in r.err
    from synth.errors import SynthError
    from synth.spec import parse_spec
    from synth.synthesis.tradeoff import Sweep, tradeoff

    spec = parse_spec({"name": "t", "plant": {"tf": "2/(s+3)"}, "controller": {"type": "P"},
                       "requirements": [{"type": "bandwidth", "min": 1}]})
    with pytest.raises(SynthError, match=r"cannot reach the Dask scheduler: .*port"):
        tradeoff(spec, [Sweep.parse("requirements.bandwidth.min=1,2")], scheduler="nonsense")


def test_initial_values_must_be_finite(run_cli, tmp_path):
    for kind, initial in (("P", "{kp: .nan}"), ("PI", "{kp: .inf, ki: 5}")):
        p = tmp_path / f"{kind}.yaml"
        p.write_text(f"name: x\nplant: {{tf: '2/(s+3)'}}\ncontroller:\n  type: {kind}\n  initial: {initial}\n"
                     "requirements:\n  - {type: bandwidth, min: 1}\n", encoding="utf-8")
        r = run_cli("check", str(p), "-c", "P(3)" if kind == "P" else "PI(3, 1)")
        assert r.code == 2 and f"{p.name}:5: controller.initial.kp: expected a finite number, got" in r.err


def _frd_csv(path, w_header: str, phase_header: str, w_factor: float, phase_factor: float) -> None:
    w = np.geomspace(0.1, 20, 80)
    H = np.exp(-0.1j * w) / ((1j * w) ** 2 + 1j * w + 1)  # the seed's example: w180 3.262 rad/s
    rows = [f"{a / w_factor:.10g},{20 * math.log10(abs(h)):.10g},{np.angle(h) * phase_factor:.10g}"
            for a, h in zip(w, H)]
    path.write_text(f"{w_header},mag_db [dB],{phase_header}\n" + "\n".join(rows) + "\n", encoding="utf-8")


@pytest.mark.parametrize("w_header, phase_header, w_factor, phase_factor", [
    ("w [Hz]", "phase_deg [deg]", 2 * math.pi, 180 / math.pi),
    ("w (rad/s)", "phase_deg (rad)", 1.0, 1.0),
])
def test_hq_frd_csv_units_in_the_header(run_cli, tmp_path, w_header, phase_header, w_factor, phase_factor):
    p = tmp_path / "f.csv"
    _frd_csv(p, w_header, phase_header, w_factor, phase_factor)
    r = run_cli("hq", "--frd", str(p), "--json", "-")
    assert r.code == 0, r.err
    assert json.loads(r.out)["w180"] == pytest.approx(3.262, rel=2e-3)


def test_hq_frd_bad_unit_lengths_and_no_band(run_cli, tmp_path):
    p = tmp_path / "f.csv"
    _frd_csv(p, "w [rpm]", "phase_deg", 1.0, 180 / math.pi)
    r = run_cli("hq", "--frd", str(p))
    assert r.code == 2 and "column 'w': unit 'rpm' is not one of rad/s, hz, 1/s" in r.err
    j = tmp_path / "j.json"
    j.write_text(json.dumps({"w": [1, 2, 3, 4, 5], "magnitude_db": [0, 0, 0], "phase_deg": [0, -90, -180, -200, -250]}))
    r = run_cli("hq", "--frd", str(j))
    assert r.code == 2 and "columns differ in length: w 5, magnitude_db 3, phase_deg 5" in r.err
    nb = tmp_path / "nb.json"
    w = np.geomspace(0.1, 20, 30)
    nb.write_text(json.dumps({"w": w.tolist(), "magnitude_db": [0.0] * 30, "phase_deg": (-20 * w).tolist(),
                              "coherent_band": {"w_min": None, "w_max": None, "threshold": 0.8}}))
    r = run_cli("hq", "--frd", str(nb))
    assert r.code == 2 and "freqresp found no coherent band in this response" in r.err
    assert run_cli("hq", "--frd", str(nb), "--all-points").code == 0


def test_freqresp_skew_longer_than_a_run(run_cli, tmp_path):
    p = tmp_path / "r.csv"
    _step_csv(p)
    r = run_cli("freqresp", "--data", str(p), "--skew", "1000", "--out", str(tmp_path / "o"))
    assert r.code == 2 and "--skew: a channel skew of 1000 s is not shorter than the shortest run (3.99 s)" in r.err


def test_runs_whose_time_stamps_were_rounded_are_at_one_rate():
    """Two runs of one 60 Hz sweep written with 6-decimal time stamps, the second cut to 70 %: their mean intervals
    differ by 3e-7 of it, and freqresp refused them ("0.0166667 s differs from the first run's 0.0166667 s")."""
    from synth.data import record_from_arrays
    from synth.ident.spectral_windows import as_runs

    t = np.round(np.arange(5400) / 60.0, 6)
    u = np.sin(0.3 * t * (1 + t / 20))
    a = record_from_arrays(t, u, u)
    b = record_from_arrays(t[:3780], u[:3780], u[:3780])
    assert a.dt != b.dt and len(as_runs([a, b])) == 2
    c = record_from_arrays(t * (1 + 1e-4), u, u)
    with pytest.raises(DataError, match=r"sample interval 0\.016668\d* s differs from the first run's 0\.016666"):
        as_runs([a, c])


def _spec(tmp_path, requirements: str, name: str = "s.yaml"):
    p = tmp_path / name
    p.write_text("name: x\nplant: {tf: '2/(s+3)'}\ncontroller: {type: P}\nrequirements:\n" + requirements,
                 encoding="utf-8")
    return p


@pytest.mark.parametrize("requirements, says", [
    ("  - {type: bandwidth, min: 1, label: a}\n  - {type: margins, phase_margin_deg: 40, label: a}\n",
     "s.yaml:4: requirements: label 'a' is given to 2 requirements"),
    ("  - {type: bandwidth, min: 1, label: closed-loop stability}\n",
     "label 'closed-loop stability' names the built-in stability row"),
    ("  - {type: bandwidth, min: .inf}\n", "s.yaml:5: requirements[0].min: expected a finite number, got inf"),
])
def test_spec_labels_and_infinite_bounds(run_cli, tmp_path, requirements, says):
    r = run_cli("check", str(_spec(tmp_path, requirements)), "-c", "P(3)")
    assert r.code == 2 and says in r.err


def test_messages_name_what_is_wrong(run_cli, tmp_path):
    (tmp_path / "afile").write_text("")
    r = run_cli("hq", "--tf", "1/(s+1)", "--json", str(tmp_path / "afile" / "x.json"))
    assert r.code == 2 and f"its folder {tmp_path / 'afile'} exists and is not a directory" in r.err
    p = tmp_path / "huge.csv"
    t = np.arange(200) * 0.01
    np.savetxt(p, np.c_[t, 1e200 * np.sin(t), np.cos(t)], delimiter=",", header="t,u,y", comments="")
    r = run_cli("diagnose", "--plant", "2/(s+3)", "--data", str(p), "--no-report")
    assert r.code == 2 and "column 'u': values up to 1e+200 overflow double precision" in r.err
    q = tmp_path / "r.csv"
    _step_csv(q)
    r = run_cli("identify", "--data", str(q), "--structure", "K/(T*s+1)", "--sensor", "1/(s-1)",
                "--out", str(tmp_path / "o"), "--no-figures")
    assert r.code == 2 and "sensor: a known sensor must be stable; 1/(s-1) has pole(s) at 1" in r.err
    folder_spec = tmp_path / "f.yaml"
    folder_spec.write_text("name: x\nplant:\n  identify: {data: " + str(tmp_path) + ", structure: 'K/(T*s+1)'}\n"
                           "controller: {type: P}\nrequirements: [{type: bandwidth, min: 1}]\n", encoding="utf-8")
    r = run_cli("check", str(folder_spec), "-c", "P(3)")
    assert r.code == 2 and "is a folder, not a file" in r.err


def test_hq_fit_band_outside_the_data(run_cli, tmp_path):
    p = tmp_path / "f.csv"
    _frd_csv(p, "w", "phase_deg", 1.0, 180 / math.pi)
    r = run_cli("hq", "--frd", str(p), "--fit-band", "1000", "2000")
    assert r.code == 2 and "--fit-band: the fit band 1000-2000 rad/s holds 0 of the response's frequencies" in r.err


def test_diagnose_with_a_constant_training_part(run_cli, tmp_path):
    """A step at 60 % of the record, the tail split at 50 %: every fit failed with "arrays: column 'input': the input
    is constant (0)", which did not say that it was the training part (a black-box helper)."""
    t = np.arange(2000) * 0.01
    u = np.where(t >= 12.0, 1.0, 0.0)
    y = np.where(t >= 12.0, 1.0 - np.exp(-(t - 12.0) / 0.3), 0.0) + 0.001 * np.sin(7 * t)
    p = tmp_path / "late_step.csv"
    np.savetxt(p, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    r = run_cli("diagnose", "--plant", "1/(0.3*s+1)", "--data", str(p), "--no-report", "--workers", "1")
    assert r.code == 2 and "the training part (t < 10 s, the record's first 50 %) holds a constant command" in r.err
