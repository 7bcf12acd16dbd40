"""Which effect closes the gap (synthetic records with a known effect and a few % nominal mismatch)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.errors import ModelError
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.effects import make_effect
from synth.plant import Plant

TRUE = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")  # the seed's rotor drive, PWM -> rad/s
NOMINAL = Plant.from_string("22*(s+0.45)/((s+9.3)*(s+0.56))")  # 2-5 % off in every coefficient
DT = 0.02
T = np.arange(0, 24, DT)
LEVELS = np.array([175, 225, 185, 235, 170, 205, 240, 180, 220, 195, 230, 175, 215, 185, 245, 190], float)
U = LEVELS[(T // 1.5).astype(int) % LEVELS.size]  # steps of several amplitudes (PWM)
NOISE = 1.0  # rad/s


def _record(effect: str | None, params: dict[str, float], seed: int = 1) -> tuple[object, np.ndarray]:
    clean = make_effect(effect).apply(TRUE, T, U, params) if effect else make_effect("delay").apply(TRUE, T, U, {})
    y = clean + NOISE * np.random.default_rng(seed).normal(size=T.size)
    return record_from_arrays(T, U, y), clean


def _true_shrinkage(dg, rec, clean: np.ndarray) -> float:
    j_true = float(np.mean((rec.y - clean)[dg.heldout] ** 2))
    return 1.0 - j_true / dg.j_refit


def test_rate_limit_is_found_with_its_rate_and_shrinkage():
    rec, clean = _record("rate_limit", {"rate": 300.0})
    dg = diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(candidates=["rate_limit", "delay"], n_null=9))
    assert dg.verdict["effects"] == ["rate_limit"]
    best = dg.effects[0]
    assert best.effect == "rate_limit" and best.accepted
    assert best.parameters["rate"] == pytest.approx(300.0, rel=0.05)
    lo, hi = best.parameter_ci["rate"]
    assert lo < best.parameters["rate"] < hi
    assert best.shrinkage == pytest.approx(_true_shrinkage(dg, rec, clean), abs=0.03)
    assert best.shrinkage_ci[0] <= best.shrinkage <= best.shrinkage_ci[1]
    assert best.shrinkage_ci[0] > dg.threshold
    assert 0.9 < best.share_of_gap < 1.1  # the rest is noise
    delay = next(e for e in dg.effects if e.effect == "delay")
    assert delay.shrinkage < best.shrinkage_ci[0] and not delay.accepted
    d = dg.to_dict()
    assert d["verdict"]["effects"] == ["rate_limit"] and d["effects"][0]["effect"] == "rate_limit"


def test_saturation_is_found_with_its_limit():
    rec, clean = _record("saturation", {"upper": 215.0})
    dg = diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(candidates=["saturation", "rate_limit"], n_null=9))
    assert dg.verdict["effects"] == ["saturation"]
    best = dg.effects[0]
    assert best.parameters["upper"] == pytest.approx(215.0, abs=1.0)
    assert not np.isfinite(best.parameters["lower"])
    assert best.shrinkage == pytest.approx(_true_shrinkage(dg, rec, clean), abs=0.03)


def test_extra_delay_is_found_or_grouped_with_a_lag():
    rec, clean = _record("delay", {"delay": 0.03})
    dg = diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(candidates=["delay", "lag"], n_null=9))
    assert dg.verdict["effects"] == ["delay"]
    best = dg.effects[0]
    assert best.parameters["delay"] == pytest.approx(0.03, abs=0.003)
    assert best.shrinkage == pytest.approx(_true_shrinkage(dg, rec, clean), abs=0.03)
    for group in dg.verdict["indistinguishable"]:  # allowed, but then with the experiment that separates them
        assert group[0] == "delay" and dg.verdict["experiments"]


def test_pure_parameter_mismatch():
    rec, _ = _record(None, {})
    dg = diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(candidates=["delay", "rate_limit"], n_null=9))
    assert dg.verdict["effects"] == ["parameter_mismatch"]
    assert dg.verdict["status"] == "parameter_mismatch"
    assert dg.refit_shrinkage_ci[0] > 0.2
    assert not any(e.accepted for e in dg.effects)
    assert dg.j_refit / dg.noise_floor == pytest.approx(1.0, abs=0.2)


def test_noise_only_is_no_gap():
    rec, _ = _record(None, {}, seed=3)
    dg = diagnose_effects(TRUE, rec, options=DiagnoseOptions(candidates=["delay", "rate_limit"], n_null=9))
    assert dg.verdict["effects"] == [] and dg.verdict["status"] == "none"
    assert np.sqrt(dg.noise_floor) == pytest.approx(NOISE, rel=0.15)


def test_bad_options_raise():
    rec, _ = _record(None, {})
    with pytest.raises(ModelError, match="train_fraction"):
        diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(train_fraction=0.95))
    with pytest.raises(ModelError, match="unknown effect"):
        diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(candidates=["gremlins"]))
