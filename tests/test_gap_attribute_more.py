"""Screening, joint confirmation, linearized calibration, the validate= path, dead zone and backlash end to end."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.gap.attribution.calibration import linearized_null, refit_null
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.attribution.refit import fit_augmented
from synth.gap.attribution.screen import screen_effect
from synth.gap.effects import DEFAULT_CANDIDATES, make_effect

TRUE_TF = "23*(s+0.43)/((s+9.6)*(s+0.54))"
NOMINAL_TF = "22*(s+0.45)/((s+9.3)*(s+0.56))"
DT = 0.02
T = np.arange(0, 24, DT)
LEVELS = np.array([175, 225, 185, 235, 170, 205, 240, 180, 220, 195, 230, 175, 215, 185, 245, 190], float)
U = LEVELS[(T // 1.5).astype(int) % LEVELS.size]


def _plants():
    from synth.plant import Plant

    return Plant.from_string(TRUE_TF), Plant.from_string(NOMINAL_TF)


def _record(effect: str | None, params: dict[str, float], seed: int = 1, u: np.ndarray = U):
    true, _ = _plants()
    clean = make_effect(effect).apply(true, T, u, params) if effect else make_effect("delay").apply(true, T, u, {})
    y = clean + np.random.default_rng(seed).normal(size=T.size)
    return record_from_arrays(T, u, y), clean


def test_screen_ranks_the_true_effect_first_and_recovers_its_parameter():
    rec, _ = _record("rate_limit", {"rate": 300.0})
    _, nominal = _plants()
    k = rec.n // 2
    refit = fit_augmented(nominal, rec.t[:k], rec.u[:k], rec.y[:k])
    bases = [("nominal", nominal), ("refit", refit.plant)]
    screened = sorted((screen_effect(make_effect(c), bases, rec.t[:k], rec.u[:k], rec.y[:k], rec.t, rec.u)
                       for c in DEFAULT_CANDIDATES), key=lambda s: s.ssr)
    best = screened[0]
    assert best.effect.name == "rate_limit"
    assert best.params["rate"] == pytest.approx(300.0, rel=0.05)
    assert best.ssr / k == pytest.approx(1.0, rel=0.2)  # down to the noise (variance 1) on the training half
    assert screened[1].ssr > 1.5 * best.ssr
    assert best.yhat_eval.size == rec.n and np.allclose(best.yhat_eval[:k], best.yhat_train)


def test_confirming_one_candidate_gives_the_full_joint_answer():
    rec, clean = _record("saturation", {"upper": 215.0})
    _, nominal = _plants()
    fast = diagnose_effects(nominal, rec, options=DiagnoseOptions(confirm=1, n_null=49))
    full = diagnose_effects(nominal, rec, options=DiagnoseOptions(candidates=["saturation"], confirm=None, n_null=49))
    assert fast.verdict["effects"] == full.verdict["effects"] == ["saturation"]
    a = next(e for e in fast.effects if e.effect == "saturation")
    b = full.effects[0]
    assert a.fit == "joint" and a.accepted
    assert a.parameters["upper"] == pytest.approx(b.parameters["upper"], abs=0.5)
    assert a.shrinkage == pytest.approx(b.shrinkage, abs=0.01)
    true = 1.0 - np.mean((rec.y - clean)[fast.heldout] ** 2) / fast.j_refit
    assert a.shrinkage == pytest.approx(true, abs=0.03)
    screened = [e for e in fast.effects if e.fit == "screened"]
    assert len(screened) == len(DEFAULT_CANDIDATES) - 1 and not any(e.accepted for e in screened)
    first_stage = [e for e in fast.to_dict()["split"]["joint_fits"] if "+" not in e]  # '+': forward selection
    assert first_stage == ["saturation"]


def test_linearized_calibration_matches_the_repeated_refit():
    rec, _ = _record(None, {})
    _, nominal = _plants()
    k = rec.n // 2
    held = np.arange(rec.n) >= k
    refit = fit_augmented(nominal, rec.t[:k], rec.u[:k], rec.y[:k])
    args = (refit, rec.t[:k], rec.u[:k], rec.t, rec.u, held, True, 1.0)
    lin = linearized_null(*args, 400, np.random.default_rng(0))
    ref = refit_null(*args, 40, np.random.default_rng(1))
    # a perfect model beats an estimated one by about p / N on held-out data (p = 5 coefficients here)
    assert np.mean(lin) == pytest.approx(np.mean(ref), abs=0.004)
    assert 0.0 < np.mean(lin) < 0.02
    assert np.quantile(lin, 0.95) == pytest.approx(np.quantile(ref, 0.95), abs=0.01)


def test_validation_record_is_the_held_out_data():
    rec, _ = _record("rate_limit", {"rate": 300.0}, seed=2)
    val, clean = _record("rate_limit", {"rate": 300.0}, seed=3, u=np.roll(U, 300))
    _, nominal = _plants()
    dg = diagnose_effects(nominal, rec, validate=val, options=DiagnoseOptions(candidates=["rate_limit", "delay", "lag"]))
    assert dg.verdict["effects"] == ["rate_limit"]
    assert dg.heldout.all() and dg.split["heldout_samples"] == val.n and dg.split["train_samples"] == rec.n
    best = dg.effects[0]
    assert best.parameters["rate"] == pytest.approx(300.0, rel=0.05)
    true = 1.0 - np.mean((val.y - clean) ** 2) / dg.j_refit
    assert best.shrinkage == pytest.approx(true, abs=0.03)


@pytest.mark.parametrize("effect, params, key, tol", [
    ("backlash", {"width": 8.0}, "width", 0.4),
])
def test_backlash_end_to_end(effect, params, key, tol):
    rec, clean = _record(effect, params)
    _, nominal = _plants()
    dg = diagnose_effects(nominal, rec)
    assert dg.verdict["effects"] == [effect]
    best = next(e for e in dg.effects if e.effect == effect)
    assert best.parameters[key] == pytest.approx(params[key], abs=tol)
    true = 1.0 - np.mean((rec.y - clean)[dg.heldout] ** 2) / dg.j_refit
    assert best.shrinkage == pytest.approx(true, abs=0.05)


def test_bad_new_options_raise():
    from synth.errors import ModelError

    rec, _ = _record(None, {})
    _, nominal = _plants()
    with pytest.raises(ModelError, match="calibration"):
        diagnose_effects(nominal, rec, options=DiagnoseOptions(calibration="exact"))
    with pytest.raises(ModelError, match="confirm"):
        diagnose_effects(nominal, rec, options=DiagnoseOptions(confirm=0))


def test_unstable_refit_is_ruled_out_for_a_stable_nominal():
    """The re-fit of a stable nominal keeps its denominator coefficients >= 0 (stable for second order)."""
    _, nominal = _plants()
    t = T[: T.size // 2]
    y = 0.05 * t**2 + np.random.default_rng(0).normal(size=t.size)  # a ramp-up no stable model follows
    fit = fit_augmented(nominal, t, U[: t.size], 150.0 + y)
    assert np.all(fit.plant.den >= -1e-9) and np.max(fit.plant.poles().real) <= 1e-6


def test_interleaved_split_holds_out_segments_of_the_one_transient():
    """One big step up and down early, then a flat tail: the interleaved split holds out parts of the transient."""
    true, nominal = _plants()
    u = np.where((T >= 2.0) & (T < 9.0), 240.0, 180.0)
    clean = make_effect("rate_limit").apply(true, T, u, {"rate": 150.0})
    rec = record_from_arrays(T, u, clean + np.random.default_rng(4).normal(size=T.size))
    kw = dict(candidates=["rate_limit", "lag", "delay"], n_null=49)
    inter = diagnose_effects(nominal, rec, options=DiagnoseOptions(split="interleaved", **kw))
    assert inter.heldout[(T >= 2.0) & (T < 3.0)].any() and inter.heldout[(T >= 9.0) & (T < 10.0)].any()
    assert inter.split["split"] == "interleaved" and inter.effects[0].effect == "rate_limit"
    best = inter.effects[0]
    assert best.parameters["rate"] == pytest.approx(150.0, rel=0.05)
    assert inter.heldout.sum() == pytest.approx(rec.n / 2, abs=2)
    true_j = np.mean((rec.y - clean)[inter.heldout] ** 2)
    assert best.shrinkage == pytest.approx(1.0 - true_j / inter.j_refit, abs=0.05)


def test_burn_in_hides_an_unknown_initial_state():
    """The record starts away from the steady state the model assumes; a burn-in keeps it out of every cost."""
    true, nominal = _plants()
    start = 40.0 * np.exp(-T / 0.5)  # the plant settling from a different initial state (fast mode)
    clean = make_effect("delay").apply(true, T, U, {"delay": 0.06}) + start
    rec = record_from_arrays(T, U, clean + np.random.default_rng(5).normal(size=T.size))
    dg = diagnose_effects(nominal, rec, options=DiagnoseOptions(candidates=["delay", "drift"], n_null=49, burn_in=3.0))
    assert dg.verdict["effects"] == ["delay"] and dg.split["burn_in"] == 3.0
    assert dg.effects[0].parameters["delay"] == pytest.approx(0.06, abs=0.01)
    assert not dg.heldout[T < 3.0].any()
    with pytest.raises(Exception, match="burn_in"):
        diagnose_effects(nominal, rec, options=DiagnoseOptions(burn_in=-1.0))
    with pytest.raises(Exception, match="split"):
        diagnose_effects(nominal, rec, options=DiagnoseOptions(split="random"))


def test_dead_zone_at_the_bottom_level_is_not_separable_from_a_lower_limit():
    """A dead zone centred on the lowest levels moves only those (the rest shift by a constant the offset absorbs):
    a one-sided limit predicts the same held-out output to a small fraction of the noise; the verdict says so."""
    rec, _ = _record("deadzone", {"width": 6.0, "center": 175.0})
    _, nominal = _plants()
    dg = diagnose_effects(nominal, rec,
                          options=DiagnoseOptions(candidates=["deadzone", "saturation", "rate_limit"], n_null=49))
    group = dg.verdict["indistinguishable"]
    assert dg.verdict["effects"][0] in ("deadzone", "saturation")
    assert group and set(group[0]) == {"deadzone", "saturation"}
    assert "one-sided" in dg.verdict["experiments"][0]
    dz = next(e for e in dg.effects if e.effect == "deadzone")
    assert dz.parameters["width"] == pytest.approx(6.0, abs=0.3)


def test_forward_selection_names_a_second_effect_on_top_of_the_first():
    """Rate limit and a slow drift together: the verdict names both, the larger first, each shrinking the held-out
    error of the model before it; with max_effects=1 only the first."""
    from synth.gap.attribution.composite import NestedEffect

    true, nominal = _plants()
    both = NestedEffect("rate_limit", {"rate": 150.0}, "drift")
    clean = both.apply(true, T, U, {"slope": 0.3})
    rec = record_from_arrays(T, U, clean + np.random.default_rng(6).normal(size=T.size))
    kw = dict(candidates=["rate_limit", "lag", "drift", "delay"], n_null=49)
    dg = diagnose_effects(nominal, rec, options=DiagnoseOptions(**kw))
    assert dg.verdict["effects"] == ["rate_limit", "drift"] and dg.verdict["status"] == "effect"
    second = next(e for e in dg.effects if e.effect == "rate_limit+drift")
    # the first effect stays at its stage-1 fit (made without the drift): the slope trades with the slow pole
    assert second.accepted and second.parameters["slope"] == pytest.approx(0.3, abs=0.12)
    assert second.shrinkage_ci[0] > dg.threshold
    true_j = np.mean((rec.y - clean)[dg.heldout] ** 2)
    first = next(e for e in dg.effects if e.effect == "rate_limit")
    assert second.j_heldout - true_j < 0.5 * (first.j_heldout - true_j)  # most of what the first left is gone
    one = diagnose_effects(nominal, rec, options=DiagnoseOptions(max_effects=1, **kw))
    assert one.verdict["effects"] == ["rate_limit"]
    assert not any("+" in e.effect for e in one.effects)


def test_two_worker_processes_give_the_same_diagnosis():
    rec, _ = _record("rate_limit", {"rate": 300.0}, seed=7)
    _, nominal = _plants()
    kw = dict(candidates=["rate_limit", "lag", "delay"], confirm=2, n_null=19)
    one = diagnose_effects(nominal, rec, options=DiagnoseOptions(**kw))
    two = diagnose_effects(nominal, rec, options=DiagnoseOptions(workers=2, **kw))
    assert one.verdict == two.verdict
    for a, b in zip(one.effects, two.effects):
        assert (a.effect, a.fit) == (b.effect, b.fit)
        assert a.j_heldout == pytest.approx(b.j_heldout, rel=1e-9)


def test_screen_moves_the_denominator_one_gauss_newton_step():
    """With the denominator 10 % off and no effect at all, the screen's step in it takes the SSR down to the
    noise, and the reported denominator moves toward the truth; held fixed it could not."""
    from synth.gap.attribution import screen as screen_module
    from synth.plant import Plant

    true, _ = _plants()
    rec, _ = _record(None, {})
    off = Plant(true.num, true.den * np.array([1.0, 1.1, 1.1]))  # both denominator coefficients 10 % high
    k = rec.n // 2
    t, u, y = rec.t[:k], rec.u[:k], rec.y[:k]
    delay = make_effect("delay")
    stepped = screen_effect(delay, [("off", off)], t, u, y, t, u)
    directions = screen_module._denominator_directions
    try:
        screen_module._denominator_directions = lambda plant: []
        held = screen_effect(delay, [("off", off)], t, u, y, t, u)
    finally:
        screen_module._denominator_directions = directions
    assert stepped.ssr / k == pytest.approx(1.0, rel=0.15)  # down to the noise (variance 1)
    assert held.ssr / k > 1.3  # numerator, delay and constant alone cannot absorb the 10 % error
    assert np.all(np.abs(stepped.plant.den - true.den) < np.abs(off.den - true.den) + 1e-12)
