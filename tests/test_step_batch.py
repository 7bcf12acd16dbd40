"""Step limits on many loops at once (issue 18): the batched steps, metrics and root counts give what the one-loop
forms give, and the steps themselves what an independent matrix exponential gives at each time."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from synth.controllers import Controller
from synth.exact_steps import doubling_grid, exact_steps
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant
from synth.requirements import StepResponse
from synth.statespace import tf_to_ss


def _plant(rng: np.random.Generator) -> Plant:
    """A random plant: 1-4 poles (some unstable, some at the origin), maybe a zero (maybe in the right
    half-plane), maybe biproper."""
    poles = [float(v) for v in rng.normal(size=rng.integers(1, 5)) * rng.choice([0.3, 1.0, 5.0])]
    if rng.random() < 0.2:
        poles[0] = 0.0
    den = np.poly(poles)
    num = np.array([1.0])
    if rng.random() < 0.4:
        num = np.poly([float(rng.normal() * 2.0)])
    if rng.random() < 0.15 and len(poles) >= 1:
        num = np.poly([float(-abs(rng.normal()) - 0.1)] * len(poles))  # biproper
    gain = float(rng.uniform(0.5, 20.0))
    return Plant(gain * num, den)


def _controllers(rng: np.random.Generator, count: int) -> list[Controller]:
    kind = str(rng.choice(["P", "PI", "PID", "leadlag"]))
    out = []
    for _ in range(count):
        if kind == "P":
            out.append(Controller("P", {"kp": float(rng.uniform(0.01, 20.0))}))
        elif kind == "PI":
            out.append(Controller("PI", {"kp": float(rng.uniform(0.0, 10.0)), "ki": float(rng.uniform(0.0, 10.0))}))
        elif kind == "PID":
            out.append(Controller("PID", {"kp": float(rng.uniform(0.0, 10.0)), "ki": float(rng.uniform(0.0, 5.0)),
                                          "kd": float(rng.uniform(0.0, 2.0)), "tf": 0.02}))
        else:
            out.append(Controller("leadlag", {"k": float(rng.uniform(0.1, 10.0)), "z": float(rng.uniform(0.1, 5.0)),
                                              "p": float(rng.uniform(1.0, 50.0))}))
    return out


@pytest.mark.parametrize("seed", range(12))
def test_batch_slack_is_the_one_loop_slack(seed):
    """On random plants and controllers (unstable loops included), the batched slack equals the slack of each
    loop on its own: same verdict, same number to rounding."""
    rng = np.random.default_rng(4000 + seed)
    plant = _plant(rng)
    controllers = _controllers(rng, 24)
    req = StepResponse(max_overshoot=float(rng.uniform(1.0, 40.0)), max_settling_time=float(rng.uniform(0.5, 30.0)),
                       max_rise_time=float(rng.uniform(0.1, 10.0)) if rng.random() < 0.5 else None)
    batched = req.batch_slack(LoopBatch(plant, controllers))
    alone = np.array([req.slack(Loop(plant, c)) for c in controllers])
    assert np.array_equal(batched >= 0, alone >= 0)
    assert np.allclose(batched, alone, rtol=1e-9, atol=1e-12, equal_nan=True)


@pytest.mark.parametrize("seed", range(12))
def test_root_counts_in_bulk_are_the_one_loop_counts(seed):
    """The right-half-plane root counts of undelayed loops from batched roots equal what each loop's own stability
    count says, gains on the stability boundary included."""
    rng = np.random.default_rng(5000 + seed)
    plant = _plant(rng)
    controllers = _controllers(rng, 40)
    if controllers[0].type == "P":  # a gain on the boundary of 10/((s - 1)(s + 5))'s set: kp = 0.5 puts a root at 0
        plant = Plant.from_string("10/((s-1)*(s+5))")
        controllers[:3] = [Controller("P", {"kp": k}) for k in (0.5, 0.5 + 1e-12, 0.4)]
    counts = LoopBatch(plant, controllers).unstable_root_counts()
    assert counts.tolist() == [Loop(plant, c).stability().unstable_poles for c in controllers]


@pytest.mark.parametrize("seed", range(6))
def test_exact_steps_match_the_matrix_exponential_at_each_time(seed):
    """Each sample of the batched steps on a doubling grid is the state from rest at that time (one matrix
    exponential of the augmented system, computed here independently) to 1e-9 of the step's size."""
    rng = np.random.default_rng(6000 + seed)
    nums, dens = [], []
    for _ in range(5):
        poles = -np.abs(rng.normal(size=3)) * rng.choice([0.5, 2.0, 20.0]) - 0.05
        dens.append(np.poly(poles))
        nums.append(np.poly([float(rng.normal())]) * float(rng.uniform(0.5, 5.0)))
    scales = rng.uniform(0.05, 2.0, 5)
    unit = doubling_grid(1.0, int(rng.integers(0, 6)), intervals=200)
    y = exact_steps(nums, dens, scales, unit)
    for i in range(5):
        A, B, C, D = tf_to_ss(nums[i], dens[i])
        n = A.shape[0]
        for k in rng.integers(0, unit.size, 12):
            M = np.zeros((n + 1, n + 1))
            M[:n, :n], M[:n, n] = A * scales[i] * unit[k], B * scales[i] * unit[k]
            expected = float(C @ expm(M)[:n, n] + D)
            assert abs(y[i, k] - expected) <= 1e-9 * max(1.0, float(np.max(np.abs(y[i]))))


