"""A step train whose cycle-average fit meets NaN (black-box helper, session 70): the whole record is fitted, and
neither a traceback nor casadi's warnings reach the user."""

from __future__ import annotations

import json

import numpy as np
import scipy.signal as sig

from synth.cli import main


def _record(path, seed):
    """0.1/((s + 0.05)(s + 2)) under a 0/1 train of 1 s holds starting low, 5,000 samples at 2 ms, noise 0.01."""
    dt, n = 0.002, 5000
    t = np.arange(n) * dt
    u = (np.floor(t / 1.0) % 2).astype(float)
    a, b, c, d, _ = sig.cont2discrete(sig.tf2ss([0.1], [1.0, 2.05, 0.1]), dt, method="zoh")
    y = sig.dlsim((a, b, c, d, dt), u)[1].ravel() + 0.01 * np.random.default_rng(seed).normal(size=n)
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="t,u,y", comments="")


def test_a_nan_cycle_average_falls_back_to_the_whole_record(tmp_path, capfd):
    """The fit of the 4-cycle average stopped with Invalid_Number_Detected; its NaN residuals reached the
    residual-whiteness test, whose least squares raised LinAlgError: a 26-line traceback on 5 of 8 noise seeds."""
    data, out = tmp_path / "r.csv", tmp_path / "result.json"
    _record(data, 0)
    code = main(["identify", "--data", str(data), "--time", "t", "--input", "u", "--output", "y",
                 "--structure", "k/((s+p1)*(s+p2))", "--no-figures", "--out", str(tmp_path / "o"), "--json", str(out)])
    captured = capfd.readouterr()
    assert code == 0
    assert "Traceback" not in captured.err and "Failed to calculate multipliers" not in captured.err
    result = json.loads(out.read_text())
    for name, value in {"k": 0.1, "p1": 0.05, "p2": 2.0}.items():
        lo, hi = result["ci95"][name]
        assert lo <= value <= hi, (name, result["parameters"][name], lo, hi)
