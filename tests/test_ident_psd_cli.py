"""``synth psd``: records from files, table, JSON, figure, errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.ident.psd import analyze_psd

DT = 0.001


def _write(path, x, header="t,speed", dt=DT):
    t = np.arange(x.size) * dt
    np.savetxt(path, np.column_stack([t, x]), delimiter=",", header=header, comments="", fmt="%.9g")
    return path


def _signal(seed, n=30_000):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * DT
    from scipy.signal import lfilter

    return lfilter([0.03], [1, -0.97], rng.normal(size=n)) + 0.3 * np.sin(250 * t) + 0.001 * rng.normal(size=n)


def test_two_records_table_and_json(run_cli, tmp_path):
    a, b = _write(tmp_path / "a.csv", _signal(1)), _write(tmp_path / "b.csv", _signal(2))
    r = run_cli("psd", "--data", str(a), "--data", str(b), "--time", "t", "--signal", "speed", "--unit", "rad/s")
    assert r.code == 0, r.err
    assert "2 record(s)" in r.out and "dB re 1 (rad/s)^2/(rad/s)" in r.out
    assert "250.0 rad/s" in r.out  # the spike
    r = run_cli("psd", "--data", str(a), "--data", str(b), "--time", "t", "--signal", "speed", "--json", "-")
    d = json.loads(r.out)
    direct = analyze_psd([np.loadtxt(a, delimiter=",", skiprows=1)[:, 1], np.loadtxt(b, delimiter=",", skiprows=1)[:, 1]],
                         DT)
    assert d["share_frequency"] == pytest.approx(direct.share_frequency, rel=1e-9)
    assert d["bandwidth_suggestion"]["spec_entry"] == {"type": "bandwidth", "min": float(f"{direct.share_frequency:.3g}")}
    assert [round(s["w"]) for s in d["spikes"]] == [250]


def test_out_folder_with_noise_record(run_cli, tmp_path):
    a = _write(tmp_path / "a.csv", _signal(3))
    n = _write(tmp_path / "n.csv", 0.002 * np.random.default_rng(4).normal(size=30_000))
    out = tmp_path / "rep"
    r = run_cli("psd", "--data", str(a), "--noise-data", str(n), "--time", "t", "--signal", "speed",
                "--share", "0.8", "--out", str(out))
    assert r.code == 0, r.err
    d = json.loads((out / "psd.json").read_text())
    assert d["floor_source"] == "noise record" and d["share"] == 0.8
    assert d["floor_db"] == pytest.approx(10 * np.log10(0.002**2 * DT / np.pi), abs=0.3)
    assert (out / "psd.png").stat().st_size > 10_000


def test_dt_without_time_column(run_cli, tmp_path):
    p = tmp_path / "x.csv"
    np.savetxt(p, _signal(5)[:, None], header="speed", comments="")
    r = run_cli("psd", "--data", str(p), "--signal", "speed", "--dt", "0.001", "--json", "-")
    assert r.code == 0, r.err
    assert json.loads(r.out)["records"][0]["dt"] == pytest.approx(0.001)


@pytest.mark.parametrize(("make", "extra", "match"), [
    (lambda p: _write(p, _signal(1), header="t,sped"), [], "signal column 'speed' not found; did you mean 'sped'?"),
    (lambda p: p.write_text("t,speed\n0,1\n0.001,nan\n" + "".join(f"{k / 1000},{k}\n" for k in range(2, 30))), [],
     "column 'speed': 1 value(s) are NaN"),
    (lambda p: p.write_text("t,speed\n" + "".join(f"{(k if k != 7 else 5) / 1000},{k % 3}\n" for k in range(30))), [],
     "time is not strictly increasing at sample 7"),
    (lambda p: _write(p, _signal(1, 5000)), ["--w-min", "0.5"], "the lowest frequency 0.5 rad/s needs segments of 25.13 s"),
    (lambda p: _write(p, _signal(1)), ["--share", "1.5"], "share must lie strictly between 0 and 1"),
    (lambda p: p.write_text("t,speed\n" + "".join(f"{k / 1000},{(k % 7) * 1e300}\n" for k in range(200))), [],
     "column 'speed': values up to 6e+300 overflow its power spectrum"),   # was a matplotlib traceback
])
def test_bad_input_one_line_exit_2(run_cli, tmp_path, make, extra, match):
    p = tmp_path / "d.csv"
    make(p)
    r = run_cli("psd", "--data", str(p), "--time", "t", "--signal", "speed", *extra)
    assert r.code == 2, r.out
    assert match in r.err and len(r.err.strip().splitlines()) == 1


def test_different_sample_rates_refused(run_cli, tmp_path):
    a = _write(tmp_path / "a.csv", _signal(1))
    b = _write(tmp_path / "b.csv", _signal(2, 10_000), dt=0.002)
    r = run_cli("psd", "--data", str(a), "--data", str(b), "--time", "t", "--signal", "speed")
    assert r.code == 2 and "sample interval 0.002 s differs from the 0.001 s" in r.err
