"""A candidate whose least-squares fit needs a sign no such effect has is not the explanation.

A first-order model against a record that leads it by half a sample (a 1 % gap, noise-free) was "explained by supply
sag (sag = -0.498)": a supply that rises when the command steps up, which no battery does; the fit used the basis as
a free correction. The candidate is now reported with the reason and never accepted. The output at rest before the
first step (exactly 0, as an encoder reads a motor that stands) was also reported as "clipped"."""

from __future__ import annotations

import numpy as np

from synth.data import record_from_arrays
from synth.gap.diagnose import diagnose
from synth.plant import Plant


def test_a_negative_supply_sag_is_not_the_verdict_and_rest_is_not_a_clip() -> None:
    t = np.arange(0, 10, 0.01)
    u = np.where(t > 2, 1.0, 0.0)
    y = 0.01 * np.convolve(u, np.exp(-t))[:t.size]   # 1/(s+1), the current sample included: half a sample ahead
    dg = diagnose(Plant.from_string("1/(s+1)"), record_from_arrays(t, u, y), candidates=["supply_sag", "drift"],
                  n_null=5)
    sag = next(e for e in dg.attribution.effects if e.effect == "supply_sag")
    assert sag.parameters["sag"] < 0 and sag.shrinkage > 0.9          # it does fit, with the wrong sign
    assert not sag.accepted and "wrong sign" in sag.unphysical
    assert dg.verdict["effects"] != ["supply_sag"] and "supply sag" not in dg.summary.split(".")[0]
    reason = next(n["reason"] for n in dg.verdict["not_carried"] if n["effect"] == "supply_sag")
    assert "not a physical supply sag" in reason
    entry = next(e for e in dg.to_dict()["effects"] if e["effect"] == "supply_sag")
    assert entry["unphysical"].startswith("sag = -0.") and not entry["accepted"]
    assert dg.verdict["observed"] == [] and "clipped" not in dg.summary