def test_a_slow_tail_is_resolved_at_the_start_with_fewer_samples():
    """A PID whose slow pole's tail asks for the horizon doubled nine times (eight, the most it was allowed until
    the poles could ask for more, settled it too): the samples start at 1/4000 of the first horizon and number
    4000 per doubling (40,001), where the even grid used 64,001 samples 1/250 apart; the settling time agrees
    with python-control's on a dense even grid within the coarsest spacing."""
    control = pytest.importorskip("control")
    loop = Loop(Plant.from_string("5/((s+1)*(s+2)*(s+3))"),
                Controller("PID", {"kp": 5.05, "ki": 1.0, "kd": 3.75, "tf": 0.01}))
    r = StepResponse(max_overshoot=50, max_settling_time=100).evaluate(loop)
    assert r.details["settled"] and r.details["samples"] == 40_001  # nine doublings
    T = control.feedback(control.tf(*loop.controller.tf()) * control.tf(loop.plant.num, loop.plant.den))
    t = np.linspace(0.0, r.details["horizon"], 400_001)
    info = control.step_info(T, T=t, SettlingTimeThreshold=0.02)
    assert r.details["settling_time"] == pytest.approx(info["SettlingTime"], abs=r.details["resolution"] + t[1])
    assert r.details["overshoot"] == pytest.approx(info["Overshoot"], abs=1e-3)


def test_the_search_of_the_bounds_screens_its_samples_in_bulk_without_changing_its_answer(monkeypatch):
    """The exact search checks its samples in order of score; those a batched step evaluation already fails are
    not checked one by one. Its answer, and what it says it rests on, are those of checking every one."""
    from synth.spec import parse_spec
    from synth.synthesis import exact_search as module

    spec = parse_spec({"name": "pid_step", "plant": {"tf": "5/((s+1)*(s+2)*(s+3))"},
                       "controller": {"type": "PID", "bounds": {"kp": [0, 20], "ki": [0, 20], "kd": [0, 10],
                                                                "tf": [0.01, 0.01]}},
                       "requirements": [{"type": "step_response", "max_overshoot": 5, "max_settling_time": 4}],
                       "objective": {"maximize": "integral_gain"}})
    screened = module.exact_search(spec)
    monkeypatch.setattr(module._BatchScreen, "may_pass", lambda self, k: True)
    every = module.exact_search(spec)
    assert screened.controller.parameters == every.controller.parameters
    assert (screened.checks, screened.checked_samples, screened.starts) == (every.checks, every.checked_samples,
                                                                            every.starts)
    assert screened.checked_samples > 100 * screened.starts  # most of the best-scoring samples fail the limits


