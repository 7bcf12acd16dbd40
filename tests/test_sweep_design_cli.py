"""``synth sweep-design`` (issue 19, item 5): the NASA sweep report's recipe as a CSV for the rig."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest


def _read(path):
    lines = path.read_text().splitlines()
    data = np.loadtxt(path, delimiter=",", skiprows=2)
    return lines[0], lines[1], data[:, 0], data[:, 1]


def _zero_crossings(t, u):
    s = np.signbit(u)
    return t[1:][s[1:] != s[:-1]]


def test_the_reports_roll_sweep(run_cli, tmp_path):
    """Bell 214ST roll: 0.4-12 rad/s, T_max about 16 s, two cycles of it first, 90 s runs, 3 flown, 2 used."""
    out = tmp_path / "roll.csv"
    r = run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--amplitude", "1.5", "--out", str(out))
    assert r.code == 0, r.err
    assert "15.71 s (2 cycles at the start: 31.42 s)" in r.out and "fly 3, concatenate the best 2" in r.out
    assert "90 s (recipe: 90 s)" in r.out
    first, head, t, u = _read(out)
    assert first.startswith("# synth") and head == "time_s,input"
    assert t[0] == 0 and t[-1] == pytest.approx(90.0) and np.allclose(np.diff(t), 1 / 48, atol=1e-6)
    assert np.max(np.abs(u)) == pytest.approx(1.5)
    assert u[0] == 0 and abs(u[-1]) < 1e-3  # starts and ends at trim
    fade = 15.708 / 4
    assert np.max(np.abs(u[t < 0.2 * fade])) < 0.2  # the raised-cosine fade-in
    # the first two cycles are at w_min: 4 zero crossings in 2 T_max (one period is 15.7 s)
    low = _zero_crossings(t[(t > 0.1) & (t < 31.4)], u[(t > 0.1) & (t < 31.4)])
    assert len(low) == 3 and np.diff(low) == pytest.approx([np.pi / 0.4] * 2, rel=0.02)
    # the frequency rises to w_max at the end: half-periods of about pi/12 s
    end = _zero_crossings(t[t > 80], u[t > 80])
    assert np.median(np.diff(end[-6:])) == pytest.approx(np.pi / 12, rel=0.15)


def test_duration_fade_sample_rate_and_json(run_cli, tmp_path):
    out = tmp_path / "rotor.csv"
    r = run_cli("sweep-design", "--w-min", "1", "--w-max", "300", "--duration", "120", "--amplitude", "20",
                "--fade", "0.5", "--sample-rate", "1000", "--name", "pwm", "--out", str(out), "--json", "-")
    assert r.code == 0, r.err
    plan = json.loads(r.out)
    assert plan["duration_s"] == 120 and plan["fade_s"] == 0.5 and plan["sample_rate_hz"] == 1000
    assert plan["samples"] == 120_001 and plan["t_max_s"] == pytest.approx(2 * np.pi)
    assert plan["recommended_run_length_s"] == 90.0 and plan["column"] == "pwm"
    _, head, t, u = _read(out)
    assert head == "time_s,pwm" and t[-1] == pytest.approx(120.0) and np.max(np.abs(u)) == pytest.approx(20.0)
    assert np.max(np.abs(u[(t > 0.5) & (t < 2.0)])) > 19  # past the 0.5 s fade: full amplitude


def test_shorter_than_the_recipe_is_noted(run_cli, tmp_path):
    r = run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--duration", "60", "--out", str(tmp_path / "s.csv"))
    assert r.code == 0 and "shorter than the recipe's 90 s" in r.out
    assert "a short sweep" not in r.out  # 28.6 s of sweep after the low cycles: 49 % of the recipe's 58.6 s


def test_a_run_that_leaves_the_sweep_a_few_seconds_says_so(run_cli, tmp_path):
    """A black-box test: 300 s from 0.044 rad/s, whose two low cycles take 285.7 s, left 14.3 s to sweep 1.8
    decades (4 % of the recipe's 357 s) with only a note about fewer windows."""
    r = run_cli("sweep-design", "--w-min", "0.04398", "--w-max", "3.062", "--duration", "300", "--sample-rate", "20",
                "--out", str(tmp_path / "s.csv"))
    assert r.code == 0, r.err
    line = next(x for x in r.out.splitlines() if "a short sweep" in x)
    assert "14.3 s for 1.8 decades, 4 % of the recipe's 357.2 s" in line


def test_never_overwrites_a_users_file_but_replaces_its_own(run_cli, tmp_path):
    out = tmp_path / "sweep.csv"
    out.write_text("time,my data\n")
    r = run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--out", str(out))
    assert r.code == 2 and "not written by synth; not overwriting" in r.err and len(r.err.strip().splitlines()) == 1
    assert out.read_text() == "time,my data\n"
    out.unlink()
    assert run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--out", str(out)).code == 0
    r = run_cli("sweep-design", "--w-min", "0.5", "--w-max", "12", "--out", str(out))  # its own: replaced
    assert r.code == 0 and "0.5-12 rad/s" in out.read_text().splitlines()[0]


@pytest.mark.parametrize("args, words", [
    (["--w-min", "5", "--w-max", "1"], "--w-min/--w-max: need 0 < w_min < w_max"),
    (["--w-min", "0", "--w-max", "1"], "--w-min: must be a positive number"),
    (["--w-min", "0.4", "--w-max", "12", "--duration", "20"], "--duration: 20 s leaves no sweep"),
    (["--w-min", "0.4", "--w-max", "12", "--fade", "50"], "--fade: fade-in plus fade-out (100 s)"),
    (["--w-min", "0.4", "--w-max", "12", "--fade", "-1"], "--fade: must be a non-negative number"),
    (["--w-min", "0.4", "--w-max", "12", "--sample-rate", "2"], "--sample-rate: sample rate 2 Hz must exceed"),
    (["--w-min", "0.4", "--w-max", "12", "--amplitude", "nan"], "--amplitude: must be a positive number"),
    (["--w-min", "0.4", "--w-max", "12", "--runs", "0"], "--runs: must be at least 1"),
    (["--w-min", "0.4", "--w-max", "12", "--name", "a,b"], "--name: not a usable column name"),
])
def test_bad_input_one_line_exit_2(run_cli, tmp_path, args, words):
    out = tmp_path / "x.csv"
    r = run_cli("sweep-design", *args, "--out", str(out))
    assert r.code == 2 and words in r.err and len(r.err.strip().splitlines()) == 1
    assert not out.exists()


def test_missing_folder(run_cli, tmp_path):
    r = run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--out", str(tmp_path / "no" / "x.csv"))
    assert r.code == 2 and "folder does not exist" in r.err


def test_amplitude_reduced_above_a_frequency_as_the_reports_pilots_did(run_cli, tmp_path):
    """Roll sweep with the amplitude halved from 1.5 Hz on (the report: pylon mode above 2 Hz)."""
    out = tmp_path / "roll.csv"
    r = run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--amplitude", "1.5", "--reduce-above", "1.5",
                "--reduce-to", "0.5", "--out", str(out), "--json", str(tmp_path / "plan.json"))
    assert r.code == 0, r.err
    first, _, t, u = _read(out)
    assert "amplitude x 0.5 above 1.5 Hz" in first
    # instantaneous frequency from the zero crossings: half a period between neighbours
    z = _zero_crossings(t, u)
    w_mid = np.pi / np.diff(z)
    peaks = np.array([np.max(np.abs(u[(t >= a) & (t < b)])) for a, b in itertools.pairwise(z)])
    below = peaks[(w_mid < 2 * np.pi * 1.5 / np.sqrt(2) * 0.9) & (z[:-1] > 10)]
    above = peaks[w_mid > 2 * np.pi * 1.5 * 1.1]
    assert below.size > 10 and above.size > 5
    assert np.min(below[:-3]) == pytest.approx(1.5, rel=0.05) and np.max(above) <= 0.75 * 1.02
    assert np.max(np.abs(np.diff(u))) < 0.5  # no step: the change is smooth
    plan = json.loads((tmp_path / "plan.json").read_text())
    assert plan["reduce_above_hz"] == 1.5 and plan["reduce_to"] == 0.5
    bad = run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--reduce-above", "1.5", "--reduce-to", "2",
                  "--out", str(tmp_path / "x.csv"))
    assert bad.code == 2 and "--reduce-to" in bad.err and len(bad.err.strip().splitlines()) == 1
