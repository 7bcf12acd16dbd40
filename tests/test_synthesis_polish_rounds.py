"""The NLP polish's rounds (synth.synthesis.nlp, nlp_peaks): sharp peaks tracked between grid points, a trust
region once a step jumps out of the stabilizing set, unconverged iterates offered to the certificate. Each case
is judged by a dense evaluation written here or by the independent reference of the design benchmark."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import synth
from benchmarks.design_reference import check_point
from synth.loop import Loop
from synth.synthesis.nlp import polish
from synth.synthesis.nlp_peaks import peak_frequencies
from synth.synthesis.nlp_problem import IPOPT_OPTIONS

LIGHT = {"name": "light", "plant": {"tf": "4/(s^2+0.1*s+4)"},
         "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}},
         "requirements": [{"type": "peak_complementary", "max_db": 3}], "objective": {"maximize": "integral_gain"}}


def _dense_peak_db(loop: Loop, curve: str) -> float:
    w = np.geomspace(1e-3, 1e3, 400_001)
    return float(20 * np.log10(np.max(np.abs(getattr(loop, curve)(w)))))


def test_a_sharp_peak_between_coarse_grid_points_is_bounded_in_the_first_round() -> None:
    """A lightly damped plant (zeta 0.025) under PI with |T| <= 3 dB, on a grid of 10 points per decade: the
    peak of |T| is narrower than the grid's spacing. Tracked at its own frequency, the first round's answer
    meets the bound everywhere (on the grid alone it took five rounds, four of them failing the dense check)."""
    spec = synth.parse_spec(LIGHT)
    start = synth.Controller("PI", {"kp": 0.1, "ki": 0.05})
    res = polish(list(spec.requirements), spec.plants(), start, spec.controller.all_bounds(),
                 [("integral_gain", "maximize", 1.0)], np.geomspace(0.01, 100, 41))
    assert res.success and res.rounds <= 2
    for c in res.candidates:
        assert _dense_peak_db(Loop(spec.plants()[0], c), "T") <= 3.0 + 1e-6
    assert res.controller.parameters["ki"] > 0.058  # the bound is active: not a timid answer


def test_peak_frequencies_finds_the_resonant_peak_of_the_complementary_sensitivity() -> None:
    """``T = k/(s^2 + 2 zeta s + 1 + k)`` peaks at ``sqrt(1 + k - 2 zeta^2)``."""
    G = synth.Plant.from_string("1/(s^2+0.04*s+1)")
    [w] = peak_frequencies(G, synth.Controller("P", {"kp": 3.0}), "T", 1.0, (0.01, 100.0))
    assert w == pytest.approx(np.sqrt(4.0 - 2 * 0.02**2), rel=1e-6)


P262 = {"name": "p262", "plant": {"tf": "70.5395*1/(s*(s^2+0.378442*s+4.25159))"},
        "controller": {"type": "PID", "bounds": {"kp": [0.0, 4.42864], "ki": [0.0, 19.782], "kd": [0.0, 0.991448],
                                                 "tf": [0.0223872, 0.0223872]}},
        "requirements": [{"type": "sensitivity", "max_db": -10.1128, "band": [0.00198497, 0.198497]},
                         {"type": "bandwidth", "min": 1.91732}],
        "objective": {"minimize": "peak_sensitivity"}}


@pytest.mark.parametrize("mu_max", ["default", "uncapped"])
def test_a_step_out_of_the_stabilizing_set_is_repeated_in_a_trust_region(mu_max: str, monkeypatch) -> None:
    """Benchmark seed 1, problem 262 (integrator and a mode with zeta 0.09, PID, minimize peak |S|). With IPOPT's
    barrier parameter uncapped (as before ``IPOPT_OPTIONS["ipopt.mu_max"]``), the second round's first step from
    a stable start lands on an unstable loop that looks perfect on the grid (|S| < 1): that round is discarded
    and repeated in a trust region. With the cap no step leaves the stabilizing set. Either way no candidate is
    unstable, and the answer's peak |S| (from the polynomials, dense) is below the start's."""
    if mu_max == "uncapped":
        monkeypatch.delitem(IPOPT_OPTIONS, "ipopt.mu_max")
    spec = synth.parse_spec(P262)
    start = synth.Controller("PID", {"kp": 0.0131137, "ki": 0.0251435, "kd": 0.0, "tf": 0.0223872})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = polish(list(spec.requirements), spec.plants(), start, spec.controller.all_bounds(),
                     [("peak_sensitivity", "minimize", 1.0)], np.geomspace(1e-3, 1e3, 250))
    assert any(h.get("unstable") for h in res.history) == (mu_max == "uncapped")
    assert res.candidates
    for c in res.candidates:  # the reference's own Nyquist count
        e = check_point([70.5395], [1.0, 0.378442, 4.25159, 0.0], 0.0,
                        {"requirements": [], "controller": {"type": "PID", "bounds": {}}}, c.parameters)
        assert e.stable, c
    num, den = [70.5395], [1.0, 0.378442, 4.25159, 0.0]
    answer = _dense_peak_db_with_dc(num, den, *res.controller.tf())  # the score is minus the peak |S| in dB
    assert answer == pytest.approx(-res.objective_value, abs=0.01)
    assert answer < _dense_peak_db_with_dc(num, den, *start.tf()) - 0.1  # 10.55 dB against the start's 11.02


@pytest.mark.slow
def test_an_unconverged_round_that_passes_is_a_design() -> None:
    """Benchmark seed 1, problem 105 (unstable plant with a right-half-plane zero and a 42 ms delay, PID,
    maximize bandwidth): the round that reaches the reference's optimum stops at IPOPT's iteration limit; its
    stable iterate is offered to the certificate and passes, within 1 % of the reference's best design. (Since
    the polish's barrier cap of session 19 the chosen round converges: the test now guards the design's
    quality on this problem, not the unconverged path itself.) The design with integral action is run alone
    (the first job of synth.design.design_jobs; synth.design's answer here): the one without it (ki = 0) ends
    infeasible."""
    from synth.design import design_jobs

    spec = {"name": "p105", "plant": {"tf": "24.4063*(1-s/5.49139)*(s+33.6887)/((s-0.719713)*(s+2.53304)*(s+30.132))",
                                      "delay": 0.0418484},
            "controller": {"type": "PID", "bounds": {"kp": [0.0, 5.81268], "ki": [0.0, 35.4934], "kd": [0.0, 0.951929],
                                                     "tf": [0.0163768, 0.0163768]}},
            "requirements": [{"type": "sensitivity_static", "max_db": -10.0522, "plant_gain": 4.45052},
                             {"type": "slew_rate", "rate_limit": 36.471, "max_error": 0.102515,
                              "band": [0.0610621, 25.8063]},
                             {"type": "margins", "phase_margin_deg": 20.2337}],
            "objective": {"maximize": "bandwidth"}}
    jobs, _ = design_jobs(synth.parse_spec(spec))
    assert len(jobs) == 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = jobs[0]()
    assert d.feasible
    num = np.polymul([-24.4063 / 5.49139, 24.4063], [1.0, 33.6887])
    den = np.polymul(np.polymul([1.0, -0.719713], [1.0, 2.53304]), [1.0, 30.132])
    mine = check_point(num, den, 0.0418484, spec, d.controller.parameters)
    ref = check_point(num, den, 0.0418484, spec, {"tf": 0.0163768, "kp": 0.09410969281718301,
                                                   "ki": 0.0825534196736773, "kd": 0.1728805498179204})
    assert mine.feasible(1e-3) and ref.feasible(1e-3)
    assert mine.objective >= 0.99 * ref.objective


@pytest.mark.parametrize("seed", range(8))
def test_peak_brackets_of_a_long_delay_hold_one_maximum_each_and_miss_none(seed: int) -> None:
    """A delay of 1-10 s makes |S| ripple about 2 pi / delay apart, finer than a log grid at high frequency.
    Against a dense linear grid (64 points per ripple): every local maximum of |S| within 3 dB of the bound
    (away from that threshold) is found, and each bracket holds exactly one local maximum of the dense curve:
    the stationary point the NLP holds there is that peak."""
    from synth.synthesis.nlp_peaks import NEAR_DB, peak_brackets

    rng = np.random.default_rng(seed)
    delay = float(rng.uniform(1.0, 10.0))
    poles = rng.uniform(0.2, 3.0, rng.integers(1, 3))
    plant = synth.Plant(np.array([float(np.prod(poles))]), np.poly(-poles), delay=delay)
    c = synth.Controller("PI", {"kp": float(rng.uniform(0.2, 0.6)), "ki": float(rng.uniform(0.0, 0.1))})
    band, bound = (0.01, 30.0), 10 ** (float(rng.uniform(1.0, 4.0)) / 20)
    found = peak_brackets(plant, c, "S", bound, band)
    w = np.linspace(band[0], band[1], int(64 * band[1] * delay / (2 * np.pi)))
    s = np.abs(Loop(plant, c).S(w))
    peaks = np.flatnonzero((s[1:-1] > s[:-2]) & (s[1:-1] >= s[2:])) + 1
    level = bound * 10 ** (-NEAR_DB / 20)
    clear = w[peaks[np.abs(20 * np.log10(s[peaks] / level)) > 0.05]]
    above = w[peaks[s[peaks] > level]]
    clear_above = [x for x in clear if x in above]
    assert len(clear_above) >= 3  # the case has many ripples near the bound
    for x in clear_above:
        assert any(lo <= x <= hi for _, lo, hi in found), x
    for w0, lo, hi in found:
        inside = w[peaks][(w[peaks] >= lo) & (w[peaks] <= hi)]
        assert inside.size == 1 and abs(inside[0] - w0) <= 2 * (w[1] - w[0]), (w0, lo, hi, inside)


def _dense_peak_db_with_dc(num: list[float], den: list[float], cnum: np.ndarray, cden: np.ndarray) -> float:
    """Peak |S| over w = 0 and 1e-9 ... 1e4 rad/s from the polynomials themselves (no synth.Loop)."""
    w = np.concatenate([[0.0], np.geomspace(1e-9, 1e4, 400_001)])
    s = 1j * w
    d = np.polyval(den, s) * np.polyval(cden, s)  # S = D / (D + N), finite at a pole of L at w = 0
    return float(20 * np.log10(np.max(np.abs(d / (d + np.polyval(num, s) * np.polyval(cnum, s))))))


def test_a_peak_objective_below_the_grid_is_seen_by_the_next_round() -> None:
    """Design benchmark seed 2026 #92 (unstable plant, second-order rational controller, |S| <= -11 dB on a low
    band, smallest peak |S|). The polish's grid starts at 5.13e-5 rad/s; below it |S| rises towards |S(0)|,
    which depends on C(0). An answer that lowered C(0) had its true peak at w = 0 (1.28 dB, the start's is
    0.41 dB) while the NLP saw 0.40 dB. That maximum is searched where the score searches it and held by the
    next round's objective, so the answer's peak (dense, from the polynomials) is what the polish reports, and
    below the start's."""
    spec = synth.parse_spec({
        "name": "p92", "plant": {"tf": "0.0190015*1/((s-0.0357522)*(s+0.103251))"},
        "controller": {"type": "rational", "order": [2, 2],
                       "bounds": {"b0": [-0.659268, 0.659268], "b1": [-5.65265, 5.65265], "b2": [-48.4665, 48.4665],
                                  "a0": [0.0, 6.12115], "a1": [0.0, 52.4835]}},
        "requirements": [{"type": "sensitivity", "max_db": -11.0728, "band": [0.000512954, 0.0512954]}]})
    start = synth.Controller("rational", {"b0": 0.000826978, "b1": 5.64909, "b2": 41.9143, "a0": 0.00154431,
                                          "a1": 3.81716})  # the convex stage's answer
    num, den = [0.0190015], list(np.polymul([1.0, -0.0357522], [1.0, 0.103251]))
    at_start = _dense_peak_db_with_dc(num, den, *start.tf())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = polish(list(spec.requirements), spec.plants(), start, spec.controller.all_bounds(),
                     [("peak_sensitivity", "minimize", 1.0)], np.geomspace(5.13e-5, 50, 200))
    assert res.success
    answer = _dense_peak_db_with_dc(num, den, *res.controller.tf())
    assert answer == pytest.approx(-res.objective_value, abs=0.01)
    assert answer < at_start - 1e-3
