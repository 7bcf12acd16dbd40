"""The delayed linear step response against scipy's solve_ivp by the method of steps (written here, apart
from synth's zero-order-hold simulation): random stable loops with delays, P, PI and PID controllers,
including a PI whose slow integral tail makes the horizon long.

Before the simulation step followed the loop's crossover, the step was 1/20000 of the horizon: a PI with
``ki = 0.004`` on ``5/(s+1)^2`` behind 50 ms was simulated for 512 s at 25.6 ms steps and overshot 24.9 %
where the reference gives 24.0 % (a ``max_overshoot: 24.5`` would have been called not met).

The holds' error is of first order in the step: a PID behind 0.33 s (seed 1's first delayed problem of
``benchmarks/step_design_verification.py``) overshot 9.998 % held at 0.66 ms where the method of steps gives
10.123 %, so a design at a 10 % limit was a false "met". The step is now extrapolated from two runs (Richardson):
within 1e-4 of the reference here, where 2e-3 was the tolerance before."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements.step_response import StepResponse
from synth.timeresp import discrete_loop, linear_step, step_response


def _companion(num, den):
    """Controllable canonical form of a proper ``num/den`` (highest power first): (A, B, C, D)."""
    den = np.asarray(den, float)
    num = np.concatenate([np.zeros(len(den) - len(num)), np.asarray(num, float)]) / den[0]
    den = den / den[0]
    n = len(den) - 1
    d = num[0]
    c = (num[1:] - d * den[1:])[::-1]
    a = np.zeros((n, n))
    if n:
        a[:-1, 1:] = np.eye(n - 1)
        a[-1, :] = -den[1:][::-1]
    b = np.zeros(n)
    if n:
        b[-1] = 1.0
    return a, b, c, d


def _reference(plant_num, plant_den, delay, c_num, c_den, t_end, t_out):
    """Unit step of the loop, exact delay, by the method of steps (strictly proper plant)."""
    ap, bp, cp, dp = _companion(plant_num, plant_den)
    ac, bc, cc, dc = _companion(c_num, c_den)
    assert dp == 0.0
    nc, np_ = len(bc), len(bp)

    def u_of(x):
        y = cp @ x[nc:]
        return (cc @ x[:nc] if nc else 0.0) + dc * (1.0 - y)

    pieces = []  # dense outputs of the state over [k tau, (k + 1) tau]

    def state_at(t):
        if t < 0 or not pieces:
            return np.zeros(nc + np_)
        k = min(int(t / delay), len(pieces) - 1)
        return pieces[k](t)

    x0 = np.zeros(nc + np_)
    k = 0
    while k * delay < t_end:
        def rhs(t, x):
            y = cp @ x[nc:]
            e = 1.0 - y
            ud = u_of(state_at(t - delay)) if t - delay >= 0 else 0.0
            out = np.empty(nc + np_)
            if nc:
                out[:nc] = ac @ x[:nc] + bc * e
            out[nc:] = ap @ x[nc:] + bp * ud
            return out

        sol = solve_ivp(rhs, (k * delay, (k + 1) * delay), x0, method="DOP853", rtol=1e-10, atol=1e-12,
                        dense_output=True)
        pieces.append(sol.sol)
        x0 = sol.y[:, -1]
        k += 1
    return np.array([cp @ state_at(t)[nc:] for t in t_out])


CASES = [  # plant, delay, controller: one with a slow integral tail, the others drawn below
    ("5/(s+1)^2", 0.05, Controller("PI", {"kp": 1.5, "ki": 0.004})),
]


def _random_case(seed):
    rng = np.random.default_rng(seed)
    poles = -rng.uniform(0.3, 5.0, int(rng.integers(1, 4)))
    gain = float(np.prod(-poles) * rng.uniform(0.5, 3.0))
    plant = f"{gain:.6g}/(" + "*".join(f"(s+{-p:.6g})" for p in poles) + ")"
    delay = float(rng.uniform(0.02, 0.3))
    kind = ["P", "PI", "PID"][seed % 3]
    params = {"P": {"kp": 0.0}, "PI": {"kp": 0.0, "ki": 0.0}, "PID": {"kp": 0.0, "ki": 0.0, "kd": 0.0, "tf": 0.05}}[kind]
    for _ in range(200):  # a stable loop with some overshoot
        trial = {k: (float(rng.uniform(0.2, 1.5)) if k in ("kp",) else float(rng.uniform(0.05, 0.8)) if k == "ki"
                     else float(rng.uniform(0.0, 0.3)) if k == "kd" else v) for k, v in params.items()}
        c = Controller(kind, trial)
        if Loop(Plant.from_string(plant, delay=delay), c).stability().stable:
            return plant, delay, c
    pytest.skip("no stable loop drawn")


@pytest.mark.parametrize("case", range(-1, 8))
def test_delayed_step_matches_the_method_of_steps(case):
    plant_text, delay, controller = CASES[0] if case < 0 else _random_case(case)
    plant = Plant.from_string(plant_text, delay=delay)
    loop = Loop(plant, controller)
    requirement = StepResponse(max_overshoot=1000)
    result = requirement.evaluate(loop)
    horizon = min(result.details["horizon"], 40.0)  # the reference integrates piece by piece: keep it short
    run = linear_step(loop, horizon, 2001)
    t, y, dt = run.t, run.y, run.dt
    c_num, c_den = controller.tf()
    ref = _reference(plant.num, plant.den, delay, c_num, c_den, horizon, t)
    assert np.max(np.abs(y - ref)) <= 1e-4 * max(1.0, np.max(np.abs(ref))), (plant_text, controller, dt)
    # the error estimate is an honest bound (up to the reference's own tolerance)
    assert np.max(np.abs(y - ref)) <= np.max(run.error) + 1e-8 * np.max(np.abs(ref)), (plant_text, controller)
    if case < 0:  # the overshoot the requirement reports, over its own (long) horizon, against the reference's
        peak = float(np.max(ref))
        assert abs(result.details["overshoot"] - 100 * (peak - 1.0)) < 0.01


def test_a_pid_at_its_overshoot_limit_is_measured_as_the_method_of_steps_does():
    plant = Plant.from_string("3.83785544493/(s^2 + 8.58985458385*s + 2.89595733607)", delay=0.3291466554043403)
    controller = Controller("PID", {"kp": 3.89572409167841, "ki": 2.402554696694673, "kd": 0.8413664603555218,
                                    "tf": 0.028447699154996443})
    result = StepResponse(max_overshoot=10).evaluate(Loop(plant, controller))
    t = np.linspace(0.0, 6.0, 6001)
    ref = _reference(plant.num, plant.den, plant.delay, *controller.tf(), 6.0, t)
    assert 100 * (float(np.max(ref)) - 1.0) > 10.1  # the design is over the limit
    assert abs(result.details["overshoot"] - 100 * (float(np.max(ref)) - 1.0)) < 0.01
    assert not result.met


def test_a_delay_shorter_than_the_step_is_held_exactly():
    """A delay under the simulation step (here 1/25000 of the horizon) was one step of delay, too long, and not
    extrapolated: 1.35e-3 off the method of steps on a PI behind 0.15 ms (0.13 points of overshoot). The step is
    now a quarter of the delay (the coarsest of the three runs holds it as one step). Reference: the loop with
    the delay's first-order Pade approximation (its error is of order (w delay)^3, 1e-10 at the loop's
    bandwidth), stepped by scipy.signal (the method of steps would need 25,000 intervals)."""
    from scipy import signal

    delay = 4e-5
    plant = Plant.from_string("20/((s+1)*(s+4))", delay=delay)
    controller = Controller("PI", {"kp": 1.2, "ki": 3.0})
    loop = Loop(plant, controller)
    args, dt = discrete_loop(loop, 1.0)
    assert args[-2] == 4 and dt == pytest.approx(delay / 4)
    t, y, _ = step_response(loop, 1.0, 1001)
    c_num, c_den = controller.tf()
    l_num = np.polymul(np.polymul(c_num, plant.num), [-delay / 2, 1.0])
    l_den = np.polymul(np.polymul(c_den, plant.den), [delay / 2, 1.0])
    _, ref = signal.step(signal.lti(l_num, np.polyadd(l_den, l_num)), T=t)
    assert np.max(np.abs(y - ref)) <= 1e-5


def test_a_pid_with_a_fast_derivative_filter_is_stepped_finely_enough():
    """Fresh seed 2 of the step-design benchmark (#10): a PID whose derivative filter has its pole at 355 rad/s,
    behind 12 ms. Held at steps set by the crossover alone (0.15 ms over the requirement's 15 s horizon), its
    extrapolated step overshot 19.98 % where the method of steps gives 20.09 %: a false "met" at 20 %. The step
    is now also at most 0.01 over the fastest controller or plant pole (STEP_PER_POLE)."""
    plant = Plant.from_string("136.345346173/(s^3 + 13.9335147062*s^2 + 86.1405363922*s + 257.083163383)",
                              delay=0.011963053035491614)
    controller = Controller("PID", {"kp": 2.09538494804094, "ki": 36.766782264219, "kd": 1.0622228639151634,
                                    "tf": 0.0028167761394247356})
    result = StepResponse(max_overshoot=20).evaluate(Loop(plant, controller))
    t = np.linspace(0.0, 1.0, 20001)
    ref = _reference(plant.num, plant.den, plant.delay, *controller.tf(), 1.0, t)
    assert 100 * (float(np.max(ref)) - 1.0) > 20.05
    assert abs(result.details["overshoot"] - 100 * (float(np.max(ref)) - 1.0)) < 0.01
    assert not result.met


def test_a_ringing_pi_at_its_settling_limit_is_refined_until_the_band_decides():
    """Fresh seed 2 of the step-design benchmark (#21): a PI behind 5.7 ms that rings for 22 cycles (damping
    0.028). Extrapolated at the crossover's step (25 us) its response was 4e-4 of the final value low at 1.745 s,
    so the peak there fell inside the 2 % band and the settling time came out one half-cycle early: 1.711 s where
    the method of steps gives 1.748 s, a false "met" at 1.725 s. The step is now halved until the estimated error
    is within 1e-4, and the metrics count that error against the limits."""
    plant = Plant.from_string("5.23904679448/(s + 3.6333025191)", delay=0.0056713211124111915)
    controller = Controller("PI", {"kp": 6.935044983337539, "ki": 1118.5737459868103})
    loop = Loop(plant, controller)
    result = StepResponse(max_settling_time=1.7248457225641385).evaluate(loop)
    t = np.linspace(0.0, 2.5, 25001)
    ref = _reference(plant.num, plant.den, plant.delay, *controller.tf(), 2.5, t)
    final = loop.T0()
    assert abs(ref[-1] / final - 1.0) < 0.01  # settled by 2.5 s: the last exit from the band lies before
    ref_settling = float(t[np.flatnonzero(np.abs(ref / final - 1.0) > 0.02)[-1] + 1])
    assert 1.74 < ref_settling < 1.76
    assert not result.met
    assert abs(result.details["settling_time"] - ref_settling) < 2e-3
    # refined until its error cannot change the verdict: below the 4e-4 of T(0) that put the peak on the wrong
    # side of the band, and decided (not judged on the worst case the error allows)
    assert 0.0 < result.details["simulation_error"] < 4e-4
    assert "judged on the worst case" not in result.message
    run = linear_step(loop, 2.5, 25001)  # the estimate bounds what the method of steps finds
    assert np.max(np.abs(run.y - ref)) <= np.max(run.error)


def test_a_peak_within_the_simulations_error_of_the_band_is_judged_on_the_worst_case():
    """The same ringing PI with its settling band set to the method of steps' own peak at 1.745 s: no step
    separates "inside" from "outside" there, so the refinement stops at the tolerance and the verdict takes the
    worst case the error allows (the peak outside: not settled by 1.73 s), and says so."""
    plant = Plant.from_string("5.23904679448/(s + 3.6333025191)", delay=0.0056713211124111915)
    controller = Controller("PI", {"kp": 6.935044983337539, "ki": 1118.5737459868103})
    loop = Loop(plant, controller)
    t = np.linspace(1.735, 1.755, 2001)
    window = _reference(plant.num, plant.den, plant.delay, *controller.tf(), 1.755, t)
    band = float(np.max(np.abs(window / loop.T0() - 1.0)))
    result = StepResponse(max_settling_time=1.73, settle_band=band).evaluate(loop)
    assert not result.met
    assert result.details["settling_time"] > 1.74
    assert "judged on the worst case" in result.message
    assert result.details["simulation_error"] <= 1e-4 * 2.1  # refined to the tolerance (|y| peaks at 2.02 T(0))


def _negative_dc_case(seed):
    """A stable P loop with ``-1 < L(0) < 0`` (a negative plant gain, or a right-half-plane zero), half of them
    delayed: its step settles at ``T(0) < 0``."""
    rng = np.random.default_rng(seed)
    for _ in range(200):
        poles = -rng.uniform(0.3, 5.0, int(rng.integers(1, 4)))
        zero = [float(rng.uniform(0.5, 5.0))] if rng.random() < 0.5 else []  # (s - z): a right-half-plane zero
        num = np.poly(zero) if zero else np.array([-1.0])
        l0 = -float(rng.uniform(0.2, 0.8))
        num = num * l0 / (np.polyval(num, 0.0) / np.prod(-poles))
        delay = float(rng.uniform(0.02, 0.3)) if seed % 2 else 0.0
        loop = Loop(Plant(num, np.poly(poles), delay=delay), Controller("P", {"kp": 1.0}))
        if loop.stability().stable:
            return loop, num, np.poly(poles), delay
    pytest.skip("no stable loop drawn")


@pytest.mark.parametrize("seed", range(6))
def test_a_step_that_settles_below_zero_is_measured(seed):
    """``T(0) < 0``: the step requirement took ``|T(0)|`` for the final value, so the response never entered its band
    and every such loop was "undetermined: not settled" (found by a black-box test of ``synth check``)."""
    from scipy import signal

    loop, num, den, delay = _negative_dc_case(seed)
    final = loop.dc_gain()
    assert final < 0 and loop.T0() == -final
    result = StepResponse(max_settling_time=1e4, max_overshoot=1e3).evaluate(loop)
    assert result.met and result.details["settled"], result.message
    t_end = max(20.0, 1.5 * result.details["settling_time"])
    t = np.linspace(0.0, t_end, 60001)
    if delay:
        ref = _reference(num, den, delay, [1.0], [1.0], t_end, t)
    else:
        _, ref = signal.step(signal.lti(num, np.polyadd(den, num)), T=t)
    assert abs(ref[-1] / final - 1.0) < 0.02  # inside the band at the end
    outside = np.flatnonzero(np.abs(ref / final - 1.0) > 0.02)
    ref_settling = float(t[outside[-1] + 1]) if outside.size else 0.0
    assert abs(result.details["settling_time"] - ref_settling) < 5e-3 * max(1.0, ref_settling)
    assert abs(result.details["overshoot"] - max(0.0, 100 * (float(np.max(ref / final)) - 1.0))) < 0.05


def test_a_peak_between_the_output_samples_is_measured():
    """Found by a black-box test: a lead-lag on ``13.08/s`` behind 3.26 s peaks at a corner near two delays, between
    the step's output samples (16 ms apart): synth measured 2.785 % with an error of 2.3e-5 and called a 2.8 %
    limit met; the method of steps says 2.826 %."""
    plant = Plant.from_string("13.0822/s", delay=3.26)
    controller = Controller("leadlag", {"k": 0.4996, "z": 0.4095, "p": 14.67})
    result = StepResponse(max_overshoot=2.8).evaluate(Loop(plant, controller))
    t = np.linspace(6.0, 7.0, 20_001)  # around the peak (the reference integrates from 0 either way)
    ref = _reference(plant.num, plant.den, plant.delay, *controller.tf(), 7.0, np.r_[0.0, t])[1:]
    peak = 100 * (float(np.max(ref)) - 1.0)
    assert peak > 2.81
    assert abs(result.details["overshoot"] - peak) < 0.005, (result.details["overshoot"], peak)
    assert not result.met
