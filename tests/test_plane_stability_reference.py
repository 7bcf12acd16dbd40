"""The plane-stability benchmark's reference (``benchmarks/plane_stability_reference.py``) on closed-form cases,
its delay count against its root count (no delay) and against the sampled argument principle (delay), and the
random cases' reproducibility."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.plane_stability_cases import random_case
from benchmarks.plane_stability_reference import (
    closed_loop_counts,
    controller_polynomials,
    stable_grid,
    winding_count_sampled,
)

CUBE = [1.0, 3.0, 3.0, 1.0]  # (s + 1)^3


def _fopdt_limit(delay: float) -> float:
    """Upper P gain of exp(-delay s)/(s + 1): |G| at the frequency where the phase is -pi."""
    lo, hi = 1e-9, np.pi / delay  # phase -atan(w) - delay w falls through -pi in (0, pi/delay)
    for _ in range(200):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if np.arctan(mid) + delay * mid < np.pi else (lo, mid)
    return float(np.hypot(1.0, lo))


@pytest.mark.parametrize("method", ["roots", "winding"])
def test_cubic_lag_with_p_is_stable_between_minus_one_and_eight(method: str) -> None:
    xs, _, stable, marginal = stable_grid([1.0], CUBE, 0.0, "P", {}, "kp", (-3.0, 10.0), "ki", (0.0, 1.0),
                                          n=53, method=method)
    inside = (xs > -1) & (xs < 8)
    edge = np.isclose(xs, -1) | np.isclose(xs, 8)
    assert np.array_equal(stable[0], inside & ~edge) and np.array_equal(marginal[0], edge)
    assert np.all(stable == stable[0]) and edge.sum() == 2


def test_cubic_lag_bounds_sharp_to_the_margin() -> None:
    """1e-4 off a bound moves the roots by about 3e-5 (sigma = 1e-6): decided; 1e-8 off: marginal."""
    kp = np.array([-1 - 1e-4, -1 + 1e-4, 8 - 1e-4, 8 + 1e-4, -1 - 1e-8, -1 + 1e-8, 8 - 1e-8, 8 + 1e-8])
    for method in ("roots", "winding"):
        out = closed_loop_counts([1.0], CUBE, 0.0, "P", {"kp": kp}, method)
        assert out["stable"].tolist() == [False, True, True, False] + [False] * 4
        assert out["marginal"].tolist() == [False] * 4 + [True] * 4
        assert out["z_minus"].tolist() == [1, 0, 0, 2, 1, 1, 2, 2]


def test_delayed_integrator_with_p_is_stable_below_half_pi() -> None:
    xs, _, stable, marginal = stable_grid([1.0], [1.0, 0.0], 1.0, "P", {}, "kp", (-0.5, 2.0), "ki", (0.0, 1.0), n=26)
    assert np.array_equal(stable[0], (xs > 1e-9) & (xs < np.pi / 2))
    assert xs[marginal[0]].tolist() == [0.0]  # C = 0 leaves the integrator
    kp = np.pi / 2 * np.array([1 - 1e-4, 1 + 1e-4, 1 - 1e-9, 1 + 1e-9])
    out = closed_loop_counts([1.0], [1.0, 0.0], 1.0, "P", {"kp": kp})
    assert out["stable"].tolist() == [True, False, False, False] and out["z_minus"].tolist() == [0, 2, 2, 2]
    assert out["marginal"].tolist() == [False, False, True, True]


@pytest.mark.parametrize("delay", [0.1, 1.0, 5.0])
def test_delayed_first_order_lag_with_p(delay: float) -> None:
    top = _fopdt_limit(delay)
    kp = np.array([-1.001, -0.999, 0.0, top * (1 - 1e-4), top * (1 + 1e-4), 3 * top])
    stable = closed_loop_counts([1.0], [1.0, 1.0], delay, "P", {"kp": kp})["stable"]
    assert stable.tolist() == [False, True, True, True, False, False]


def test_unstable_lag_with_pi_needs_kp_above_one_and_positive_ki() -> None:
    xs, ys, stable, marginal = stable_grid([1.0], [1.0, -1.0], 0.0, "PI", {}, "kp", (0.0, 3.0), "ki", (-1.0, 2.0),
                                          n=31)
    gx, gy = np.meshgrid(xs, ys)
    off = ~np.isclose(gx, 1.0) & ~np.isclose(gy, 0.0)
    assert np.array_equal(stable[off], ((gx > 1) & (gy > 0))[off])
    assert not marginal[off].any()
    assert np.all(marginal[np.isclose(gx, 1.0) & (gy > 0.05)])  # s^2 + ki: roots on the axis
    # ki = 0 exactly is the P loop kp/(s - 1) (the PI's s/s cancelled): stable iff kp > 1
    row = np.flatnonzero(ys == 0.0)
    assert row.size == 1 and np.array_equal(stable[row[0]], xs > 1 + 1e-9)


def test_pi_pole_at_the_origin_and_a_vanishing_integral_gain() -> None:
    """A tiny ki leaves a closed-loop root within the margin of the origin: marginal, not stable."""
    out = closed_loop_counts([1.0], [1.0, 1.0], 0.5, "PI", {"kp": 1.0, "ki": [0.0, 1e-12, 0.5]})
    assert out["stable"].tolist() == [True, False, True] and out["marginal"].tolist() == [False, True, False]


def _random_plant(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    n = int(rng.integers(1, 5))
    poles = -np.exp(rng.uniform(np.log(0.1), np.log(20), n)) * np.where(rng.random(n) < 0.3, -1, 1)
    poles = poles.astype(complex)
    if n >= 2 and rng.random() < 0.3:
        wn, zeta = np.exp(rng.uniform(np.log(0.1), np.log(20))), rng.uniform(0.05, 0.5)
        poles[:2] = wn * (-zeta + 1j * np.sqrt(1 - zeta**2)), wn * (-zeta - 1j * np.sqrt(1 - zeta**2))
    if rng.random() < 0.2:
        poles[-1] = 0
    zeros = -np.exp(rng.uniform(np.log(0.1), np.log(20), int(rng.integers(0, n)))) * rng.choice([-1, 1])
    return np.real(np.poly(zeros)) * rng.uniform(0.1, 20), np.real(np.poly(poles))


def test_contour_count_matches_the_roots_without_delay() -> None:
    rng = np.random.default_rng(7)
    for _ in range(30):
        num, den = _random_plant(rng)
        ctype = str(rng.choice(["P", "PI", "PID"]))
        k = 200
        params = {"kp": rng.uniform(-5, 20, k), "ki": rng.uniform(-5, 30, k) * (rng.random(k) > 0.1),
                  "kd": rng.uniform(-1, 2, k), "tf": 0.02}
        by_roots = closed_loop_counts(num, den, 0.0, ctype, params, "roots")
        by_contour = closed_loop_counts(num, den, 0.0, ctype, params, "winding")
        assert not by_contour["ambiguous"].any()
        assert np.array_equal(by_roots["z_minus"], by_contour["z_minus"])
        assert np.array_equal(by_roots["z_plus"], by_contour["z_plus"])


def test_delay_count_matches_the_sampled_argument_principle() -> None:
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(30):
        num, den = _random_plant(rng)
        delay = float(np.exp(rng.uniform(np.log(0.01), np.log(2.0))))
        ctype = str(rng.choice(["PI", "PID"]))
        k = 6
        params = {"kp": rng.uniform(-2, 5, k) * 10 ** rng.uniform(-1, 1), "ki": rng.uniform(-2, 5, k),
                  "kd": rng.uniform(-0.2, 0.5, k), "tf": 0.02}
        out = closed_loop_counts(num, den, delay, ctype, params)
        num_c, den_c = controller_polynomials(ctype, params)
        for i in np.flatnonzero(~out["ambiguous"] & ~out["not_decaying"]):
            for key, shift in (("z_minus", -out["sigma"]), ("z_plus", out["sigma"])):
                assert winding_count_sampled(num_c[i], den_c[i], num, den, delay, shift) == out[key][i]
            checked += 1
    assert checked >= 150


def test_random_cases_are_reproducible_and_well_formed() -> None:
    for index in range(40):
        case = random_case(3, index)
        assert case == random_case(3, index)
        assert 1 <= len(case["den"]) - len(case["num"]) <= 3 and 2 <= len(case["den"]) <= 5
        assert case["ctype"] in ("PI", "PID") and case["delay"] <= 2.0
        assert case["x_box"][0] < case["x_box"][1] and case["y_box"][0] < case["y_box"][1]
        if case["ctype"] == "PID":
            assert 0.01 <= case["fixed"]["tf"] <= 0.1 and len(case["fixed"]) == 2
    assert random_case(3, 0) != random_case(4, 0)
