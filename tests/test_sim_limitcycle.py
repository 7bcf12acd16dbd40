"""Describing-function predictions against simulated limit cycles; oscillation detection."""

import numpy as np
import pytest

from synth.controllers import Controller
from synth.plant import Plant
from synth.sim.blocks import RateLimit, Saturation
from synth.sim.describing import (
    dead_zone_df,
    harmonic_balance,
    numeric_df,
    rate_limiter_df,
    saturation_df,
)
from synth.sim.limitcycle import detect_oscillation
from synth.sim.loops import NonlinearLoop
from synth.sim.signals import step_reference
from synth.sim.simulator import simulate


def _simulated_cycle(plant: str, k: float, block, step: float, t_end: float = 150.0):
    loop = NonlinearLoop(Plant.from_string(plant), Controller("P", {"kp": k}), actuator=[block], dt=0.001)
    r = simulate(loop, step_reference(0.0, step), t_end)
    # the nonlinearity's input is the controller command
    return detect_oscillation(r.t, r.command, window=50.0)


def test_saturation_loop_df_within_10_percent_of_simulation():
    k, plant = 20.0, "1/(s*(s+1)*(s+2))"
    G = Plant.from_string(plant)
    [pred] = harmonic_balance(lambda w: k * G.freqresp(w), lambda a, w: saturation_df(a, 1.0), (0.1, 10), (1, 1e3))
    # closed form: w = sqrt(2) where the phase is -180 deg, N(A) = 1/(k |G|) = 6/20
    assert pred.frequency == pytest.approx(np.sqrt(2), rel=1e-9)
    assert float(saturation_df(pred.amplitude, 1.0)) == pytest.approx(6 / 20, rel=1e-9)
    assert pred.stable
    osc = _simulated_cycle(plant, k, Saturation(-1, 1), 0.1)
    assert osc.present
    assert osc.fundamental_amplitude == pytest.approx(pred.amplitude, rel=0.10)
    assert osc.frequency == pytest.approx(pred.frequency, rel=0.10)


def test_rate_limited_loop_df_within_10_percent_of_simulation():
    k, rate, plant = 12.0, 1.0, "1/(s+1)^3"
    G = Plant.from_string(plant)
    [pred] = harmonic_balance(lambda w: k * G.freqresp(w), lambda a, w: rate_limiter_df(a, w, rate),
                              (0.05, 20), (1e-4, 1e4))
    assert pred.stable
    osc = _simulated_cycle(plant, k, RateLimit(rate), 0.01)
    assert osc.present
    assert osc.fundamental_amplitude == pytest.approx(pred.amplitude, rel=0.10)
    assert osc.frequency == pytest.approx(pred.frequency, rel=0.10)


def test_unstable_rate_limit_cycle_is_a_threshold():
    """K/(s(s+1)) with a rate limit: with the textbook describing function harmonic balance has a
    closed form, w^2 = 8K/pi^2 - 1; the cycle is unstable: smaller excitations decay, larger grow."""
    k, rate = 10.0, 1.0
    G = Plant.from_string("1/(s*(s+1))")
    [textbook] = harmonic_balance(lambda w: k * G.freqresp(w),
                                  lambda a, w: rate_limiter_df(a, w, rate, exact=a * w < np.pi * rate / 2),
                                  (0.1, 10), (1e-3, 1e3))
    w = np.sqrt(8 * k / np.pi**2 - 1)
    assert textbook.frequency == pytest.approx(w, rel=1e-8)
    assert textbook.amplitude == pytest.approx(np.pi * rate * np.sqrt(1 + w * w) / (2 * w * w), rel=1e-8)
    # there R/(A w) = 0.596: the output is not yet a pure triangle, and the exact N moves the cycle
    [pred] = harmonic_balance(lambda w: k * G.freqresp(w), lambda a, w: rate_limiter_df(a, w, rate),
                              (0.1, 10), (1e-3, 1e3))
    assert rate / (textbook.amplitude * textbook.frequency) == pytest.approx(0.596, abs=1e-3)
    assert pred.frequency == pytest.approx(2.729, abs=1e-3)
    assert not pred.stable and not textbook.stable
    loop = NonlinearLoop(G, Controller("P", {"kp": k}), actuator=[RateLimit(rate)], dt=0.001)
    small = simulate(loop, step_reference(0, 0.2 * pred.amplitude / k), 40.0)  # command jump 0.2 A
    large = simulate(loop, step_reference(0, 5.0 * pred.amplitude / k), 40.0)
    err_small = np.abs(small.output - small.reference)
    assert err_small[-1000:].max() < 1e-3 * err_small.max()
    assert np.abs(large.command[-2000:]).max() > 20 * pred.amplitude


