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


def tone_record(seed: int, n: int = 80000, coloured: float = 0.0):
    """White noise (std 0.2), tones at 50 and 400 Hz, and optionally a disturbance low-passed at 2 Hz."""
    from scipy import signal

    rng = np.random.default_rng(seed)
    t = np.arange(n) / 1000
    x = 0.2 * rng.standard_normal(n) + np.sin(2 * np.pi * 50 * t) + 0.5 * np.sin(2 * np.pi * 400 * t)
    if coloured:
        b, a = signal.butter(1, 2.0 / 500.0)
        x += coloured * signal.lfilter(b, a, rng.standard_normal(n))
    return t, x, rng


def suggestion(run_cli, tmp_path, data, *extra):
    out = tmp_path / "psd.json"
    res = run_cli("psd", "--data", data, "--signal", "d", "--json", str(out), *extra)
    assert res.code == 0, res.err
    return json.loads(out.read_text())


def test_a_hole_in_the_log_is_not_interpolated_into_a_requirement(run_cli, tmp_path):
    t, x, _ = tone_record(31)
    t[40001:] += 0.5  # a 0.5 s hole
    data = suggestion(run_cli, tmp_path, write(tmp_path / "gap.csv", t, x), "--time", "t")
    assert data["bandwidth_suggestion"]["status"] == "not significant"  # was a bandwidth of 320 rad/s
    assert len(data["records"]) == 2 and any("split there" in n for n in data["notes"])


def test_tones_interpolated_across_dropped_samples_are_not_a_disturbance(run_cli, tmp_path):
    t, x, rng = tone_record(80)
    keep = rng.uniform(size=t.size) > 0.02
    keep[0] = keep[-1] = True
    data = suggestion(run_cli, tmp_path, write(tmp_path / "drop.csv", t[keep], x[keep]), "--time", "t")
    assert data["bandwidth_suggestion"]["status"] == "interpolated", data["bandwidth_suggestion"]  # was 1220 rad/s


def test_a_disturbance_with_dropped_samples_keeps_its_suggestion(run_cli, tmp_path):
    t, x, rng = tone_record(81, coloured=3.0)
    whole = suggestion(run_cli, tmp_path, write(tmp_path / "whole.csv", t, x), "--time", "t")
    keep = rng.uniform(size=t.size) > 0.02
    keep[0] = keep[-1] = True
    dropped = suggestion(run_cli, tmp_path, write(tmp_path / "drop.csv", t[keep], x[keep]), "--time", "t")
    a, b = whole["bandwidth_suggestion"], dropped["bandwidth_suggestion"]
    assert "min_bandwidth" in a and "min_bandwidth" in b, (a, b)
    # the tones' interpolation error spread over the band still moves the 90 % frequency up (12 % here)
    assert a["min_bandwidth"] <= b["min_bandwidth"] <= 1.15 * a["min_bandwidth"]
