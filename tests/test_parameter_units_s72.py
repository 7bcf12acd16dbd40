"""Each identified parameter's unit (synth.ident.parameter_units), checked against units derived by hand, and
printed in ``synth identify``'s table and JSON (session 71's black-box finding: the table printed none)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.ident.parameter_units import parameter_units

BY_HAND = [
    ("k/(s+p)", {"k": "(rad/s)/V*rad/s", "p": "rad/s"}),           # k = DC gain * p
    ("K*exp(-Td*s)/((T1*s+1)*(T2*s+1))", {"K": "(rad/s)/V", "T1": "s", "T2": "s", "Td": "s"}),
    ("k*(1-a*s)/((s+p1)*(s+p2))", {"k": "(rad/s)/V*(rad/s)^2", "a": "s", "p1": "rad/s", "p2": "rad/s"}),
    ("k*exp(-Td*s)/(s^2+2*z*w*s+w^2)", {"k": "(rad/s)/V*(rad/s)^2", "z": "", "w": "rad/s", "Td": "s"}),
    ("1/(m*s^2+b*s+c)", {"m": "V/(rad/s)*s^2", "b": "V/(rad/s)*s", "c": "V/(rad/s)"}),  # mass, damper, spring
    ("k/s", {"k": "(rad/s)/V*rad/s"}),
    ("a*b/(s+p)", {"p": "rad/s"}),                                # a and b share one unit the formula leaves open
    ("K*exp(-0.02*s)/(T*s+1)", {"K": "(rad/s)/V", "T": "s"}),      # a fixed delay is no parameter
]


@pytest.mark.parametrize(("formula", "expected"), BY_HAND)
def test_units_agree_with_the_hand_derivation(formula, expected):
    assert parameter_units(formula, "V", "rad/s") == expected


def test_identify_prints_a_unit_column_and_writes_the_units(tmp_path, run_cli):
    from scipy import signal

    t = np.arange(0, 40, 0.01)
    u = np.floor(t / 4) % 2
    b, a, _ = signal.cont2discrete(([1.6], [1.0, 0.8]), 0.01, method="zoh")  # k/(s+p), k = 1.6, p = 0.8
    y = signal.lfilter(np.squeeze(b), a, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    path = tmp_path / "run.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    res = run_cli("identify", "--data", str(path), "--structure", "k/(s+p)", "--delay", "fit", "--input-unit", "V",
                  "--output-unit", "rad/s", "--out", str(tmp_path / "out"), "--no-figures")
    assert res.code == 0, res.err
    header = next(line for line in res.out.splitlines() if line.startswith("parameter"))
    assert header.split()[-1] == "unit"
    rows = {line.split()[0]: line.split()[-1] for line in res.out.splitlines() if line.split()[:1] in (["k"], ["p"],
                                                                                                  ["delay"])}
    assert rows == {"k": "(rad/s)/V*rad/s", "p": "rad/s", "delay": "s"}
    saved = json.loads((tmp_path / "out" / "identify.json").read_text())
    assert saved["parameter_units"] == {"k": "(rad/s)/V*rad/s", "p": "rad/s", "delay": "s", "offset": "rad/s"}
    assert saved["parameters"]["p"] == pytest.approx(0.8, rel=0.02)