@pytest.mark.parametrize("seed", range(2))
def test_step_metrics_on_the_doubling_grid_against_a_dense_even_grid(seed):
    """Random stable PI and PID loops (stable plants of order 1-3, some with a zero): the step limit's overshoot
    and settling time against scipy's step of the closed loop on a 200,001-sample even grid over the same horizon,
    computed apart from synth: overshoot within 0.005 points, settling within the limit's coarsest spacing."""
    from scipy import signal

    rng = np.random.default_rng(7000 + seed)
    checked = 0
    while checked < 4:
        poles = -np.abs(rng.normal(size=rng.integers(1, 4))) * rng.choice([0.3, 1.0, 5.0]) - 0.05
        num = np.array([float(rng.uniform(0.5, 5.0)) * float(np.prod(-poles))])
        if rng.random() < 0.3:
            num = np.polymul(num, [0.5, 1.0])
        plant = Plant(num, np.poly(poles))
        if rng.random() < 0.5:
            c = Controller("PI", {"kp": float(rng.uniform(0, 5)), "ki": float(rng.uniform(0.01, 5))})
        else:
            c = Controller("PID", {"kp": float(rng.uniform(0, 5)), "ki": float(rng.uniform(0.01, 3)),
                                   "kd": float(rng.uniform(0, 2)), "tf": float(rng.choice([0.01, 0.05]))})
        loop = Loop(plant, c)
        if not loop.stability().stable:
            continue
        d = StepResponse(max_overshoot=1000, max_settling_time=1e6).evaluate(loop).details
        if not d["settled"]:
            continue
        checked += 1
        cn, cd = c.tf()
        L_num, L_den = np.polymul(cn, plant.num), np.polymul(cd, plant.den)
        t = np.linspace(0.0, d["horizon"], 200_001)
        _, y = signal.step(signal.lti(L_num, np.polyadd(L_den, L_num)), T=t)
        frac = y / loop.T0()
        outside = np.flatnonzero(np.abs(frac - 1.0) > 0.02)
        settling = t[outside[-1] + 1] if outside.size else 0.0
        assert d["overshoot"] == pytest.approx(max(0.0, (frac.max() - 1.0) * 100.0), abs=5e-3)
        assert d["settling_time"] == pytest.approx(settling, abs=d["resolution"] + t[1])


@pytest.mark.parametrize("seed", range(10))
def test_a_coarse_proof_of_failure_is_never_wrong_and_catches_clear_failures(seed):
    """``fails_surely`` (the step on a tenth of the samples, all among the full evaluation's) says True only where
    the full evaluation's slack is negative, on random plants and controllers; and it catches every stable loop
    whose overshoot is over its limit by more than a point or whose step leaves the band a second after its
    settling limit."""
    rng = np.random.default_rng(5000 + seed)
    plant = _plant(rng)
    loops = [Loop(plant, c) for c in _controllers(rng, 30)]
    stable = [lp for lp in loops if lp.stability().stable]
    req = StepResponse(max_overshoot=float(rng.uniform(1.0, 40.0)), max_settling_time=float(rng.uniform(0.5, 30.0)),
                       settle_band=float(rng.choice([0.02, 0.05])))
    proved = req.fails_surely(stable)
    for lp, sure in zip(stable, proved):
        r = req.evaluate(lp)
        if sure:
            assert r.slack < 0, (lp.controller, r.message)
        elif r.details.get("settled"):
            overshoot, settling = r.details["overshoot"], r.details["settling_time"]
            assert not (overshoot > req.max_overshoot + 1.0 or settling > req.max_settling_time + 1.0), r.message


def test_the_quick_check_with_the_coarse_proof_gives_the_checks_verdict():
    """quick_check asks the coarse proof first: its verdict is still check's on random PID loops of one plant,
    around its best design under these limits (ki 5.14), where the two verdicts mix."""
    from synth.check import check, quick_check
    from synth.spec import parse_spec

    spec = parse_spec({"name": "q", "plant": {"tf": "5/((s+1)*(s+2)*(s+3))"},
                       "controller": {"type": "PID", "bounds": {"kp": [0, 20], "ki": [0, 20], "kd": [0, 10],
                                                                "tf": [0.01, 0.01]}},
                       "requirements": [{"type": "step_response", "max_overshoot": 5, "max_settling_time": 4}]})
    rng = np.random.default_rng(7)
    verdicts = []
    for _ in range(40):
        c = Controller("PID", {"kp": 5.05 * float(rng.uniform(0.8, 1.2)), "ki": float(rng.uniform(0, 5.5)),
                               "kd": 3.75 * float(rng.uniform(0.8, 1.2)), "tf": 0.01})  # around the best design
        verdicts.append(check(spec, c).feasible)
        assert quick_check(spec, c).feasible == verdicts[-1], c
    assert 5 <= sum(verdicts) <= len(verdicts) - 5, sum(verdicts)  # both verdicts occur
