"""``sensitivity``'s ``met_up_to`` is the highest frequency up to which ``|S| <= max_db`` holds from the band's low
end, met or not (it was null whenever the requirement was met), against a dense grid written here."""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements.sensitivity import Sensitivity


def _first_exceedance(plant: Plant, kp: float, limit_db: float, lo: float) -> float | None:
    """First frequency >= lo where |1/(1 + kp G(jw))| rises above the limit, on 20,000 points per decade."""
    w = np.geomspace(max(lo, 1e-4), 1e5, 20000 * 9)
    g = np.polyval(plant.num, 1j * w) / np.polyval(plant.den, 1j * w)
    above = np.flatnonzero(20 * np.log10(np.abs(1 / (1 + kp * g))) > limit_db)
    if above.size == 0:
        return None
    return None if above[0] == 0 else float(w[above[0]])


def test_met_up_to_is_the_first_crossing_of_the_bound_met_or_not():
    rng = np.random.default_rng(71)
    checked = met = 0
    for _ in range(40):
        p1, p2 = 10 ** rng.uniform(-1, 1, 2)
        gain = 10 ** rng.uniform(0, 1.5)
        plant = Plant.from_string(f"{gain:.6g}/((s+{p1:.6g})*(s+{p2:.6g}))")
        kp = 10 ** rng.uniform(-0.5, 1)
        limit = -float(rng.uniform(3, 20))
        top = 10 ** rng.uniform(-1, 0.5)
        r = Sensitivity(type="sensitivity", max_db=limit, band=(0, top)).evaluate(Loop(plant, Controller("P", {"kp": kp})))
        reference = _first_exceedance(plant, kp, limit, 1e-4)
        if reference is None:
            assert r.details["met_up_to"] is None  # fails at the low end already
            continue
        checked += 1
        met += r.met
        assert r.met == (reference > top)
        assert r.details["met_up_to"] == pytest.approx(reference, rel=1e-3)
    assert checked >= 20 and met >= 5
