"""Each block's equation against a direct computation; signals with a PSD."""

import control
import numpy as np
import pytest
from scipy.signal import welch

from synth.errors import DataError, ModelError
from synth.sim.blocks import (
    Backlash,
    DeadZone,
    Delay,
    Dynamics,
    Lag,
    Noise,
    Quantizer,
    RateLimit,
    SampleHold,
    Saturation,
    Static,
    SupplySag,
    apply_chain,
)
from synth.sim.signals import PsdDisturbance, RecordDisturbance, psd_signal, psd_value, psd_variance

RNG = np.random.default_rng(7)
X = np.cumsum(RNG.normal(0, 1.0, 3000))  # a rough random walk
DT = 0.001


def _loop(step, x, y0):
    out, prev = [], y0
    for v in x:
        prev = step(prev, v)
        out.append(prev)
    return np.array(out)


def test_rate_limit_equation_and_flags():
    block = RateLimit(rate=400.0, falling=250.0)
    y, flags = apply_chain([block], X, DT, return_flags=True)
    expected = _loop(lambda p, v: p + np.clip(v - p, -0.25, 0.4), X, X[0])
    np.testing.assert_allclose(y, expected, atol=1e-12)
    prev = np.concatenate([[X[0]], y[:-1]])
    limited = (X - prev > 0.4) | (X - prev < -0.25)
    np.testing.assert_array_equal(flags[0], limited)
    assert limited.sum() > 100


def test_memoryless_blocks():
    np.testing.assert_array_equal(Saturation(-3, 5).apply(X, DT), np.clip(X, -3, 5))
    q = Quantizer(1.2).apply(X, DT)
    np.testing.assert_allclose(q, 1.2 * np.floor(X / 1.2 + 0.5), atol=1e-12)
    assert np.all(np.abs(q - X) <= 0.6 + 1e-12)
    np.testing.assert_allclose(Quantizer(1.0, mode="floor").apply(X, DT), np.floor(X), atol=1e-12)
    dz = DeadZone(2.0, center=1.0).apply(X, DT)
    np.testing.assert_allclose(dz, np.where(X > 3, X - 2, np.where(X < -1, X + 2, 1.0)), atol=1e-12)
    pts = [(-10, -30), (0, 0), (5, 5), (20, 8)]
    st = Static(pts).apply(X, DT)
    inside = (X >= -10) & (X <= 20)
    np.testing.assert_allclose(st[inside], np.interp(X[inside], *zip(*pts)), atol=1e-12)


def test_backlash_equation():
    w = 1.5
    y = Backlash(width=2 * w).apply(X, DT)
    expected = _loop(lambda p, v: min(max(p, v - w), v + w), X, X[0])
    np.testing.assert_allclose(y, expected, atol=1e-12)


def test_dynamics_block_matches_python_control_zoh():
    block = Dynamics.from_string("442/((s+45)*(s+9.7))")
    u = np.repeat(RNG.normal(0, 1, 100), 10)
    u[0] = 0.0
    y = block.apply(u, DT)
    sysd = control.c2d(control.tf(list(block.num), list(block.den)), DT, "zoh")
    expected = control.forced_response(sysd, np.arange(u.size) * DT, u).outputs
    np.testing.assert_allclose(y, expected, atol=1e-10)
    lag = Lag(tau=0.02, gain=2.0)
    step = lag.apply(np.concatenate([[0.0], np.ones(200)]), DT)
    k = np.arange(201)
    np.testing.assert_allclose(step, np.where(k > 0, 2.0 * (1 - np.exp(-(k - 1) * DT / 0.02)), 0.0), atol=1e-12)


def test_sample_hold_at_400_hz_on_a_1_khz_grid():
    t = np.arange(20) * DT
    y = SampleHold(400).apply(t, DT)
    # samples at 0, 2.5, 5, 7.5 ... ms are read at the first step at or after: 0, 3, 5, 8, 10 ...
    assert (y * 1000).round(6).tolist()[:11] == [0, 0, 0, 3, 3, 5, 5, 5, 8, 8, 10]


