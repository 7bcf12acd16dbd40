"""Verdict order by parsimony, the relevance share against an overestimated noise floor, the sub-sample lag."""

from __future__ import annotations

import numpy as np
import pytest

import synth.gap.attribution.heldout as heldout
from synth.data import record_from_arrays
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.attribution.parsimony import free_parameters, parsimonious_lead, share_of_excess
from synth.gap.attribution.screen import screen_effect
from synth.gap.effects import make_effect
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


# ------------------------------------------------------------------------------------------- parameter counts
@pytest.mark.parametrize(("effect", "params", "count"), [
    ("delay", {"delay": 0.01}, 1),
    ("lag", {"tau": 0.01}, 1),
    ("resonance", {"wn": 80.0, "zeta": 0.3}, 2),
    ("saturation", {"lower": 2.4, "upper": np.inf}, 1),  # the unused side is no parameter
    ("deadzone", {"width": 0.1, "center": 2.0}, 1),  # the center is the command at rest, not fitted
    ("quantization", {"step": 0.4, "offset": 0.1}, 2),
    ("supply_sag", {"sag": 0.01, "tau": 0.9}, 2),
    ("static_nonlinearity", {"a2": 0.1, "a3": 0.0, "center": 6.0, "scale": 4.0}, 2),  # center, scale fixed
    ("drift", {"slope": 0.5}, 1),
])
def test_free_parameters_count_what_the_fit_chose(effect, params, count):
    assert free_parameters(make_effect(effect), params) == count


def test_parsimonious_lead_needs_a_significant_advantage_against_each_simpler_candidate():
    def ci(a, b):  # shrinkage of a against b, +-0.01
        r = 1.0 - a.sum() / b.sum()
        return r - 0.01, r + 0.01

    three = ("three", np.array([100.0]))
    two = ("two", np.array([101.0]))  # the best is 1 % better: not above a threshold of 0.02
    one = ("one", np.array([110.0]))  # 9 % better: significant
    lead, info = parsimonious_lead([three, two, one], [3, 2, 1], ci, 0.02)
    assert lead == 1 and info["lead"] == "two" and info["best"] == "three"
    assert info["advantage_ci"] == pytest.approx([0.0, 0.02], abs=1e-2)
    # a simpler candidate that the best beats significantly never leads; an equal count never moves the lead
    assert parsimonious_lead([three, one], [3, 1], ci, 0.02) == (0, None)
    assert parsimonious_lead([three, two], [2, 2], ci, 0.02) == (0, None)
    # among candidates the best does not beat, the fewest parameters lead, whatever their order in J
    lead, _ = parsimonious_lead([three, two, ("one", np.array([100.5]))], [3, 2, 1], ci, 0.02)
    assert lead == 2


# ------------------------------------------------------------------------------------------------ end to end
def test_a_true_lag_is_not_contested_by_a_resonance_without_a_peak():
    """The resonance's fit here has the lower held-out J (it led before the parsimony rule, which then chose the
    lag); its damping of 0.83 leaves no peak, so it is no resonance at all (synth.gap.attribution.physical)."""
    dg = diagnose_effects(NOMINAL, _record("lag", {"tau": 0.0144}, seed=8),
                          options=DiagnoseOptions(candidates=["lag", "resonance"], confirm=None, max_effects=1))
    res = _by_label(dg)
    assert res["resonance"].j_heldout < res["lag"].j_heldout   # the premise
    assert res["resonance"].parameters["zeta"] > 0.7072 and "no resonance peak" in res["resonance"].unphysical
    assert dg.verdict["effects"] == ["lag"] and not res["resonance"].accepted
    assert dg.verdict["indistinguishable"] == [] and dg.verdict["parsimony"] is None


def test_a_lightly_damped_resonance_is_still_named_resonance():
    dg = diagnose_effects(NOMINAL, _record("resonance", {"wn": 60.0, "zeta": 0.15}, seed=0),
                          options=DiagnoseOptions(candidates=["lag", "delay", "resonance"], confirm=None, max_effects=1))
    res = _by_label(dg)
    assert res["delay"].significant and res["lag"].significant  # simpler contenders were there
    assert dg.verdict["effects"] == ["resonance"]
    assert dg.verdict["parsimony"] is None
    assert res["resonance"].parameters["wn"] == pytest.approx(60.0, rel=0.05)
    assert res["resonance"].parameters["zeta"] < 0.25


# ------------------------------------------------------------------------------ relevance against the floor
def test_share_of_excess_takes_the_floor_as_at_most_the_judged_models_error():
    assert share_of_excess(2.0, 1.5, 1.0) == pytest.approx(0.5)  # the floor below both: unchanged
    assert share_of_excess(0.95, 0.85, 1.0) == 1.0  # below the floor's estimate: all that can be measured
    assert share_of_excess(0.95, 0.97, 1.0) == 0.0  # no better than the model before: nothing removed
    assert share_of_excess(1.0, 1.0, 1.0) == 0.0


def test_an_effect_that_beats_an_overestimated_noise_floor_is_relevant(monkeypatch):
    rec = _record("lag", {"tau": 0.0144}, seed=3)
    # a floor estimate 20 % (in sigma) above the re-fit's error: the re-fit alone looks within the noise
    monkeypatch.setattr(heldout, "noise_sigma", lambda e, keep=None: 1.2 * float(np.sqrt(np.mean(np.square(e)))))
    dg = diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(candidates=["lag"], confirm=None, max_effects=1))
    lag = dg.effects[0]
    # the premise was the re-fit's residual alone, 1.44 J_refit: no excess over it; since session 68 the floor is
    # the least over the fitted models' residuals, the lag's, so the overestimate shrinks to the lag's own error
    assert dg.noise_floor < 1.44 * dg.j_refit and dg.noise_floor <= 1.44 * lag.j_heldout * 1.05
    assert lag.significant and lag.j_heldout < dg.j_refit
    assert dg.verdict["effects"] == ["lag"] and lag.accepted


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