def test_rate_limiter_df_regimes_against_simulation():
    for a, w, r in [(1.0, 1.0, 0.9), (1.0, 1.0, 0.7), (1.0, 1.0, 2 / np.pi), (1.0, 1.0, 0.55),
                    (2.0, 3.0, 1.0)]:
        exact = rate_limiter_df(a, w, r)
        sim = numeric_df([RateLimit(r)], a, w, points=4000, periods=60)
        assert abs(exact - sim) < 2e-3 * abs(exact), (a, w, r)
    assert rate_limiter_df(1.0, 1.0, 1.0) == 1.0
    # the output becomes a pure triangle at A w = R sqrt(1 + pi^2/4): the two forms meet there
    rho = 1 / np.sqrt(1 + np.pi**2 / 4)
    assert abs(rate_limiter_df(1.0, 1.0, rho * (1 + 1e-7)) - rate_limiter_df(1.0, 1.0, rho * (1 - 1e-7))) < 1e-5
    # the textbook form, used from A w = pi R/2, is off by 19 degrees there
    textbook = rate_limiter_df(1.0, 1.0, 2 / np.pi, exact=False)
    assert textbook == pytest.approx(8 / np.pi**2)
    assert np.degrees(np.angle(rate_limiter_df(1.0, 1.0, 2 / np.pi))) == pytest.approx(-18.9, abs=0.1)


def test_saturation_and_dead_zone_df_against_simulation():
    for a in (0.5, 1.5, 4.0, 20.0):
        assert abs(numeric_df([Saturation(-1, 1)], a, 2.0) - saturation_df(a, 1.0)) < 1e-3
    assert float(dead_zone_df(3.0, 1.0)) == pytest.approx(1 - float(saturation_df(3.0, 1.0)))


def test_detect_oscillation_cases():
    t = np.arange(0, 20, 0.001)
    rng = np.random.default_rng(1)
    osc = detect_oscillation(t, 5 + 2 * np.sin(7 * t) + 0.05 * rng.standard_normal(t.size))
    assert osc.present and osc.frequency == pytest.approx(7, rel=1e-3)
    assert osc.fundamental_amplitude == pytest.approx(2, rel=1e-2) and osc.center == pytest.approx(5, abs=0.05)
    assert not detect_oscillation(t, 0.3 * rng.standard_normal(t.size), min_amplitude=0.0).present
    assert not detect_oscillation(t, np.exp(-0.5 * t) * np.sin(7 * t)).present
    assert not detect_oscillation(t, 0.5 * np.sin(7 * t), min_amplitude=1.0).present
    grow = detect_oscillation(t, np.exp(0.4 * t) * np.sin(7 * t))
    assert grow.present and grow.diverging
    drift = detect_oscillation(t, np.exp(0.5 * t))
    assert not drift.present and drift.diverging


def test_sampled_loop_response_equals_python_control_pulse_transfer():
    import control

    from synth.sim.describing import sampled_loop_response
    from synth.sim.loops import NonlinearLoop

    G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
    loop = NonlinearLoop(G, Controller.from_string("PI(kp=2, ki=30)"), dt=0.001, loop_delay=0.004)
    w = np.array([0.5, 20.0, 150.0, 900.0])
    Ld = (control.c2d(control.tf([2.0, 30.0], [1.0, 0.0]), 0.001, "tustin")
          * control.c2d(control.tf(G.num, G.den), 0.001, "zoh") * control.tf([1], [1, 0, 0, 0, 0], 0.001))
    expected = np.array([Ld(np.exp(1j * x * 0.001)) for x in w])
    np.testing.assert_allclose(sampled_loop_response(loop, w), expected, rtol=1e-7)


def test_loop_prediction_matches_simulation_with_a_delay():
    """A saturated loop whose oscillation comes from a 20 ms delay: the harmonic balance on the
    sampled loop predicts the simulated cycle within 10 %."""
    from synth.sim.describing import predict_loop_cycles

    G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
    loop = NonlinearLoop(G, Controller("P", {"kp": 6.0}), actuator=[Saturation(-40, 40)], loop_delay=0.02)
    [pred] = predict_loop_cycles(loop, 0.0, (10, 1000), points=80)
    r = simulate(loop, step_reference(0.0, 10.0), 4.0)
    osc = detect_oscillation(r.t, r.command, window=2.0)
    assert osc.present and pred.cycle.stable
    assert osc.fundamental_amplitude == pytest.approx(pred.cycle.amplitude, rel=0.10)
    assert osc.period == pytest.approx(pred.cycle.period, rel=0.10)
    out = detect_oscillation(r.t, r.output, window=2.0)
    assert out.fundamental_amplitude == pytest.approx(pred.output_amplitude, rel=0.10)