def test_supply_sag_voltage_and_brown_out():
    sag = SupplySag(v_open=16.8, r_internal=0.1, i_static=0.04, i_dynamic=1.0, tau=0.05, v_reset=5.0,
                    reset_time=0.01)
    u = np.concatenate([np.full(5, 200.0), np.full(30, 230.0), np.full(30, 330.0)])
    y, flags = apply_chain([sag], u, DT, return_flags=True)
    v_nom = 16.8 - 0.1 * 0.04 * 200  # gain 1 at rest
    assert y[0] == pytest.approx(200.0)
    # first step of +30: current 0.04*230 + 1.0*30 = 39.2 A -> 12.88 V
    assert y[5] == pytest.approx(230 * (16.8 - 0.1 * 39.2) / v_nom, rel=1e-12)
    # +100 more: more than 100 A of inrush pulls the pack below 5 V: 10 ms of reset with the drive off
    off = np.flatnonzero(flags[0])
    assert off[0] == 35 and off.size == 10 and np.all(y[off] == 0.0)


def test_delay_block_shifts_whole_steps_and_noise_is_seeded():
    y = apply_chain([Delay(0.003)], np.arange(10.0), DT)
    assert y.tolist() == [0, 0, 0, 0, 1, 2, 3, 4, 5, 6]
    a = Noise(std=2.0).apply(np.zeros(5000), DT, seed=4)
    b = Noise(std=2.0).apply(np.zeros(5000), DT, seed=4)
    np.testing.assert_array_equal(a, b)
    assert np.std(a) == pytest.approx(2.0, rel=0.05)


def test_psd_signal_has_the_psd():
    table = ((2.0, 1.0), (30.0, 1.0), (300.0, 1e-3))
    n, dt = 2**16, DT
    x = psd_signal(table, n, dt, np.random.default_rng(0))
    assert np.mean(x**2) == pytest.approx(psd_variance(table, n, dt), rel=1e-12)
    # integral of the table: flat part 28 + log-log segment from 30 to 300 (slope -3)
    exact = 28.0 + 15.0 * (1 - 0.01)  # int_30^300 (w/30)^-3 dw = 15 (1 - (1/10)^2)
    assert psd_variance(table, n, dt) == pytest.approx(exact, rel=5e-3)
    f, p = welch(x, fs=1 / dt, nperseg=4096)  # one-sided, unit^2/Hz
    w = 2 * np.pi * f
    band = (w > 5) & (w < 25)
    assert np.mean(p[band] / (2 * np.pi)) == pytest.approx(1.0, rel=0.15)  # unit^2/(rad/s)
    assert psd_value(table, np.array([1.0, 1000.0])).tolist() == [0.0, 0.0]


def test_record_disturbance_from_csv(tmp_path):
    path = tmp_path / "d.csv"
    path.write_text("time,load\n0,0\n0.5,1\n1.0,0\n")
    d = RecordDisturbance.from_csv(path, "time", "load", at="input", scale=2.0)
    assert d.signal(np.array([0.25, 0.5]), None).tolist() == [1.0, 2.0]
    with pytest.raises(DataError, match="covers 0 to 1 s"):
        d.signal(np.array([0.0, 2.0]), None)
    with pytest.raises(DataError, match="no column 'speed'; columns are: time, load"):
        RecordDisturbance.from_csv(path, "time", "speed")
    path.write_text("time,load\n0,0\n0,1\n")
    with pytest.raises(DataError, match="not strictly increasing at row 2"):
        RecordDisturbance.from_csv(path, "time", "load")
    with pytest.raises(ModelError, match="frequencies must be > 0"):
        PsdDisturbance(((0.0, 1.0), (1.0, 1.0)))


@pytest.mark.parametrize("make, message", [
    (lambda: RateLimit(0), "rate must be > 0"),
    (lambda: Quantizer(-1), "step must be a finite number > 0"),
    (lambda: Static([(0, 0), (0, 1)]), "strictly increasing"),
    (lambda: Dynamics.from_string("1/s"), "pole at s = 0"),
    (lambda: Dynamics.from_string("1/(s-1)"), "unstable"),
    (lambda: Noise(), "give std > 0 or a psd"),
    (lambda: SupplySag(v_open=12, r_internal=-1), "r_internal must be"),
])
def test_block_validation(make, message):
    with pytest.raises(ModelError, match=message):
        make()


def test_a_symmetric_table_is_exactly_zero_at_its_middle():
    eps, level = 1.7303501862000147e-06, 0.48608418533100345  # a relay as a steep table (seed 111 loop 84)
    relay = Static(((-2 * eps, -level), (-eps, -level), (eps, level), (2 * eps, level)))
    y = relay.apply(np.array([0.0, eps / 2, -eps / 2, eps, 3 * eps]), DT)
    assert y[0] == 0.0
    assert y[1] == pytest.approx(level / 2, rel=1e-12) and y[2] == pytest.approx(-level / 2, rel=1e-12)
    assert y[3] == level and y[4] == level
