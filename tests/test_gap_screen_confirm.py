"""Which screened candidates are confirmed jointly: the screen's linearized denominator step can hide a large effect."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.gap.attribution.candidates import confirmed_candidates
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.attribution.refit import fit_augmented
from synth.gap.attribution.screen import screen_effect
from synth.gap.effects import make_effect
from synth.plant import Plant

# a DC-motor drive (two poles near 6.8 rad/s), its nominal model a few % off, and an extra lag of 0.136 s (close to
# the plant's own time constants) large enough that the re-fit alone stays 6 noise variances above the floor
TRUE = Plant.from_string("1.176e4/((s+6.8)*(s+7.1))", delay=0.032)
NOMINAL = Plant.from_string("1.129e4/((s+6.863)*(s+6.685))", delay=0.032)
DT = 0.01
T = np.arange(0.0, 12.8, DT)
LEVELS = np.array([4.6, 8.9, 3.2, 7.6, 2.8, 9.4, 5.0, 8.1, 3.6, 9.2, 2.9, 7.0, 4.6, 9.1, 3.0, 8.4])
U = LEVELS[np.minimum((T // 0.8).astype(int), LEVELS.size - 1)]
TAU = 0.136


@pytest.fixture(scope="module")
def record():
    clean = make_effect("lag").apply(TRUE, T, U, {"tau": TAU})
    return record_from_arrays(T, U, clean + 3.0 * np.random.default_rng(5).normal(size=T.size))


def test_the_held_denominator_ranking_is_confirmed_when_the_step_ranking_misses_it():
    S = type("S", (), {})

    def sc(ssr, held):
        s = S()
        s.ssr, s.ssr_held = ssr, held
        return (None, s)

    ranked = [sc(1.0, 50.0), sc(1.0, 40.0), sc(1.0, 45.0), sc(1.0, 1.1), sc(2.0, np.inf)]
    assert confirmed_candidates(ranked, 3) == [0, 1, 2, 3]
    assert confirmed_candidates(ranked[:3], 3) == [0, 1, 2]  # already among the first: nothing added
    assert confirmed_candidates([sc(1.0, np.inf)], 3) == [0]


def test_a_large_lag_the_step_screen_cannot_rank_is_still_found(record):
    k = record.n // 2
    t, u, y = record.t[:k], record.u[:k], record.y[:k]
    refit = fit_augmented(NOMINAL, t, u, y)
    bases = [("nominal", NOMINAL), ("refit", refit.plant)]
    lag = screen_effect(make_effect("lag"), bases, t, u, y, record.t, record.u)
    drift = screen_effect(make_effect("drift"), bases, t, u, y, record.t, record.u)
    # with the Gauss-Newton step every candidate screens alike (the static map a little ahead of the lag); with the
    # denominator held the lag is far ahead
    assert lag.ssr > 0.9 * drift.ssr
    assert lag.ssr_held < 0.2 * drift.ssr_held
    assert lag.params_held["tau"] == pytest.approx(TAU, rel=0.3)
    dg = diagnose_effects(NOMINAL, record,
                          options=DiagnoseOptions(candidates=["drift", "static_nonlinearity", "backlash", "delay", "lag"],
                                                  n_null=9, confirm=1, max_effects=1))
    assert dg.verdict["effects"][0] == "lag"
    best = dg.effects[0] if dg.effects[0].effect == "lag" else next(e for e in dg.effects if e.effect == "lag")
    assert best.fit == "joint" and best.parameters["tau"] == pytest.approx(TAU, rel=0.3)
