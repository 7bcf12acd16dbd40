"""Clipping seen directly in a record (synth.gap.where.clipping) and how the diagnosis reports it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.gap.diagnose import diagnose
from synth.gap.where.clipping import find_clipping, record_clipping
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

RNG = np.random.default_rng(7)


def _noisy_sine(n: int = 3000) -> np.ndarray:
    t = np.linspace(0.0, 30.0, n)
    return np.sin(t) + 0.3 * np.sin(2.7 * t) + 0.02 * RNG.standard_normal(n)


def test_an_upper_clip_is_found_with_its_level_and_every_sample_on_it():
    x = np.minimum(_noisy_sine(), 0.9)
    clips = find_clipping(x, "output", "level", "V")
    assert len(clips) == 1
    c = clips[0]
    assert (c.side, c.level, c.effect) == ("upper", 0.9, "saturation(output)")
    assert c.samples == int(np.sum(x == 0.9)) and c.samples > 50
    edges = np.diff(np.r_[0, (x == 0.9).astype(int), 0])
    assert c.runs == int(np.sum(edges == 1)) and c.longest == int(np.max(np.flatnonzero(edges == -1)
                                                                         - np.flatnonzero(edges == 1)))


def test_a_lower_clip_on_the_command_says_the_model_already_sees_it():
    u = np.maximum(_noisy_sine(), -0.7)
    (c,) = find_clipping(u, "input", "voltage", "V")
    assert (c.side, c.level, c.effect) == ("lower", -0.7, "saturation")
    assert "already sees it" in c.describe() and "minimum -0.7 V" in c.describe()


def test_a_noisy_signal_without_a_limit_is_not_clipped():
    assert find_clipping(_noisy_sine(), "output") == []


def test_a_step_command_rests_on_its_levels_by_design():
    u = np.repeat([0.0, 5.0, 15.0, 5.0], 300)
    assert find_clipping(u, "input") == []


def test_a_coarsely_quantized_signal_cannot_be_told_from_a_clipped_one():
    x = np.round(np.minimum(_noisy_sine(), 0.9), 1)  # 0.1 steps: every level repeats
    assert find_clipping(x, "output") == []


def test_an_extreme_repeated_no_more_than_other_values_is_not_a_clip():
    x = _noisy_sine()
    x[np.argsort(x)[-3:]] = x.max()  # the maximum three times ...
    x[10:15] = 0.123  # ... but another value five times: repeats here are not special
    assert find_clipping(x, "output") == []
    x[10:15] = x[10:15] + 1e-3 * np.arange(5)
    assert [c.samples for c in find_clipping(x, "output")] == [3]


def test_the_diagnosis_reports_an_output_clip_as_observed_with_the_clip_fit():
    t = np.arange(0.0, 40.0, 0.01)
    u = np.sin(0.7 * t) + 0.5 * np.sin(1.9 * t) + 0.05 * RNG.standard_normal(t.size)
    plant = Plant.from_string("2/(0.3*s+1)")
    y = np.minimum(simulate_plant(plant, t, u), 2.2) + 0.01 * RNG.standard_normal(t.size)
    y = np.where(y >= 2.2, 2.2, y)  # the sensor's range: samples at the limit read exactly the limit
    rec = record_from_arrays(t, u, y)
    dg = diagnose(plant, rec, candidates=["saturation(output)", "delay"], n_null=5)
    assert dg.verdict["observed"] == ["saturation(output)"]
    assert dg.verdict["effects"][0] == "saturation(output)"  # the model-based verdict agrees here
    d = json.loads(json.dumps(dg.to_dict()))
    (clip,) = d["where"]["clipping"]
    assert clip["level"] == 2.2 and clip["samples"] == int(np.sum(y == 2.2)) and clip["record"] == "record"
    assert "rests on its maximum 2.2" in dg.summary


def test_the_diagnosis_finds_clipping_in_the_validation_record_too():
    t = np.arange(0.0, 20.0, 0.01)
    u = np.sin(t) + 0.02 * RNG.standard_normal(t.size)
    plant = Plant.from_string("1/(0.1*s+1)")
    y = simulate_plant(plant, t, u) + 0.01 * RNG.standard_normal(t.size)
    rec = record_from_arrays(t, u, y)
    val = record_from_arrays(t, np.minimum(u, 0.8), y)
    dg = diagnose(plant, rec, val, candidates=["delay"], n_null=3)
    assert [(c.record, c.column, c.level) for c in dg.clipping] == [("validate", "input", 0.8)]
    assert dg.verdict["observed"] == ["saturation"] and "(validation record)" in dg.summary
    assert record_clipping(rec) == []


@pytest.mark.parametrize("bad", [[1.0, np.nan, 2.0, 3.0, 4.0, 5.0, 6.0], [1.0, 1.0]])
def test_non_finite_or_short_signals_are_not_judged(bad):
    assert find_clipping(np.array(bad)) == []


def test_a_heldout_tail_without_transients_is_warned_about():
    from synth.gap.diagnose import heldout_warnings

    t = np.arange(0.0, 10.0, 0.01)
    u = np.where(t >= 2.0, 1.0, 0.0)
    y = simulate_plant(Plant.from_string("1/(0.2*s+1)", delay=0.05), t, u) + 0.01 * RNG.standard_normal(t.size)
    rec = record_from_arrays(t, u, y)
    dg = diagnose(Plant.from_string("1/(0.2*s+1)"), rec, candidates=["delay"], n_null=3)
    (w,) = dg.warnings
    assert "t >= 5 s" in w and "spans 0 %" in w and dg.to_dict()["warnings"] == [w]
    assert heldout_warnings(rec, split="interleaved") == []
    assert heldout_warnings(rec, train_fraction=0.15) == []  # the step at 2 s is then held out
    assert heldout_warnings(rec, record_from_arrays(t, 0.5 + 1e-3 * np.sin(t), y))[0].startswith("the validation")
