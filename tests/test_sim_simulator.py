"""The sampled simulator against independently built python-control / scipy models."""

import control
import numpy as np
import pytest
from scipy.linalg import expm

from synth.controllers import Controller
from synth.errors import ModelError
from synth.plant import Plant
from synth.sim.blocks import Backlash, DeadZone, Dynamics, Lag, RateLimit, SampleHold, Saturation, Static
from synth.sim.loops import NonlinearLoop, OpenLoop, OperatingPoint
from synth.sim.signals import StepDisturbance, step_reference
from synth.sim.simulator import (
    simulate,
    simulate_batch,
    simulate_open_loop,
    simulate_open_loop_batch,
)

from .conftest import X4_PLANT

DT = 0.001
OFF = [RateLimit(1e12), Saturation(-1e12, 1e12), DeadZone(0.0), Backlash(0.0),
       Static([(-1e6, -1e6), (1e6, 1e6)])]


def _reference(t):
    return 870.0 + 50.0 * (t >= 0.01) + 20.0 * np.sin(37.0 * t) * (t >= 0.2)


def _python_control_loop(plant_tf, controller, dt, delay_steps, method="tustin"):
    """The same sampled loop built with python-control only: c2d(G) z^-m, c2d(C), unity feedback."""
    Gd = control.c2d(plant_tf, dt, method="zoh")
    cnum, cden = controller.tf()
    Cd = control.c2d(control.tf(cnum, cden), dt, method=method) if cden.size > 1 else \
        control.tf(cnum, cden, dt)
    Z = control.tf([1.0], [1.0] + [0.0] * delay_steps, dt)
    return control.feedback(Cd * Gd * Z, 1)


@pytest.mark.parametrize("controller, delay_steps, method", [
    (Controller("P", {"kp": 3.0}), 0, "tustin"),
    (Controller.from_string("PI(kp=1.2, ki=20)"), 3, "tustin"),
    (Controller.from_string("PI(kp=1.2, ki=20)"), 2, "zoh"),
    (Controller.from_string("leadlag(k=2, z=20, p=200)"), 5, "tustin"),
])
def test_blocks_off_match_python_control_forced_response(controller, delay_steps, method):
    G = Plant.from_string(X4_PLANT)
    loop = NonlinearLoop(G, controller, actuator=OFF, sensor=[SampleHold(1 / DT)], dt=DT,
                         loop_delay=delay_steps * DT, operating_point=OperatingPoint(200, 870),
                         discretization=method)
    t_end = 0.6
    result = simulate(loop, _reference, t_end)
    T = _python_control_loop(control.tf(G.num, G.den), controller, DT, delay_steps, method)
    resp = control.forced_response(T, result.t, result.reference - 870.0)
    y_pc = np.asarray(resp.outputs) + 870.0
    dev = result.output - 870.0
    assert np.max(np.abs(dev - (y_pc - 870.0))) <= 1e-6 * np.max(np.abs(dev))


def test_folded_lag_and_sensor_dynamics_match_python_control():
    """Linear blocks next to the plant are folded into its exact discretization."""
    G = Plant.from_string(X4_PLANT)
    lag = Lag(tau=0.004)
    sensor = Dynamics.from_string("442/((s+45)*(s+9.7))")
    C = Controller("P", {"kp": 2.0})
    loop = NonlinearLoop(G, C, actuator=[Saturation(-1e9, 1e9), lag], sensor=[sensor, SampleHold(1000)], dt=DT)
    result = simulate(loop, step_reference(0.0, 1.0), 1.0)
    s = control.tf("s")
    plant_and_lag = control.tf(G.num, G.den) / (0.004 * s + 1)
    forward = control.c2d(2.0 * plant_and_lag, DT, "zoh")
    measured_path = control.c2d(2.0 * plant_and_lag * control.tf(sensor.num, sensor.den), DT, "zoh")
    # y_meas = M/(1+M) r with M the sampled path through the sensor; y = F (r - y_meas)
    y_meas = control.forced_response(control.feedback(measured_path, 1), result.t, result.reference).outputs
    y_true = control.forced_response(forward, result.t, result.reference - y_meas).outputs
    np.testing.assert_allclose(result.measured, y_meas, atol=1e-9, rtol=1e-6)
    np.testing.assert_allclose(result.output, y_true, atol=1e-9, rtol=1e-6)


