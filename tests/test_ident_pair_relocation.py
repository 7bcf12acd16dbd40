"""A fit caught in a nearly cancelling pair's other minimum is moved to the lower one (synth.ident.pair_relocation).

A seeded sample of ``benchmarks/pair_relocation.py``'s randomized problems (its module text: the generator, the
wrong starts, and the reference, the same record fitted from the truth's own parameters): where the fit from a
wrong start ends more than 2 noise variances of SSR above the reference, the relocated fit must end no more than
half a noise variance above it, and it must never end higher than the fit it was given.
"""

from __future__ import annotations

import json
from functools import cache

import numpy as np
import pytest

from benchmarks.pair_relocation import STARTS, problem, run, wrong_start
from synth.data import record_from_arrays
from synth.ident.identification import identify
from synth.ident.pair_relocation import pair_profile
from synth.ident.simulate import simulate_plant
from synth.ident.structure import parse_structure
from synth.plant import Plant

DT = 0.005


@cache
def _run(seed: int) -> tuple[list[dict], dict[str, tuple]]:
    """The benchmark's rows of problem ``seed`` and each start's (fit, relocated fit), computed once per process."""
    fits: dict[str, tuple] = {}
    return run(seed, fits), fits


@pytest.mark.xdist_group("pair_relocation_7")  # one worker: the evidence test reads problem 7's fits from the cache
@pytest.mark.parametrize(("seed", "caught"), [(7, 3), (14, 2), (18, 0)])
def test_relocation_reaches_the_truths_basin(seed: int, caught: int) -> None:
    """The benchmark's problems (4,000 samples each; chosen by cost). Seeds 7 and 14 have fits caught in
    another minimum (a test that nothing catches shows nothing); 18 has fits the relocation must leave
    where they are or lower."""
    rows, _ = _run(seed)
    assert sum(r["caught"] for r in rows) >= caught
    for r in rows:
        assert not r["worse"]
        if r["caught"]:
            assert r["relocated_above_reference"] <= 0.5, r


@pytest.mark.xdist_group("pair_relocation_7")
def test_the_evidence_says_what_happened() -> None:
    """Problem 7 fitted from the start with the pair cancelled far below the band (the benchmark's first start,
    ``wrong_start(truth, 0)``, by the convolution fitter), then relocated: the fits the test above judged."""
    fit, moved = _run(7)[1][STARTS[0]]
    evidence = moved.solver["pair_profile"]
    json.dumps(evidence)
    assert evidence[0]["largest_drop_noise_variances"] > 2.0
    assert "refitted from there" in evidence[-1]["note"] and moved.residual_std < fit.residual_std


def test_a_pinned_down_pair_is_not_profiled() -> None:
    """identify profiles only fits with a weakly identifiable parameter: a well-determined pair costs nothing."""
    t = np.arange(6000) * DT
    u = np.where((t % 6) < 3, 1.0, 0.0)
    y = simulate_plant(Plant.from_string("10*(s+1.5)/((s+1)*(s+6))"), t, u)
    y = y + 0.001 * np.random.default_rng(1).normal(size=t.size)
    res = identify((t, u, y), "k*(s+z)/((s+p1)*(s+p2))", average="none")
    assert not res.fit.weak and res.fit.t.size == t.size and not res.fit.periodic
    assert "pair_profile" not in res.fit.solver  # not profiled by identify ...
    assert pair_profile(record_from_arrays(t, u, y), res.fit)  # ... though it is a near pair (1.5 beside 1)


def test_identify_relocates_a_caught_whole_record_fit(monkeypatch: pytest.MonkeyPatch) -> None:
    """identify hands its whole-record fit to the relocation: a fit forced into the wrong minimum (its start
    replaced by one with the pair cancelled far below the band) comes back in the truth's basin."""
    import synth.ident.identification as identification

    p = problem(14)
    st = parse_structure(p["structure"])
    real = identification.fit_structure

    def caught(*args, **kwargs):
        kwargs.setdefault("initial", {**wrong_start(p["truth"], 0), "delay": p["delay"]})
        return real(*args, **{"solver": "convolution", **kwargs})  # IPOPT diverges from that start

    monkeypatch.setattr(identification, "fit_structure", caught)
    res = identify((p["t"], p["u"], p["y"]), st, p["delay_option"], p["sensor"], average="none")
    assert res.fit.solver["pair_profile"][-1]["refit"] == "kept: a lower residual"
    assert abs(res.fit.parameters["z"] / p["truth"]["z"] - 1) < 0.2


def test_synth_identify_says_the_fit_moved(run_cli, tmp_path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The CLI prints the relocation's note and writes its evidence to the JSON."""
    import synth.ident.identification as identification

    p = problem(14)
    path = tmp_path / "rec.csv"
    path.write_text("t,u,y\n" + "\n".join(f"{a:.4f},{b:.6g},{c:.10g}" for a, b, c in zip(p["t"], p["u"], p["y"])))
    real = identification.fit_structure

    def caught(*args, **kwargs):
        kwargs.setdefault("initial", {**wrong_start(p["truth"], 0), "delay": p["delay"]})
        return real(*args, **{"solver": "convolution", **kwargs})

    monkeypatch.setattr(identification, "fit_structure", caught)
    res = run_cli("identify", "--data", str(path), "--time", "t", "--input", "u", "--output", "y",
                  "--structure", p["structure"], "--delay", "fit", "--average", "none", "--out",
                  str(tmp_path / "out"), "--json", str(tmp_path / "r.json"))
    assert res.code == 0, res.err
    assert "note: the fit ended with a zero at" in res.out and "noise variances of SSR lower, kept" in res.out
    assert json.loads((tmp_path / "r.json").read_text())["solver"]["pair_profile"][-1]["refit"] == \
        "kept: a lower residual"

