"""``synth freqresp``: JSON keys, figures, fit and verification, one-line errors with exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.ident.simulate import simulate_plant
from synth.ident.sweep_design import design_sweep
from synth.plant import Plant

RATE = Plant.from_string("31.6*s/((s+0.49)*(s+2.30))", delay=0.041)
ATT = Plant.from_string("31.6/((s+0.49)*(s+2.30))", delay=0.041)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("sweeps")
    rng = np.random.default_rng(5)
    paths = []
    for k in range(2):
        t, u = design_sweep(0.4, 12.0).signal(1.0, 50.0)
        y = simulate_plant(RATE, t, u, "zero")
        y = y + 0.05 * np.std(y) * rng.standard_normal(t.size)
        p = d / f"run{k}.csv"
        np.savetxt(p, np.c_[t, u, y], delimiter=",", header="t,lat,p", comments="")
        paths.append(str(p))
    t = np.arange(0, 20, 0.02)
    u = np.where(t > 2, 1.0, 0.0)
    step = d / "step.csv"
    np.savetxt(step, np.c_[t, u, simulate_plant(ATT, t, u)], delimiter=",", header="t,lat,p", comments="")
    short = d / "short.csv"
    np.savetxt(short, np.c_[t, np.sin(t * t / 4), np.cos(t)], delimiter=",", header="t,lat,p", comments="")
    return {"runs": paths, "step": str(step), "short": str(short), "dir": d}


def test_json_keys_fit_and_verification(run_cli, files, tmp_path):
    out = tmp_path / "r.json"
    res = run_cli("freqresp", "--data", files["runs"][0], "--data", files["runs"][1], "--time", "t", "--input", "lat",
                  "--output", "p", "--wmin", "0.4", "--wmax", "12", "--rate-to-attitude", "--fit", "0/2",
                  "--verify", files["step"], "--json", str(out), "--out", str(tmp_path / "rep"))
    assert res.code == 0, res.err
    data = json.loads(out.read_text())
    n = len(data["w"])
    for key in ("magnitude_db", "phase_deg", "coherence", "random_error"):
        assert len(data[key]) == n
    assert data["w"][0] == pytest.approx(0.4) and data["w"][-1] == pytest.approx(12.0)
    w = np.array(data["w"])
    k = np.argmin(abs(w - 2.0))
    assert data["magnitude_db"][k] == pytest.approx(20 * np.log10(abs(ATT.freqresp(w[k]))), abs=0.5)
    assert data["coherent_band"]["w_min"] == pytest.approx(0.4) and data["coherent_band"]["threshold"] == 0.8
    fit = data["fit"]
    assert set(fit["parameters"]) == {"b0", "a1", "a0", "delay"} and fit["J"] > 0
    assert fit["parameters"]["b0"] == pytest.approx(31.6, rel=0.05)
    # the runs are simulated from input samples held 20 ms, which lag a sine by half a sample: the sweep's response
    # carries the plant's 41 ms and about 10 ms more, which a step (changing at a sample) does not show
    assert fit["parameters"]["delay"] == pytest.approx(0.041 + 0.010, abs=0.004)
    assert data["verification"]["fit_percent"] > 85
    assert (tmp_path / "rep" / "bode.png").exists() and (tmp_path / "rep" / "verify.png").exists()
    assert "coherent band" in res.out and "J = " in res.out


def test_bad_input_exits_2_with_one_line(run_cli, files):
    cases = [
        (("--data", files["short"], "--wmin", "0.4"), "one run of"),
        (("--data", files["runs"][0], "--output", "q"), "output column 'q' not found"),
        (("--data", files["runs"][0], "--wmin", "0.4", "--fit", "k/(s+"), "--fit: cannot parse structure"),
        (("--data", files["runs"][0], "--wmin", "0.4", "--verify", files["step"]), "--verify: needs --fit"),
        (("--data", files["runs"][0], "--wmin", "0.4", "--fit", "0/2", "--delay", "soon"), "--delay"),
        (("--data", str(files["dir"] / "missing.csv")), "file not found"),
    ]
    for args, message in cases:
        res = run_cli("freqresp", *args)
        assert res.code == 2, (args, res.out, res.err)
        assert message in res.err and len(res.err.strip().splitlines()) == 1, res.err
        assert "Traceback" not in res.err


def test_does_not_overwrite_user_file(run_cli, files, tmp_path):
    mine = tmp_path / "mine.json"
    mine.write_text("my notes")
    res = run_cli("freqresp", "--data", files["runs"][0], "--wmin", "0.4", "--json", str(mine))
    assert res.code == 2 and "not overwriting" in res.err and mine.read_text() == "my notes"


def test_a_single_run_says_where_its_input_is_under_excited(run_cli, files, tmp_path):
    """A fast linear chirp logged from its first sample: the Hann windows fade its start out, so the response
    below the mode reads 3-4 dB high at a coherence of 0.98 (Welch with scipy reads the same). The console names
    the under-excited share for a single run too; a sweep designed with equal time per decade draws no warning."""
    t = np.arange(0, 60, 0.01)
    u = np.sin(2 * np.pi * (0.1 * t + 4.9 / 120 * t ** 2))
    y = simulate_plant(Plant.from_string("10/(s^2+2*s+10)"), t, u, "zero")
    chirp = tmp_path / "chirp.csv"
    np.savetxt(chirp, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    res = run_cli("freqresp", "--data", str(chirp), "--out", str(tmp_path / "c"))
    assert res.code == 0, res.err
    line = next(x for x in res.out.splitlines() if x.startswith("run quality:"))
    share = float(line.split("under-excited over ")[1].split(" %")[0])
    assert 30 <= share <= 80, line
    res = run_cli("freqresp", "--data", files["runs"][0], "--time", "t", "--input", "lat", "--output", "p",
                  "--wmin", "0.4", "--wmax", "12", "--out", str(tmp_path / "d"))
    assert res.code == 0, res.err
    assert "run quality" not in res.out and "coherent band" in res.out


@pytest.mark.parametrize(("args", "said"), [
    (["--fit-range", "1:5"], "nothing is fitted without --fit"),
    (["--fit", "k/(s+p)", "--fit-range", "10:1"], "must be LO:HI with 0 < LO < HI"),
])
def test_a_fit_range_without_a_fit_or_reversed_is_refused(run_cli, files, args, said):
    # a black-box test (session 62): both were accepted, the first silently ignored
    res = run_cli("freqresp", "--data", files["runs"][0], *args)
    lines = res.err.strip().splitlines()
    assert res.code == 2 and len(lines) == 1 and "--fit-range" in lines[0] and said in lines[0], res.err
