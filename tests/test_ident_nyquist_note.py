"""A fit whose plant has a pole or zero beyond the record's Nyquist frequency says so (library and CLI): samples
cannot resolve it, and the model says nothing of the plant above that frequency (found by a helper: the real
Silverbox, cut to 65,000 samples, was once fitted with w = 3392 rad/s against its 1917 rad/s Nyquist frequency
and reported as a 76.3 % fit without a word)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.ident.simulate import simulate_plant
from synth.ident.timefit import fit_structure
from synth.plant import Plant

T = np.arange(0, 6, 0.01)                     # Nyquist frequency 314.2 rad/s
U = np.where((T % 2) >= 1, 1.0, 0.0)


def _record(truth: str):
    y = simulate_plant(Plant.from_string(truth), T, U) + 0.001 * np.random.default_rng(0).normal(size=T.size)
    return record_from_arrays(T, U, y)


def test_a_second_pole_fitted_beyond_nyquist_is_noted_with_where_it_is():
    # a first-order plant fitted with two poles: the second runs off far beyond what 10 ms samples resolve
    fit = fit_structure(_record("2/(s+3)"), "k/((s+p1)*(s+p2))")
    fast = max(fit.parameters["p1"], fit.parameters["p2"])
    assert fast > np.pi / 0.01
    note = fit.solver["nyquist_note"]
    assert note.startswith(f"the fitted plant has a pole at {fast:.4g} rad/s, beyond the record's Nyquist frequency "
                           "314.2 rad/s: samples 0.01 s apart cannot resolve it"), note
    assert "nyquist_note" in fit.to_dict()["solver"]


def test_a_fit_inside_nyquist_has_no_note():
    fit = fit_structure(_record("2*30/((s+3)*(s+30))"), "k/((s+p1)*(s+p2))")
    assert max(fit.parameters["p1"], fit.parameters["p2"]) == pytest.approx(30, rel=0.02)
    assert "nyquist_note" not in fit.solver


def test_the_cli_prints_the_note(run_cli, tmp_path):
    rec = _record("2/(s+3)")
    path = tmp_path / "r.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.u, rec.y]), delimiter=",", header="t,u,y", comments="")
    res = run_cli("identify", "--data", str(path), "--structure", "k/((s+p1)*(s+p2))", "--average", "none",
                  "--no-figures", "--out", str(tmp_path / "rep"), "--json", str(tmp_path / "r.json"))
    assert res.code == 0, res.err
    assert "note: the fitted plant has a pole at " in res.out and "Nyquist frequency 314.2 rad/s" in res.out
    assert "Nyquist" in json.loads((tmp_path / "r.json").read_text())["solver"]["nyquist_note"]
