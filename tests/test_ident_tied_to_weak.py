"""A parameter the weak-identifiability rule does not flag, but correlated 0.9 or more with one it does, is
reported as tied to it: its standard error rests on the same failing linearization (synth.ident.identifiability)."""

from __future__ import annotations

import io
import json
from contextlib import redirect_stdout

import numpy as np

from benchmarks.ident_crb import DT, make_case
from synth.cli import main
from synth.ident import identify


def test_gain_tied_to_a_weak_cancelling_pair_is_reported_in_library_json_and_text(tmp_path):
    # the Cramer-Rao benchmark's case 26 (k (s+z)/((s+p1)(s+p2)), z within 15 % of p2, delay fitted, a square
    # wave whose slow mode does not settle), noise seed 1: z and p2 are flagged weak; k correlates 0.96 with
    # them, and over the benchmark's 20 seeds k scatters 2.7 times its bound while its reported standard
    # error is 7 times that scatter: not a number to read as a confident +- either. One identification, through
    # the CLI; the library's lists are checked on the same record's fit as the JSON carries it
    case = make_case(26, 16000)
    t = np.arange(case.samples) * DT
    y = 3.0 + case.y0 + case.sigma * np.random.default_rng(1).normal(size=case.samples)
    path = tmp_path / "r.csv"
    np.savetxt(path, np.column_stack([t, case.u, y]), delimiter=",", header="t,u,y", comments="")
    out = io.StringIO()
    with redirect_stdout(out):
        code = main(["identify", "--data", str(path), "--structure", case.structure, "--delay", "fit",
                     "--no-figures", "--out", str(tmp_path / "rep"), "--json", str(tmp_path / "r.json")])
    assert code == 0
    data = json.loads((tmp_path / "r.json").read_text())
    weak = {w["name"] for w in data["weakly_identifiable"]}
    tied = {x["name"]: x for x in data["tied_to_weak"]}
    assert {"z", "p2"} <= weak
    assert "k" in tied and tied["k"]["partner"] in weak and abs(tied["k"]["correlation"]) >= 0.9
    assert not set(tied) & weak
    names = [n for n in data["covariance"]["names"] if n != "offset"]
    full = np.array(data["covariance"]["matrix"])
    index = [data["covariance"]["names"].index(n) for n in names]
    cov = full[np.ix_(index, index)]
    sd = np.sqrt(np.diag(cov))
    corr = cov / np.outer(sd, sd)
    for name in names:  # exactly the unflagged parameters correlated 0.9 or more with a weak one
        strong = any(abs(corr[names.index(name), names.index(w)]) >= 0.9 for w in weak)
        assert (name in tied) == (name not in weak and strong), name
    text = out.getvalue()
    assert "k (tied to weak)" in text and f"moves with weakly identifiable {tied['k']['partner']}" in text, text


def test_nothing_is_tied_when_nothing_is_weak():
    case = make_case(40, 16000)  # delay known, seed 1: every parameter within 1.3 bounds, none weak
    t = np.arange(case.samples) * DT
    y = 3.0 + case.y0 + case.sigma * np.random.default_rng(1).normal(size=case.samples)
    fit = identify((t, case.u, y), case.structure, case.delay, compare_directions=False).fit
    assert fit.weak == [] and fit.tied == []
