"""Gap localization in time: residual size, step phases, CUSUM drift, energy windows."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from synth.data import record_from_arrays
from synth.errors import ModelError
from synth.gap.where.drift import cusum_drift
from synth.gap.where.localize import localize_gap
from synth.gap.where.residual import model_residual
from synth.gap.where.steps import detect_steps
from synth.gap.where.time import energy_windows
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

G = Plant.from_string("2/(0.1*s+1)")
DT = 0.01


def coloured(n: int, sigma: float, rng: np.random.Generator, pole: float = 0.8) -> np.ndarray:
    """AR(1) noise of standard deviation ``sigma``."""
    return lfilter([np.sqrt(1 - pole**2)], [1.0, -pole], rng.normal(0, sigma, n))


def step_train(rng: np.random.Generator, duration: float = 60.0, period: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """Levels alternating in sign with random size: every change is a step of 0.4-2."""
    t = np.arange(0, duration, DT)
    n = int(duration / period) + 1
    levels = rng.uniform(0.2, 1.0, n) * (-1.0) ** np.arange(n)
    return t, levels[(t // period).astype(int)]


def rate_limit(u: np.ndarray, rate: float) -> np.ndarray:
    out = np.empty_like(u)
    out[0] = u[0]
    for k in range(1, u.size):
        out[k] = out[k - 1] + np.clip(u[k] - out[k - 1], -rate * DT, rate * DT)
    return out


def test_nrmse_and_fitted_offset_match_independent_computation():
    rng = np.random.default_rng(0)
    t, u = step_train(rng, 20.0)
    y_true = simulate_plant(G, t, u)
    noise = coloured(t.size, 0.05, rng)
    r = model_residual(G, record_from_arrays(t, u, y_true + 3.0 + noise))
    assert r.offset == pytest.approx(3.0 + noise.mean(), abs=1e-9)
    expected = np.linalg.norm(noise - noise.mean()) / np.linalg.norm(y_true + noise - np.mean(y_true + noise))
    assert r.nrmse == pytest.approx(expected, rel=1e-9)
    assert r.fit_percent == pytest.approx(100 * (1 - expected))
    r0 = model_residual(G, record_from_arrays(t, u, y_true + 3.0 + noise), offset="none")
    assert r0.offset == 0.0 and np.mean(r0.e) == pytest.approx(3.0 + noise.mean())


def test_bad_offset_and_model_are_one_line_errors():
    t = np.arange(0, 1, 0.01)
    rec = record_from_arrays(t, np.where(t > 0.5, 1.0, 0.0), t)
    with pytest.raises(ModelError, match=r"^offset: must be 'fit', 'none' or a number"):
        model_residual(G, rec, offset="mean")
    with pytest.raises(ModelError, match=r"^plant: expected a Plant"):
        model_residual("2/(s+1)", rec)  # type: ignore[arg-type]


def test_correct_model_with_coloured_noise_gap_is_the_noise_level():
    rng = np.random.default_rng(1)
    t, u = step_train(rng)
    y_true = simulate_plant(G, t, u)
    noise = coloured(t.size, 0.02, rng)
    loc = localize_gap(G, record_from_arrays(t, u, y_true + noise))
    assert loc.residual.nrmse == pytest.approx(np.std(noise) / np.std(y_true + noise), rel=0.02)
    assert not loc.where.time.drift.detected
    assert loc.where.frequency.bands == []


def test_step_detection_finds_every_edge_with_its_size():
    rng = np.random.default_rng(2)
    t, u = step_train(rng, 20.0)
    edges = detect_steps(t, u + 0.001 * rng.normal(size=t.size))
    jumps = np.flatnonzero(np.abs(np.diff(u)) > 0.2 * np.ptp(u)) + 1
    assert [e.index for e in edges] == jumps.tolist()
    assert [e.size for e in edges] == pytest.approx([float(u[k] - u[k - 1]) for k in jumps], abs=0.01)


def test_rate_limited_actuator_gap_is_in_the_rise_and_grows_with_rate():
    rng = np.random.default_rng(3)
    t, u = step_train(rng)
    y = simulate_plant(G, t, rate_limit(u, 2.0)) + coloured(t.size, 0.005, rng)
    loc = localize_gap(G, record_from_arrays(t, u, y))
    time = loc.where.time
    rise = sum(time.phases[d]["rise"] for d in time.phases)
    assert rise > 0.7, time.phases
    big = [s for s in time.steps if abs(s.edge.size) > 0.8]
    assert big and all(s.record.rise_time > 1.5 * s.model.rise_time for s in big)
    # per step, the residual energy grows with the step size (the time the limiter needs)
    sizes = np.array([abs(s.edge.size) for s in time.steps])
    shares = np.array([s.share for s in time.steps])
    assert np.corrcoef(sizes, shares)[0, 1] > 0.8
    assert loc.where.regimes["rate"].trend == "grows"
    assert "rise" in loc.headline and "grows with input rate" in loc.headline


def test_cusum_false_alarms_are_rare_on_coloured_noise():
    t = np.arange(0, 60, DT)
    alarms = sum(cusum_drift(t, coloured(t.size, 1.0, np.random.default_rng(s), 0.8)).detected for s in range(40))
    assert alarms <= 6  # designed for 5 % (2 of 40); 6 of 40 has probability < 2 % at 5 %


def test_slow_drift_is_flagged_where_it_is():
    rng = np.random.default_rng(4)
    t, u = step_train(rng)
    drift = np.where(t > 35, 0.01 * (t - 35), 0.0)
    y = simulate_plant(G, t, u) + coloured(t.size, 0.02, rng) + drift
    loc = localize_gap(G, record_from_arrays(t, u, y))
    d = loc.where.time.drift
    assert d.detected and d.direction == "up"
    assert 33 < d.t_start < 45 and d.t_end > 55 and d.size > 0.05
    assert loc.where.time.windows and all(w.t0 >= 35 for w in loc.where.time.windows[:3])
    assert "drifts up" in loc.headline


def test_energy_windows_merge_neighbours_and_shares_add_up():
    t = np.arange(0, 10, DT)
    e = 0.01 * np.random.default_rng(5).normal(size=t.size)
    e[(t > 2) & (t < 3)] += 1.0
    e[(t > 7) & (t < 7.4)] -= 2.0
    w = energy_windows(t, e)
    assert len(w) == 2
    assert (w[0].t0, w[0].t1) == pytest.approx((7.0, 7.4), abs=0.11)
    expected = np.sum(e[(t >= w[0].t0) & (t < w[0].t1 + DT / 2)] ** 2) / np.sum(e**2)
    assert w[0].share == pytest.approx(expected, rel=0.05)
    assert w[0].share + w[1].share > 0.99
