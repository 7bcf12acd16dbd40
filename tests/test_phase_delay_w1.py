"""Phase delay at a stated w1 (issue 19, item 5; seed 2 sec. 6.2, eq. 2-4) and ``synth hq --w1``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.errors import DataError
from synth.ident.hq import hq_from_frd, hq_from_plant
from synth.ident.phase_delay import phase_delay_at, phase_delay_from_phase
from synth.plant import Plant

EQ4 = "1/(s^2+s+1)"  # the sweep report's eq. 4, with a 0.1 s delay


@pytest.fixture(scope="module")
def eq4():
    G = Plant.from_string(EQ4, delay=0.1)
    return G, hq_from_plant(G)


def test_the_reports_example(eq4):
    G, m = eq4
    far = phase_delay_at(m, 20.0, G)  # "well above twice w180": close to the 0.1 s delay
    assert far.phase_delay == pytest.approx(0.0975, abs=5e-5)
    assert far.phase_delay == pytest.approx(0.1, rel=0.03)
    near = phase_delay_at(m, 6.6, G)  # the report's 2 w180 = 6.6 rad/s: 0.077 s
    assert round(near.phase_delay, 3) == 0.077
    assert m.w180 == pytest.approx(3.262, abs=1e-3)  # the report reads about 3.3
    at2 = phase_delay_at(m, 2 * m.w180, G)
    assert at2.phase_delay == pytest.approx(m.phase_delay, rel=1e-12) and at2.notes == ()
    assert far.phase_delay_2w180 == pytest.approx(0.0761, abs=5e-5)
    assert "compare values only at the same w1" in far.notes[0]


def test_delay_alone_gives_the_delay_at_every_w1():
    G = Plant.from_string("1/s^2", delay=0.05)  # phase = -180 deg - 0.05 w exactly
    m = hq_from_plant(G)
    for w1 in (1.0, 7.0, 40.0):
        assert phase_delay_at(m, w1, G).phase_delay == pytest.approx(0.05, rel=1e-9)
    assert phase_delay_from_phase(10.0, -180.0) == 0.0


def test_measured_response_interpolated_and_line(eq4):
    G, _ = eq4
    w = np.logspace(-1, 1.5, 300)
    m = hq_from_frd(w, G.freqresp(w), phase_fit="raw")
    r = phase_delay_at(m, 20.0)
    assert r.method == "raw" and r.phase_delay == pytest.approx(0.0975, rel=2e-3)
    with pytest.raises(DataError, match="w1 = 50 rad/s lies outside the measured response"):
        phase_delay_at(m, 50.0)
    short = w[w <= 8.0]
    ml = hq_from_frd(short, G.freqresp(short), phase_fit="line")  # 2 w180 = 6.5 inside; the line is fitted
    beyond = phase_delay_at(ml, 12.0)
    assert beyond.method == "line" and "extrapolated" in beyond.notes[0]
    assert np.isfinite(beyond.phase_delay)


def test_below_w180_is_stated(eq4):
    G, m = eq4
    r = phase_delay_at(m, 2.0, G)
    assert "is not above w180" in r.notes[0]


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_w1(eq4, bad):
    G, m = eq4
    with pytest.raises(DataError, match="w1 must be a positive frequency"):
        phase_delay_at(m, bad, G)


def test_cli_w1_model(run_cli):
    r = run_cli("hq", "--tf", EQ4, "--delay", "0.1", "--w1", "20")
    assert r.code == 0, r.err
    assert "phase delay at w1 = 20      0.0975 s" in r.out
    r = run_cli("hq", "--tf", EQ4, "--delay", "0.1", "--w1", "6.6", "--json", "-")
    d = json.loads(r.out)["phase_delay_at_w1"]
    assert round(d["phase_delay"], 3) == 0.077 and d["method"] == "exact" and d["units"]["phase_delay"] == "s"


def test_cli_w1_measured_and_out(run_cli, tmp_path, eq4):
    G, _ = eq4
    w = np.logspace(-1, 1.5, 300)
    H = G.freqresp(w)
    p = tmp_path / "frd.csv"
    np.savetxt(p, np.column_stack([w, 20 * np.log10(np.abs(H)), np.unwrap(np.angle(H)) * 180 / np.pi]),
               delimiter=",", header="w,mag_db,phase_deg", comments="")
    r = run_cli("hq", "--frd", str(p), "--w1", "20", "--phase-fit", "raw", "--out", str(tmp_path / "o"))
    assert r.code == 0, r.err
    d = json.loads((tmp_path / "o" / "hq.json").read_text())
    assert d["phase_delay_at_w1"]["phase_delay"] == pytest.approx(0.0975, rel=2e-3)
    assert "curves" in d  # the curves are still there
    r = run_cli("hq", "--frd", str(p), "--w1", "100", "--phase-fit", "raw")
    assert r.code == 2 and "--w1: w1 = 100 rad/s lies outside the measured response" in r.err
    assert len(r.err.strip().splitlines()) == 1


@pytest.mark.parametrize("value", ["-3", "0", "nan", "x"])
def test_cli_bad_w1_one_line_exit_2(run_cli, value):
    r = run_cli("hq", "--tf", EQ4, "--w1", value)
    assert r.code == 2 and "--w1" in r.err.strip().splitlines()[-1]  # argparse's own type error adds its usage