def _delayed_zoh_response(G: Plant, u: np.ndarray, dt: float, delay: float, t: np.ndarray) -> np.ndarray:
    """Exact response of G to the piecewise-constant u delayed by `delay`: a sum of shifted steps,
    each step response s(tau) = C A^-1 (e^{A tau} - I) B from a matrix exponential."""
    A, B, C, D = control.ssdata(control.tf2ss(control.tf(G.num, G.den)))
    taus = np.arange(t.size) * dt - delay
    step = np.array([0.0 if tau <= 0 else float((C @ np.linalg.solve(A, expm(A * tau) - np.eye(A.shape[0]))
                                                 @ B + D)[0, 0]) for tau in taus])
    du = np.diff(np.concatenate([[0.0], u]))
    y = np.zeros_like(t)
    for j in np.flatnonzero(du):
        y[j:] += du[j] * step[: t.size - j]
    return y


@pytest.mark.parametrize("delay", [0.0, 0.0025, 0.0137])
def test_open_loop_fractional_delay_is_exact(delay):
    G = Plant.from_string(X4_PLANT, delay=delay)
    rng = np.random.default_rng(3)
    u = np.repeat(rng.uniform(-10, 10, 40), 7)
    u[0] = 0.0
    result = simulate_open_loop(G, u, DT)
    expected = _delayed_zoh_response(G, u, DT, delay, result.t)
    np.testing.assert_allclose(result.output, expected, atol=1e-9 * np.max(np.abs(expected)))


def test_operating_point_and_absolute_limits():
    """The 0-255 PWM range is absolute: the controller's deviation is added to the 200 PWM trim."""
    G = Plant.from_string(X4_PLANT)
    loop = NonlinearLoop(G, Controller("P", {"kp": 3.0}), actuator=[Saturation(0, 255)],
                         operating_point=OperatingPoint(200, 870))
    r = simulate(loop, step_reference(820, 920), 0.3)
    k_g0 = 3.0 * G.dc_gain()
    rest = 870 + k_g0 * (820 - 870) / (1 + k_g0)  # P-control rest point at the initial reference
    assert r.output[0] == pytest.approx(rest, rel=1e-12)
    assert r.actuator.max() == 255.0
    assert r.command.max() == pytest.approx(200 + 3.0 * (920 - rest), rel=1e-9)  # asked for > 255 PWM
    assert r.time_active("saturated") > 0


def test_batch_equals_single_runs_and_is_independent_of_order():
    G = Plant.from_string(X4_PLANT)
    base = NonlinearLoop(G, Controller("P", {"kp": 3.0}), actuator=[RateLimit(10000), Saturation(0, 255)],
                         sensor=[SampleHold(400)], operating_point=OperatingPoint(200, 870))
    variants = [base.with_gain("kp", k) for k in (1.0, 3.0, 8.0)] + [base.replace(loop_delay=0.0125)]
    batch = simulate_batch(variants, step_reference(820, 920), 0.4)
    for i, v in enumerate(variants):
        single = simulate(v, step_reference(820, 920), 0.4)
        np.testing.assert_array_equal(batch.output[i], single.output)
        np.testing.assert_array_equal(batch.flags[i], single.flags)


def test_controller_rate_holds_output_between_updates():
    G = Plant.from_string(X4_PLANT)
    loop = NonlinearLoop(G, Controller("P", {"kp": 3.0}), dt=0.0005, controller_rate=500)
    r = simulate(loop, step_reference(0.0, 1.0), 0.05)
    steps = np.flatnonzero(np.diff(r.command) != 0) + 1
    assert np.all(steps % 4 == 0)  # 2000 Hz simulation, 500 Hz controller
    with pytest.raises(ModelError, match="whole number"):
        NonlinearLoop(G, Controller("P", {"kp": 3.0}), dt=0.001, controller_rate=300)


