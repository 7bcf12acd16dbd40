"""Gap localization by regime, the whole diagnosis (JSON, figure), and a real record."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from synth.data import load_record, record_from_arrays
from synth.errors import DataError
from synth.gap.where.gapmap import write_gap_map
from synth.gap.where.localize import localize_gap
from synth.gap.where.regime import localize_regime
from synth.gap.where.residual import model_residual
from synth.ident.simulate import simulate_plant
from synth.plant import Plant
from tests.conftest import shared_path

DT = 0.01
G = Plant.from_string("2/(0.1*s+1)")


def random_steps(rng: np.random.Generator, duration: float = 60.0) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0, duration, DT)
    levels = rng.uniform(-3.0, 3.0, int(duration) + 1)
    return t, levels[t.astype(int)]


def noise(n: int, rng: np.random.Generator, sigma: float = 0.02) -> np.ndarray:
    return sigma * lfilter([np.sqrt(1 - 0.8**2)], [1.0, -0.8], rng.normal(size=n))


def test_saturation_is_flagged_at_large_amplitude():
    rng = np.random.default_rng(0)
    t, u = random_steps(rng)
    y = simulate_plant(G, t, np.clip(u, -2.0, 2.0)) + noise(t.size, rng)
    loc = localize_gap(G, record_from_arrays(t, u, y))
    amp = loc.where.regimes["amplitude"]
    assert amp.trend == "grows"
    top = amp.flagged_high
    assert top is not None and top.lo >= 1.5 and top.ratio > 2.0
    # below the limit (|u| < 2 in every bin under 1.5) no bin is larger than the rest
    assert not any(b.flagged and b.ratio > 1 for b in amp.bins if b.hi is not None and b.hi <= 1.5)
    assert "input amplitude" in loc.headline


def test_correct_model_flags_few_regime_bins():
    flagged = 0
    for seed in range(10):
        rng = np.random.default_rng(10 + seed)
        t, u = random_steps(rng, 40.0)
        r = model_residual(G, record_from_arrays(t, u, simulate_plant(G, t, u) + noise(t.size, rng)))
        regimes = localize_regime(r, G)
        flagged += sum(b.flagged for v in regimes.values() for b in v.bins)
    assert flagged <= 5  # about 16 bins per seed, each variable tested at 5 % familywise


def test_aux_channel_that_drives_the_error_is_flagged_and_bad_aux_is_rejected():
    rng = np.random.default_rng(2)
    t, u = random_steps(rng)
    temperature = np.linspace(20.0, 60.0, t.size)
    gain = np.where(temperature > 50.0, 0.7, 1.0)  # the plant weakens when hot
    y = simulate_plant(G, t, u) * gain + noise(t.size, rng)
    loc = localize_gap(G, record_from_arrays(t, u, y, aux={"temperature": temperature}))
    temp = loc.where.regimes["aux:temperature"]
    assert temp.trend == "grows" and temp.flagged_high.lo >= 50.0 - 8.0
    r = model_residual(G, record_from_arrays(t, u, y))
    with pytest.raises(DataError, match="aux 'aux:temperature'"):
        localize_regime(r, G, {"temperature": temperature[:-5]})


def test_diagnosis_serializes_to_the_json_contract_and_draws(tmp_path):
    rng = np.random.default_rng(3)
    t, u = random_steps(rng, 20.0)
    y = simulate_plant(G, t, np.clip(u, -2.0, 2.0)) + noise(t.size, rng)
    loc = localize_gap(G, record_from_arrays(t, u, y))
    d = json.loads(json.dumps(loc.to_dict()))
    assert d["gap"]["nrmse"] == pytest.approx(loc.residual.nrmse)
    assert d["gap"]["fit_percent"] == pytest.approx(100 * (1 - loc.residual.nrmse))
    for key in ("time_windows", "frequency_bands", "regimes"):
        assert key in d["where"]
    assert all(len(w) == 3 and w[0] < w[1] and 0 < w[2] <= 1 for w in d["where"]["time_windows"])
    assert all(len(b) == 3 and b[0] <= b[1] for b in d["where"]["frequency_bands"])
    png = write_gap_map(loc, tmp_path / "gap.png", G)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_dc_motor_record_gap_lies_where_the_step_response_arrives():
    path = shared_path("data", "dcmotor_speed_lab", "06_dc_step_5_15_00.mat")
    rec = load_record(path, "Zeit", "Motorspannung", "Geschwindigkeit", input_unit="V", output_unit="rpm")
    model = Plant.from_string("245.5/(0.1468*s+1)^2", delay=0.035)
    loc = localize_gap(model, rec)  # affine static map: the fitted offset is the operating point
    r = loc.residual
    # the offset is the zero-speed intercept of the affine map: ~1064 rpm at 5 V vs 245.5 * 5 = 1227.5
    assert r.offset == pytest.approx(np.mean(rec.y[:300]) - 245.5 * 5.0, abs=15.0)
    assert r.fit_percent > 95.0
    steps = loc.where.time.steps
    assert len(steps) == 1 and steps[0].edge.direction == "up" and steps[0].edge.t == pytest.approx(3.24, abs=0.02)
    # 10-90 % rise of 1/(T s + 1)^2 is 3.357 T (independent); the record rises within 5 % of it
    assert steps[0].model.rise_time == pytest.approx(3.357 * 0.1468, rel=0.01)
    assert steps[0].record.rise_time == pytest.approx(steps[0].model.rise_time, rel=0.05)
    # the largest residual window is where the response arrives (the record overshoots ~1.4 %, the model cannot)
    first = loc.where.time.windows[0]
    assert 3.5 <= first.t0 and first.t1 <= 4.6 and first.share > 0.2
    assert steps[0].record.overshoot_percent > 1.0 and steps[0].model.overshoot_percent < 1e-9  # rounding only
