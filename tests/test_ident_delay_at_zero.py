"""A fitted delay whose optimum is 0 (a plant without one, fitted with ``--delay fit``): IPOPT relaxes its bounds by
a relative 1e-8 and returned -1e-8 s, which no plant accepts, so ``synth freqresp --fit 0/2 --delay fit`` on a sweep
of a delay-free plant ended "fit failed: delay must be a finite number >= 0 s, got -9.999902724565971e-09". The
delay is kept within its bounds."""

from __future__ import annotations

import json

import numpy as np
from scipy.signal import lsim


def test_a_delay_free_sweep_fits_with_delay_zero_not_a_failure(run_cli, tmp_path) -> None:
    fs, rng = 100.0, np.random.default_rng(0)
    t = np.arange(0, 60, 1 / fs)
    u = np.sin(np.cumsum(2 * np.pi * (0.1 + 4.9 * t / 60)) / fs)  # 0.1 -> 5 Hz in 60 s
    y = lsim(([10.0], [1.0, 2.0, 10.0]), u, t)[1] + 0.01 * rng.normal(size=t.size)
    data = tmp_path / "sweep.csv"
    data.write_text("t,u,y\n" + "".join(f"{a},{b},{c}\n" for a, b, c in zip(t, u, y)))
    res = run_cli("freqresp", "--data", str(data), "--time", "t", "--input", "u", "--output", "y", "--fit", "0/2",
                  "--delay", "fit", "--out", str(tmp_path / "out"))
    assert res.code == 0, res.out + res.err
    fit = json.loads((tmp_path / "out" / "result.json").read_text())["fit"]
    assert fit["parameters"]["delay"] == 0.0


def test_a_record_too_short_for_the_default_band_says_so(run_cli, tmp_path) -> None:
    t = np.arange(20) / 100.0
    data = tmp_path / "short.csv"
    data.write_text("t,u,y\n" + "".join(f"{a},{np.sin(9 * a)},{np.cos(9 * a)}\n" for a in t))
    res = run_cli("freqresp", "--data", str(data), "--time", "t", "--input", "u", "--output", "y",
                  "--out", str(tmp_path / "out"))
    assert res.code == 2 and "Traceback" not in res.err and len(res.err.strip().splitlines()) == 1
    assert "too short for a frequency response: its 20 samples" in res.err and "w_min < w_max" not in res.err
