"""synth psd on what a black-box helper (session 69) tried: white noise given a bandwidth floor by
--requirements (the frequency where a disturbance that never stands above the sensor floor 'falls' to it was the
fitted corner), a noise record in mm/s taken as m/s (a floor 60 dB high), a traceback for --signal naming the time
column, and errors that did not name the option that caused them."""

from __future__ import annotations

import json

import numpy as np
import pytest


def write(path, t, x, header="t,d"):
    np.savetxt(path, np.c_[t, x], delimiter=",", header=header, comments="")
    return str(path)


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_white_noise_gets_no_bandwidth_floor(run_cli, tmp_path, seed):
    rng = np.random.default_rng(seed)
    n = 13153
    data = write(tmp_path / "white.csv", np.arange(n) / 1000, 3 * rng.standard_normal(n))
    out = tmp_path / "psd.json"
    res = run_cli("psd", "--data", data, "--time", "t", "--signal", "d", "--requirements", "--json", str(out))
    assert res.code == 0, res.err
    req = json.loads(out.read_text())["requirements"]
    assert req["min_bandwidth"] is None and "bandwidth" not in res.out.split("requirements from the disturbance")[1] \
        .split("\n")[1], res.out


def test_a_plateau_below_a_coarse_resolution_gives_no_bandwidth_floor(run_cli, tmp_path):
    from scipy import signal

    rng = np.random.default_rng(5)
    n = 60000
    b, a = signal.butter(2, 4.0 / 500.0)  # a disturbance with a plateau up to 4 Hz
    x = signal.lfilter(b, a, rng.standard_normal(n)) + 0.01 * rng.standard_normal(n)
    data = write(tmp_path / "d.csv", np.arange(n) / 1000, x)
    out = tmp_path / "psd.json"
    res = run_cli("psd", "--data", data, "--time", "t", "--signal", "d", "--resolution", "100", "--json", str(out))
    req = json.loads(out.read_text())["requirements"]
    assert res.code == 0 and req["max_db"] is None and req["min_bandwidth"] is None, res.out
    assert "requirements: []" in res.out


def test_the_time_column_as_the_signal_is_one_line(run_cli, tmp_path):
    data = write(tmp_path / "w.csv", np.arange(4000) / 1000, np.random.default_rng(0).standard_normal(4000))
    res = run_cli("psd", "--data", data, "--time", "t", "--signal", "t")
    assert res.code == 2 and len(res.err.strip().splitlines()) == 1 and "--signal" in res.err, res.err


def test_records_in_different_units_are_refused(run_cli, tmp_path):
    rng = np.random.default_rng(70)
    t = np.arange(30000) / 1000
    a = write(tmp_path / "ua.csv", t, rng.standard_normal(t.size), "t,d (m/s)")
    c = write(tmp_path / "uc.csv", t, 1000 * rng.standard_normal(t.size), "t,d (mm/s)")
    res = run_cli("psd", "--data", a, "--noise-data", c, "--time", "t", "--signal", "d")
    line = res.err.strip()
    assert res.code == 2 and "\n" not in line and "--noise-data" in line and "mm/s" in line and "m/s" in line, line
    res = run_cli("psd", "--data", a, "--data", c, "--time", "t", "--signal", "d")
    assert res.code == 2 and "--data" in res.err and "uc.csv" in res.err


@pytest.mark.parametrize(("extra", "flag"), [(("--segment", "100"), "--segment"), (("--w-min", "5000"), "--w-min")])
def test_a_segment_the_record_cannot_hold_names_its_option(run_cli, tmp_path, extra, flag):
    data = write(tmp_path / "w.csv", np.arange(20000) / 1000, np.random.default_rng(1).standard_normal(20000))
    res = run_cli("psd", "--data", data, "--time", "t", "--signal", "d", *extra)
    assert res.code == 2 and res.err.strip().split(": error: ")[1].startswith(f"{flag}: "), res.err


def test_a_noise_record_shorter_than_a_segment_names_it(run_cli, tmp_path):
    rng = np.random.default_rng(2)
    data = write(tmp_path / "w.csv", np.arange(40000) / 1000, rng.standard_normal(40000))
    noise = write(tmp_path / "n.csv", np.arange(3000) / 1000, rng.standard_normal(3000))
    res = run_cli("psd", "--data", data, "--noise-data", noise, "--time", "t", "--signal", "d")
    assert res.code == 2 and "--noise-data" in res.err and "noise record" in res.err, res.err
