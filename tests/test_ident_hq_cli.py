"""``synth hq``: the printed table, JSON keys, measured files (CSV and freqresp JSON), errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.ident.hq import hq_from_plant
from synth.plant import Plant


def test_prints_the_seed_example(run_cli):
    r = run_cli("hq", "--tf", "1/(s^2+s+1)", "--delay", "0.1")
    assert r.code == 0, r.err
    assert "w180                        3.262 rad/s" in r.out
    assert "phase delay tau_p           0.0761 s" in r.out
    assert "bandwidth_gain (+6 dB)      2.351 rad/s" in r.out
    assert "attitude response type" in r.out


@pytest.mark.parametrize(("tf", "delay", "expect"), [
    ("1/(s*(s+1))", "0.1", (3.111, 0.844, 2.149, 0.844, 0.0744)),
    ("4/(s*(0.1*s+1))", "0.05", (13.07, 5.56, 8.29, 5.56, 0.0360)),
])
def test_json_keys_and_values(run_cli, tf, delay, expect):
    r = run_cli("hq", "--tf", tf, "--delay", delay, "--json", "-")
    assert r.code == 0, r.err
    d = json.loads(r.out)
    got = [d[k] for k in ("w180", "bandwidth_phase", "bandwidth_gain", "bandwidth", "phase_delay")]
    assert np.allclose(got, expect, rtol=6e-4)
    assert d["response_type"] == "rate" and d["bandwidth_limit"] == "phase"


def test_response_type_option(run_cli):
    r = run_cli("hq", "--tf", "(s/2+1)/(s*(s/6+1))", "--delay", "0.1", "--response-type", "attitude", "--json", "-")
    d = json.loads(r.out)
    assert d["bandwidth"] == d["bandwidth_phase"] > d["bandwidth_gain"]


def _measured(tmp_path, fmt):
    G = Plant.from_string("1/(s*(s+1))", delay=0.1)
    w = np.logspace(-1, 1.5, 120)
    H = G.freqresp(w)
    coh = np.full(w.size, 0.9)
    mag, ph = 20 * np.log10(np.abs(H)), np.degrees(np.unwrap(np.angle(H)))
    if fmt == "csv":
        p = tmp_path / "roll.csv"
        np.savetxt(p, np.column_stack([w, mag, ph, coh]), delimiter=",", header="w,mag_db,phase_deg,coherence",
                   comments="")
    else:
        p = tmp_path / "roll.json"
        p.write_text(json.dumps({"generator": "synth", "w": w.tolist(), "magnitude_db": mag.tolist(),
                                 "phase_deg": ph.tolist(), "coherence": coh.tolist(), "averages": 12}))
    return p, G


@pytest.mark.parametrize("fmt", ["csv", "json"])
def test_measured_file(run_cli, tmp_path, fmt):
    p, G = _measured(tmp_path, fmt)
    r = run_cli("hq", "--frd", str(p), "--averages", "12", "--json", "-") if fmt == "csv" else \
        run_cli("hq", "--frd", str(p), "--json", "-")
    assert r.code == 0, r.err
    d = json.loads(r.out)
    exact = hq_from_plant(G)
    assert d["w180"] == pytest.approx(exact.w180, rel=2e-3)
    assert d["source"] == "measured" and d["uncertainty"]["w180"] > 0
    e = np.sqrt(0.1) / (np.sqrt(0.9) * np.sqrt(24))  # n_d = 12 from the option or the JSON
    slope = 1 / (1 + exact.w180**2) + 0.1
    assert d["uncertainty"]["w180"] == pytest.approx(e / slope, rel=0.02)


def test_out_folder_and_table_uncertainty(run_cli, tmp_path):
    p, _ = _measured(tmp_path, "csv")
    out = tmp_path / "report"
    r = run_cli("hq", "--frd", str(p), "--averages", "12", "--out", str(out))
    assert r.code == 0, r.err
    assert "+-" in r.out
    assert (out / "hq_bode.png").stat().st_size > 10_000
    d = json.loads((out / "hq.json").read_text())
    assert len(d["curves"]["w"]) == 120


@pytest.mark.parametrize(("args", "content", "match"), [
    (["--tf", "1/(s^2+s"], None, "--tf"),
    (["--tf", "1/(s^2+s+1)", "--all-points"], None, "--all-points: applies to a measured response"),
    (["--frd", "{f}"], "w,mag_db\n1,0\n2,1\n", "column 'phase_deg' not found"),
    (["--frd", "{f}"], "w,mag_db,phase_deg\n1,0,-90\n2,nan,-100\n3,1,-110\n4,1,-120\n", "'mag_db': 1 value"),
    (["--frd", "{f}"], "w,mag_db,phase_deg\n1,0,-90\n3,0,-100\n2,1,-110\n4,1,-120\n", "increase strictly"),
    (["--frd", "{f}", "--averages", "0"], "w,mag_db,phase_deg,coherence\n1,0,-90,1\n2,0,-100,1\n3,1,-110,1\n4,1,-120,1\n",
     "averages must be >= 1"),
])
def test_bad_input_one_line_exit_2(run_cli, tmp_path, args, content, match):
    f = tmp_path / "bad.csv"
    if content is not None:
        f.write_text(content)
    r = run_cli("hq", *[a.format(f=f) for a in args])
    assert r.code == 2
    assert match in r.err and len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err


def test_missing_file_and_refuses_to_overwrite(run_cli, tmp_path):
    r = run_cli("hq", "--frd", str(tmp_path / "nope.csv"))
    assert r.code == 2 and "file not found" in r.err
    mine = tmp_path / "mine.json"
    mine.write_text("my notes")
    r = run_cli("hq", "--tf", "1/(s*(s+1))", "--delay", "0.1", "--json", str(mine))
    assert r.code == 2 and "not overwriting" in r.err and mine.read_text() == "my notes"


def test_frd_from_freqresp_uses_its_recorded_averaging_count(run_cli, tmp_path):
    """The issue: hq read freqresp's JSON with n_d = 1 (w180 +- 3.2 instead of +- 0.71)."""
    from synth.ident.simulate import simulate_plant
    from synth.ident.sweep_design import design_sweep

    G = Plant.from_string("31.6*s/((s+0.49)*(s+2.30))", delay=0.041)   # roll rate; hq reads the attitude p/s
    rng = np.random.default_rng(11)
    runs = []
    for k in range(2):
        t, u = design_sweep(0.4, 12.0).signal(1.0, 50.0)
        y = simulate_plant(G, t, u, "zero")
        y = y + 0.2 * np.std(y) * rng.standard_normal(t.size)
        p = tmp_path / f"run{k}.csv"
        np.savetxt(p, np.c_[t, u, y], delimiter=",", header="t,lat,p", comments="")
        runs += ["--data", str(p)]
    fr = tmp_path / "roll.json"
    assert run_cli("freqresp", *runs, "--wmin", "0.4", "--wmax", "12", "--rate-to-attitude", "--json", str(fr)).code == 0
    saved = json.loads(fr.read_text())
    recorded = json.loads(run_cli("hq", "--frd", str(fr), "--json", "-").out)
    single = json.loads(run_cli("hq", "--frd", str(fr), "--averages", "1", "--json", "-").out)
    w, n_d = np.array(saved["w"]), np.array(saved["n_averages"])
    nd_w180 = np.interp(np.log(recorded["w180"]), np.log(w), n_d)      # the count at w180, interpolated in log w
    assert recorded["w180"] == single["w180"] and nd_w180 > 9
    # the coherence's error over sqrt(n_d) = 6.2 (the slope's window, hq.crossing_sigma, depends on that error too)
    assert recorded["uncertainty"]["w180"] < single["uncertainty"]["w180"] / 4
    assert not any("n_d = 1 assumed" in note for note in recorded["notes"])
    assert f"averaging count per frequency: n_d = {nd_w180:.3g} at w180" in recorded["notes"]


