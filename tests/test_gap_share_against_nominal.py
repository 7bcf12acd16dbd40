"""An effect that beats only a re-fit which made the held-out error worse does not explain the gap (session 44).

Found by a black-box test on the real Silverbox record (a Duffing oscillator): on the first 32,000 samples of its
"arrow" part, the re-fit of the nominal coefficients made the held-out error worse (shrinkage -0.57), and duffing,
significant against that re-fit, was named as the explanation while it "removes -3 % of the held-out error".
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

SILVERBOX = Path(__file__).resolve().parents[2] / "shared" / "data" / "silverbox_duffing" / "SNLS80mV.csv"


def test_no_effect_is_named_that_does_worse_than_the_nominal_model(run_cli, tmp_path) -> None:
    if not SILVERBOX.exists():
        pytest.skip(f"needs the shared data file {SILVERBOX} (present in CI and the dev workspace)")
    v = np.genfromtxt(SILVERBOX, delimiter=",", skip_header=1, usecols=(0, 1))[100:32100]
    data = tmp_path / "arrow.csv"
    t = np.arange(v.shape[0]) * 0.0016384  # the README's sample interval (610.35 Hz)
    np.savetxt(data, np.column_stack([t, v]), delimiter=",", header="t,V1,V2", comments="", fmt="%.9g")
    out = tmp_path / "d.json"
    r = run_cli("diagnose", "--plant", "1.919e5/(s^2+44.18*s+1.977e5)", "--data", str(data), "--input", "V1",
                "--output", "V2", "--candidates", "duffing,static_nonlinearity,saturation,delay,resonance",
                "--no-report", "--json", str(out), "-q")
    assert r.code in (0, 1), r.err
    d = json.loads(out.read_text())
    j_nominal = d["attribution"]["j_nominal"]
    named = set(d["verdict"]["effects"]) - {"parameter_mismatch"}
    for e in d["effects"]:
        if e["effect"] in named or e["accepted"]:
            assert e["share_of_gap"] > 0 and e["j_heldout"] < j_nominal, e
    duffing = next(e for e in d["effects"] if e["effect"] == "duffing")
    if duffing["j_heldout"] >= j_nominal:  # as on this record today: said why it is not the verdict
        assert "duffing" not in named
        reason = next(n["reason"] for n in d["verdict"]["not_carried"] if n["effect"] == "duffing")
        assert "no lower than the nominal model's" in reason


def test_burn_in_is_left_out_of_the_gaps_size_and_place() -> None:
    """`diagnose --burn-in 5` on the real HSM150 record measured 68 % NRMSE 'mostly in t = 0-2.6 s', the start-up it
    was asked to leave out (13 % after it, by a black-box test's own computation)."""
    from synth.data import record_from_arrays
    from synth.gap.where.localize import localize_gap
    from synth.ident.simulate import simulate_plant
    from synth.plant import Plant

    t = np.arange(0.0, 12.0, 0.005)
    u = np.where((t % 4) >= 2, 1.0, 0.0)
    G = Plant.from_string("1/(0.2*s+1)")
    start = np.where(t < 1.0, 3.0 * np.exp(-t / 0.2), 0.0)  # a start-up from another state, gone by t = 1 s
    y = simulate_plant(G, t, u) + start + 0.01 * np.random.default_rng(2).normal(size=t.size)
    rec = record_from_arrays(t, u, y)
    whole, after = localize_gap(G, rec), localize_gap(G, rec, burn_in=1.0)
    assert whole.residual.nrmse > 0.3
    assert after.residual.nrmse < 0.05 and after.residual.t[0] >= 1.0 and after.residual.t.size == np.sum(t >= 1.0)