def test_pi_anti_windup_limits_overshoot_after_saturation():
    G = Plant.from_string("1/(s+1)")
    C = Controller.from_string("PI(kp=2, ki=10)")
    plain = NonlinearLoop(G, C, actuator=[Saturation(-1.2, 1.2)], dt=0.001)
    guarded = plain.replace(anti_windup=True)
    a = simulate(plain, step_reference(0, 1.0), 6.0)
    b = simulate(guarded, step_reference(0, 1.0), 6.0)
    assert a.output.max() > 1.15 and b.output.max() < 1.05  # wound-up integrator: 19 % vs 3.5 %
    assert b.output[-1] == pytest.approx(1.0, abs=1e-3)
    # without limits in action the anti-windup form changes nothing
    free = simulate(plain.replace(actuator=(Saturation(-100, 100),)), step_reference(0, 1.0), 2.0)
    free_aw = simulate(plain.replace(actuator=(Saturation(-100, 100),), anti_windup=True),
                       step_reference(0, 1.0), 2.0)
    np.testing.assert_allclose(free.output, free_aw.output, atol=1e-9)


def test_output_step_disturbance_is_rejected_by_integral_action():
    G = Plant.from_string("10/(s+10)")
    loop = NonlinearLoop(G, Controller.from_string("PI(kp=1, ki=20)"), dt=0.001)
    r = simulate(loop, 0.0, 3.0, disturbances=[StepDisturbance(5.0, at_time=0.1, at="output")])
    assert r.output[99] == 0.0 and r.output[100] == 5.0  # the disturbance shows at once at the output
    assert abs(r.output[-1]) < 1e-6


def test_open_loop_batch_and_rest_start():
    G = Plant.from_string("2/(0.05*s+1)")
    u = np.concatenate([np.full(10, 100.0), np.full(1000, 130.0)])
    loops = [OpenLoop(G, (RateLimit(r),), dt=DT, operating_point=OperatingPoint(100, 50)) for r in (1e3, 1e4)]
    batch = simulate_open_loop_batch(loops, u)
    assert batch.output[:, 0].tolist() == [50.0, 50.0]  # at rest at the trim
    assert batch.output[0, -1] == pytest.approx(50 + 2 * 30, abs=1e-6)
    slow, fast = batch[0], batch[1]
    assert slow.time_active("rate_limited") == pytest.approx(0.029, abs=1e-9)
    assert fast.time_active("rate_limited") == pytest.approx(0.002, abs=1e-9)


def test_bad_inputs_raise_model_errors():
    G = Plant.from_string("1/(s+1)")
    C = Controller("P", {"kp": 1.0})
    with pytest.raises(ModelError, match="dt must be > 0"):
        NonlinearLoop(G, C, dt=0.0)
    with pytest.raises(ModelError, match="reference has 3 samples"):
        simulate(NonlinearLoop(G, C), np.zeros(3), 1.0)
    with pytest.raises(ModelError, match="anti_windup needs the actuator chain"):
        simulate(NonlinearLoop(G, Controller.from_string("PI(1, 1)"), anti_windup=True), 1.0, 0.1)
    with pytest.raises(ModelError, match=r"min .* must be below max"):
        Saturation(5, 1)