def test_frd_from_freqresp_is_read_within_its_coherent_band(run_cli, tmp_path):
    """A freqresp JSON keeps every frequency it estimated, trusted or not; hq reads only its coherent band. A
    black-box test's record (an integrating attitude response behind 70 ms, swept 2-45 rad/s) had a phase
    unwrapped from leakage below the band: w180 0.114 rad/s and tau_p 39.2 s instead of 11.6 rad/s and 0.049 s.
    Here the points below the band carry a phase that falls 360 deg over a decade (as that leakage did)."""
    import json

    import numpy as np

    from synth.ident.hq import hq_from_plant
    from synth.plant import Plant

    G = Plant.from_string("11.87/(s*(s+12.22))", delay=0.0695)
    w = np.geomspace(0.06, 60, 120)
    H = G.freqresp(w)
    low = w < 2.0
    H[low] = np.abs(H[low]) * np.exp(1j * (np.angle(H[low]) - 2 * np.pi * np.log10(2.0 / w[low])))
    coherence = np.where(low, 0.5, 0.99)
    doc = {"w": w.tolist(), "magnitude_db": (20 * np.log10(np.abs(H))).tolist(),
           "phase_deg": np.degrees(np.angle(H)).tolist(), "coherence": coherence.tolist(),
           "n_averages": [10.0] * w.size, "coherent_band": {"w_min": float(w[~low][0]), "w_max": float(w[-1])}}
    path = tmp_path / "fr.json"
    path.write_text(json.dumps(doc))
    exact = hq_from_plant(G)
    res = run_cli("hq", "--frd", str(path), "--json", "-")
    assert res.code == 0, res.err
    got = json.loads(res.out)
    assert got["w180"] == pytest.approx(exact.w180, rel=2e-3)
    assert got["phase_delay"] == pytest.approx(exact.phase_delay, rel=2e-2)
    assert got["frequency_band_used"][0] == pytest.approx(float(w[~low][0]))
    assert "used the coherent band" in got["notes"][0]
    every = json.loads(run_cli("hq", "--frd", str(path), "--json", "-", "--all-points").out)
    assert every["w180"] != pytest.approx(exact.w180, rel=0.05)  # the old answer: undefined here
