"""A periodic train after a short constant start: the start-up transient and the static gain.

The cycle average stands for the periodic steady state, its mean removed. Its first period starts one period after
the train began; with a step every time constant (0.5 s periods of ``2/(0.5 s + 1)`` after a 1 s rest), the next
periods still carry e^-2, e^-4, ... of the start-up, and k and tau came out 13 standard errors off (20 noise seeds).
Now a record whose output is flat over the constant start (the plant at rest) is fitted whole when that is
predicted to be more precise (the transition from rest carries the static gain); otherwise the periods that start
within the model's settling time are dropped; with none left, the whole record is fitted, its start weighted 0."""

from __future__ import annotations

import numpy as np
import pytest

from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

TRUTH = Plant.from_string("2/(0.5*s+1)")


def _train(rest: float, half: float, duration: float, moving: bool = False) -> tuple[np.ndarray, ...]:
    """Low for ``rest`` s from rest, or (``moving``) high from a zero state, so that the output still rises over
    the constant start; then a square wave of half period ``half``."""
    t = np.arange(0, duration, 0.01)
    first = 1.0 if moving else 0.0
    u = np.where(t < rest, first, (((t - rest) // half) % 2 == int(moving)).astype(float))
    return t, u, simulate_plant(TRUTH, t, u, initial="zero")


def _spread(rest: float, half: float, duration: float, seeds: range,
            moving: bool = False) -> tuple[np.ndarray, np.ndarray, set[str]]:
    t, u, y = _train(rest, half, duration, moving)
    est, std, notes = [], [], set()
    for seed in seeds:
        r = identify((t, u, y + 0.01 * np.random.default_rng(seed).normal(size=t.size)), "k/(tau*s+1)")
        est.append([r.fit.parameters["k"], r.fit.parameters["tau"]])
        std.append([r.fit.std["k"], r.fit.std["tau"]])
        notes.add(r.whole_record_note)
    return np.array(est), np.array(std), notes


def test_from_rest_the_whole_record_is_fitted_and_the_bias_is_gone() -> None:
    est, std, notes = _spread(1.0, 0.5, 12.0, range(12))
    # the whole record is predicted 1.3-1.7 times as precise here, around the threshold: either remedy, no bias
    assert all(n.startswith(("the whole record, from rest", "dropped")) for n in notes), notes
    assert any(n.startswith("the whole record, from rest") for n in notes), notes
    spread = est.std(axis=0)
    assert np.all(np.abs(est.mean(axis=0) - np.array([2.0, 0.5])) < spread), (est.mean(axis=0), spread)  # 13 before
    assert np.all((std.mean(axis=0) > 0.6 * spread) & (std.mean(axis=0) < 1.6 * spread)), (std.mean(axis=0), spread)


def test_not_at_rest_the_periods_within_the_settling_time_are_dropped_and_the_bias_is_gone() -> None:
    est, std, notes = _spread(1.0, 0.5, 12.0, range(12), moving=True)
    assert all(n.startswith("dropped") and "start-up transient" in n for n in notes), notes
    spread = est.std(axis=0)
    bias = est.mean(axis=0) - np.array([2.0, 0.5])
    assert np.all(np.abs(bias) < spread), (bias, spread)           # 13 spreads before
    assert np.all((std.mean(axis=0) > 0.6 * spread) & (std.mean(axis=0) < 1.6 * spread)), (std.mean(axis=0), spread)


def test_with_no_period_free_of_the_transient_the_whole_record_is_fitted() -> None:
    est, std, notes = _spread(1.0, 1.0, 5.0, range(4), moving=True)
    assert all("no later period is left" in n and "fitted the whole record" in n for n in notes), notes
    assert np.all(np.abs(est - np.array([2.0, 0.5])) < 4 * std), (est, std)


def test_a_train_that_settles_keeps_every_period_after_the_first() -> None:
    t, u, y = _train(1.0, 3.0, 25.0)
    r = identify((t, u, y + 0.01 * np.random.default_rng(0).normal(size=t.size)), "k/(tau*s+1)")
    assert r.average.count == 2 and r.whole_record_note == ""   # the periods from 10 and 16 s
    assert r.fit.parameters["tau"] == pytest.approx(0.5, abs=4 * r.fit.std["tau"])


def test_a_short_rest_before_a_train_that_never_settles_is_fitted_on_the_whole_record() -> None:
    """3/((s+1)(s+3)), 1.5 s half periods after 3 s at the high level: the periodic average (its mean removed)
    gave k a spread of 0.07 over 20 seeds; the whole record, whose transition from rest carries the static
    gain, 0.012. Three noise seeds here: each must be fitted whole and hold k within 4 of its standard errors."""
    t = np.arange(0, 30, 0.01)
    u = np.where(t < 3.0, 1.0, 1.0 - (((t - 3.0) // 1.5) % 2 == 0))
    y = simulate_plant(Plant.from_string("3/((s+1)*(s+3))"), t, u)
    est, std = [], []
    for seed in range(3):
        r = identify((t, u, y + 0.01 * np.random.default_rng(100 + seed).normal(size=t.size)), "k/((s+p1)*(s+p2))")
        assert "predicted" in r.whole_record_note and "fitted it instead" in r.whole_record_note, r.whole_record_note
        est.append(r.fit.parameters["k"])
        std.append(r.fit.std["k"])
    assert np.mean(std) < 0.03                                   # the periodic average's was 0.07
    assert np.all(np.abs(np.array(est) - 3.0) < 4 * np.array(std)), (est, std)