def test_nonlinear_x4_loop_matches_a_hand_written_step_loop():
    """Saturation, rate limit, 400 Hz sample-and-hold and quantizer against a plain loop written
    from the equations (independent of the kernel and the block code). The hand loop ramps from the
    PWM actually applied: that is the chain [saturation, rate_limit]; in the order
    [rate_limit, saturation] the limiter's own state may run beyond 255 PWM while the output is clipped."""
    from synth.sim.blocks import Quantizer

    G = Plant.from_string(X4_PLANT)
    kp = 4.0
    loop = NonlinearLoop(G, Controller("P", {"kp": kp}), actuator=[Saturation(0, 255), RateLimit(10000)],
                         sensor=[SampleHold(400), Quantizer(1.2)], operating_point=OperatingPoint(200, 870))
    r = simulate(loop, step_reference(820, 920), 1.0)
    other_order = simulate(loop.replace(actuator=(RateLimit(10000), Saturation(0, 255))),
                           step_reference(820, 920), 1.0)
    ss = control.c2d(control.tf2ss(control.tf(G.num, G.den)), DT, "zoh")
    Ad, Bd, Cd = np.asarray(ss.A), np.asarray(ss.B), np.asarray(ss.C)[0]
    g0 = G.dc_gain()
    y_rest = 870 + kp * g0 * (820 - 870) / (1 + kp * g0)
    x = np.linalg.solve(np.eye(2) - Ad, Bd[:, 0] * (y_rest - 870) / g0)
    u_prev, held, next_sample, ys = 200 + kp * (820 - y_rest), y_rest, 0.0, []
    for k in range(r.t.size):
        y = 870 + float(Cd @ x)
        if k >= next_sample - 1e-9:
            held, next_sample = y, next_sample + 2.5
        u = 200 + kp * (920 - 1.2 * np.floor(held / 1.2 + 0.5))
        u = min(max(min(max(u, u_prev - 10.0), u_prev + 10.0), 0.0), 255.0)  # rate limit, then 0-255
        u_prev = u
        x = Ad @ x + Bd[:, 0] * (u - 200)
        ys.append(y)
    np.testing.assert_allclose(r.output, ys, atol=1e-8)
    assert np.max(np.abs(other_order.output - r.output)) > 0.1


def test_monte_carlo_batch_with_noise_and_psd_disturbance_is_reproducible():
    from synth.sim.blocks import Noise
    from synth.sim.signals import PsdDisturbance

    G = Plant.from_string(X4_PLANT)
    loop = NonlinearLoop(G, Controller("P", {"kp": 3.0}), actuator=[Saturation(0, 255)],
                         sensor=[Noise(std=2.0)], operating_point=OperatingPoint(200, 870))
    dist = [PsdDisturbance(((1.0, 4.0), (30.0, 4.0), (80.0, 0.04)), at="output")]
    a = simulate_batch([loop] * 4, 870.0, 2.0, disturbances=dist, seed=11)
    b = simulate_batch([loop] * 4, 870.0, 2.0, disturbances=dist, seed=11)
    np.testing.assert_array_equal(a.output, b.output)
    assert not np.allclose(a.output[0], a.output[1])  # variants draw independent noise
    noise = a.measured - a.output
    assert np.std(noise) == pytest.approx(2.0, rel=0.05)
    # the loop attenuates the low-frequency disturbance: |S(0)| = 1/(1 + 3*1.908) = 0.149
    c = simulate_batch([loop.without("noise")], 870.0, 2.0, disturbances=dist, seed=11)
    open_loop_disturbance = np.std(dist[0].signal(c.t, np.random.default_rng([11, 0])))
    assert np.std(c.output[0] - 870) < 0.5 * open_loop_disturbance


def test_supply_sag_brown_out_in_the_loop():
    from synth.sim.blocks import SupplySag

    G = Plant.from_string(X4_PLANT)
    sag = SupplySag(v_open=16.8, r_internal=0.1, i_static=0.04, i_dynamic=1.5, tau=0.1, v_reset=5.0,
                    reset_time=0.02)
    loop = NonlinearLoop(G, Controller("P", {"kp": 3.0}), actuator=[Saturation(0, 255), sag],
                         operating_point=OperatingPoint(200, 870))
    small = simulate(loop, step_reference(865, 875), 0.5)
    big = simulate(loop, step_reference(820, 920), 0.5)
    assert small.time_active("brown_out") == 0.0
    assert big.time_active("brown_out") >= 0.02 and big.actuator.min() == 0.0  # the drive resets: motor off
