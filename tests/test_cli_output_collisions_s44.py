"""Defects a black-box test found in sweep-design, hq and tradeoff (session 44): outputs that overwrote each other or an
input, an amplitude reduction scaled back up, sizes and sweeps that gave tracebacks, options silently ignored."""

from __future__ import annotations

import json

import numpy as np
import pytest

P_DELAY = """\
name: p_delay
plant:
  tf: "5/((s+1)*(0.1*s+1))"
  delay: 0.05
controller:
  type: P
  bounds: {kp: [0, 20]}
requirements:
  - {type: margins, phase_margin_deg: 45, label: pm}
  - {type: bandwidth, min: 2, label: bw}
objective: {maximize: bandwidth}
"""


def _one_line(r) -> str:
    assert r.code == 2, (r.out, r.err)
    assert "Traceback" not in r.err and len(r.err.strip().splitlines()) == 1, r.err
    return r.err


def _sweep(path):
    data = np.loadtxt(path, delimiter=",", skiprows=2)
    return data[:, 0], data[:, 1]


@pytest.mark.parametrize("reduce_above_hz", [0.01, 0.07, 0.08])
def test_reduction_near_or_below_w_min_is_not_scaled_back_up(run_cli, tmp_path, reduce_above_hz):
    """0.4-12 rad/s (f_min 0.064 Hz): the low cycles under the reduction were normalized to the full amplitude, so
    0.01 Hz gave 1.0 everywhere and 0.08 Hz 0.575 above 0.3 Hz, for 0.5 asked."""
    out = tmp_path / "s.csv"
    r = run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--reduce-above", str(reduce_above_hz),
                "--out", str(out))
    assert r.code == 0, r.err
    t, u = _sweep(out)
    late = (t > 0.6 * t[-1]) & (t < t[-1] - 4.0)  # above 1 rad/s, before the fade-out
    assert 0.49 < np.max(np.abs(u[late])) <= 0.5 + 1e-9
    assert np.max(np.abs(u)) <= 1.0 + 1e-9
    if reduce_above_hz < 0.064:
        assert np.max(np.abs(u)) <= 0.5 + 1e-9
        assert "low-frequency cycles are reduced too" in r.out


def test_sweep_design_refuses_what_it_cannot_write(run_cli, tmp_path):
    out = tmp_path / "roll.csv"
    err = _one_line(run_cli("sweep-design", "--w-min", "0.4", "--w-max", "1e6", "--out", str(out)))
    assert "samples" in err and "--w-min/--w-max" in err and not out.exists()
    err = _one_line(run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--out", str(out), "--json", str(out)))
    assert "two outputs" in err and not out.exists()
    err = _one_line(run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--reduce-to", "0.3", "--out", str(out)))
    assert "--reduce-to" in err and "--reduce-above" in err
    err = _one_line(run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--name", "time_s", "--out", str(out)))
    assert "--name" in err
    err = _one_line(run_cli("sweep-design", "--w-min", "0.4", "--w-max", "12", "--sample-rate", "3", "--out", str(out)))
    assert "2 f_max = 3.82 Hz" in err
    assert not out.exists()


def test_hq_json_onto_its_own_input_is_refused(run_cli, tmp_path):
    w = np.logspace(-1, 1, 40)
    H = 1 / (1j * w * (1j * w + 1))
    frd = tmp_path / "fr.csv"
    np.savetxt(frd, np.column_stack([w, 20 * np.log10(abs(H)), np.degrees(np.unwrap(np.angle(H))) - 0.0]),
               delimiter=",", header="w,mag_db,phase_deg", comments="")
    before = frd.read_bytes()
    err = _one_line(run_cli("hq", "--frd", str(frd), "--json", str(frd)))
    assert "input" in err and frd.read_bytes() == before


def test_tradeoff_sweeps_of_one_value_and_a_json_inside_its_folder(run_cli, tmp_path):
    spec = tmp_path / "p_delay.yaml"
    spec.write_text(P_DELAY)
    out = tmp_path / "td"
    err = _one_line(run_cli("tradeoff", str(spec), "--sweep", "requirements.pm.phase_margin_deg=20,30",
                            "--sweep", "requirements.margins.phase_margin_deg=40,50", "--out", str(out), "-q"))
    assert "name the same value" in err
    err = _one_line(run_cli("tradeoff", str(spec), "--sweep", "requirements.pm.phase_margin_deg=40,,50",
                            "--out", str(out), "-q"))
    assert "empty item" in err
    err = _one_line(run_cli("tradeoff", str(spec), "--sweep", "requirements.pm.phase_margin_deg=40,50",
                            "--out", str(out), "--json", str(out / "tradeoff.csv"), "-q"))
    assert "two outputs" in err and not out.exists()
    r = run_cli("tradeoff", str(spec), "--sweep", "requirements.pm.phase_margin_deg=40,50",
                "--sweep", "requirements.bw.min=1,2", "--out", str(out), "--json", str(tmp_path / "t.json"), "-q")
    assert r.code == 0, r.err
    points = json.loads((tmp_path / "t.json").read_text())["points"]
    assert len(points) == 4
