"""Weak identifiability (issue 16, item 1): a parameter the record cannot pin down is reported as such,
with its correlation partner and interval, in the library, the JSON and the text of `synth identify`."""

from __future__ import annotations

import io
import json
from contextlib import redirect_stdout

import numpy as np

from synth.cli import main
from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

STRUCTURE = "k*(s+z)/((s+p1)*(s+p2))"
DT = 0.005
T = np.arange(0, 40, DT)
U = np.where((T % 8) < 4, 1.0, 0.0) * (T >= 2)


def _record(seed: int, cancel: bool):
    """Random plant; with ``cancel`` its zero lies within 1-3 % of the slow pole (a near pole-zero cancellation)."""
    rng = np.random.default_rng(seed)
    p_fast, p_slow = rng.uniform(5, 15), rng.uniform(0.5, 2)
    z = p_slow * rng.uniform(1.01, 1.03) if cancel else p_slow * rng.uniform(2.5, 4)
    k = p_fast * rng.uniform(1, 3)
    y = simulate_plant(Plant.from_string(f"{k}*(s+{z})/((s+{p_fast})*(s+{p_slow}))"), T, U)
    return T, U, y + 0.03 * rng.normal(size=T.size), {"z": z, "slow": p_slow}


def _slow_name(params):
    return "p1" if params["p1"] < params["p2"] else "p2"


def test_near_pole_zero_cancellation_is_reported_weak_with_its_partner_in_json_and_text(tmp_path):
    t, u, y, truth = _record(11, cancel=True)
    res = identify((t, u, y), STRUCTURE, average="none")
    weak = {w.name: w for w in res.fit.weak}
    slow = _slow_name(res.fit.parameters)
    assert set(weak) >= {"z", slow}, [w.text() for w in res.fit.weak]
    assert weak["z"].partner == slow and abs(weak["z"].correlation) > 0.99
    lo, hi = weak["z"].interval
    assert lo < truth["z"] < hi and weak["z"].std == res.fit.std["z"]
    assert "k" not in weak  # the gain is pinned down by the step's final value
    path = tmp_path / "r.csv"
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="t,u,y", comments="")
    out = io.StringIO()
    with redirect_stdout(out):
        code = main(["identify", "--data", str(path), "--time", "t", "--input", "u", "--output", "y", "--structure",
                     STRUCTURE, "--average", "none", "--no-figures", "--out", str(tmp_path / "rep"),
                     "--json", str(tmp_path / "r.json")])
    assert code == 0
    text = out.getvalue()
    assert "z (weak)" in text and f"correlation {weak['z'].correlation:+.3f} with {slow}" in text, text
    listed = json.loads((tmp_path / "r.json").read_text())["weakly_identifiable"]
    assert {d["name"] for d in listed} == set(weak)
    assert next(d for d in listed if d["name"] == "z")["partner"] == slow


def test_a_well_separated_zero_is_not_flagged():
    for seed in (12, 13):
        t, u, y, truth = _record(seed, cancel=False)
        res = identify((t, u, y), STRUCTURE, average="none")
        assert res.fit.weak == [], [w.text() for w in res.fit.weak]
        assert abs(res.fit.parameters["z"] - truth["z"]) < 4 * res.fit.std["z"]
        assert res.to_dict()["weakly_identifiable"] == []
