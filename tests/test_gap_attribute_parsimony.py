"""The sub-sample lag (the verdict rules follow)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.gap.effects import make_effect
from synth.gap.screen import screen_effect
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

# the DC-motor drive of the withheld-effect benchmark, its nominal model 2-4 % off, a step train of 16 levels
TRUE = Plant.from_string("245.6/(0.151*s+1)^2", delay=0.032)
NOMINAL = Plant.from_string("252/(0.02205*s^2+0.292*s+1)", delay=0.032)
DT = 0.01
T = np.arange(0, 12.8, DT)
LEVELS = np.array([3.1, 8.9, 4.2, 7.6, 2.5, 9.7, 5.0, 8.1, 3.6, 9.2, 2.2, 7.0, 4.6, 9.9, 3.0, 8.4])
U = LEVELS[np.minimum((T // 0.8).astype(int), LEVELS.size - 1)]
NOISE = 8.0


def _record(effect: str, params: dict[str, float], seed: int):
    clean = make_effect(effect).apply(TRUE, T, U, params)
    return record_from_arrays(T, U, clean + NOISE * np.random.default_rng(seed).normal(size=T.size))


def _by_label(dg):
    return {e.effect: e for e in dg.effects}


# --------------------------------------------------------------------------------------------- sub-sample lag
def test_the_lag_search_reaches_a_lag_shorter_than_the_sample_time():
    t = np.arange(0, 6, DT)
    u = np.where((t % 2) >= 1, 1.0, 0.0)
    plant = Plant.from_string("2/(0.2*s+1)")
    y = make_effect("lag").apply(plant, t, u, {"tau": 0.3 * DT})
    assert np.sqrt(np.mean((y - simulate_plant(plant, t, u)) ** 2)) > 1e-3  # visible in the output
    sc = screen_effect(make_effect("lag"), [("nominal", plant)], t, u, y, t, u)
    assert sc.params["tau"] == pytest.approx(0.3 * DT, rel=0.1)
    assert sc.ssr < 1e-8
