"""The design benchmark's reference (``benchmarks/design_reference.py``) counts the closed-loop poles of a loop
without delay from its characteristic polynomial. Its contour count along ``Re s = -eps`` passed within ``eps``
of a controller's poles on the imaginary axis and called a stable loop unstable (seed 15 #42: ``29.77/(s^2 +
283.67)`` on ``5.93/(s (s + 5.17)(s + 0.092))``, closed-loop roots -5.188, -0.0344 +- 0.3446j, -0.00100 +-
16.842j). Checked against mpmath's roots at 50 digits."""

import mpmath
import numpy as np
import pytest

from benchmarks.design_reference import check_point, controller_polys

PLANT_42 = ([5.93], list(np.polymul(np.polymul([1.0, 0.0], [1.0, 5.17]), [1.0, 0.092])))
SPEC_42 = {"controller": {"type": "rational", "order": [0, 2],
                          "bounds": {"b0": [0.0, 100.0], "a1": [0.0, 10.0], "a0": [0.0, 1000.0]}},
           "requirements": [{"type": "bandwidth", "min": 0.1}]}


def _mp_unstable(num: list[float], den: list[float], cn: np.ndarray, cd: np.ndarray) -> int:
    """Roots with Re >= 0 of den cd + num cn, found by mpmath at 50 digits from the exact coefficients."""
    char = np.polyadd(np.polymul(den, cd), np.polymul(num, cn))
    with mpmath.workdps(50):
        roots = mpmath.polyroots([mpmath.mpf(float(c)) for c in char], maxsteps=400, extraprec=400)
        return sum(1 for r in roots if mpmath.re(r) >= 0)


def test_controller_poles_on_the_axis_do_not_fool_the_count() -> None:
    params = {"b0": 29.7668, "a1": 0.0, "a0": 283.6738}
    e = check_point(*PLANT_42, 0.0, SPEC_42, params)
    assert e.stable and e.unstable_poles == 0
    cn, cd = controller_polys("rational", [0, 2], params)
    assert _mp_unstable(*PLANT_42, cn, cd) == 0


def test_a_slightly_negative_damping_is_two_unstable_poles() -> None:
    # a1 < 0 moves the controller's (and, at this gain, the loop's) light pair across the axis
    params = {"b0": 29.7668, "a1": -0.01, "a0": 283.6738}
    cn, cd = controller_polys("rational", [0, 2], params)
    want = _mp_unstable(*PLANT_42, cn, cd)
    e = check_point(*PLANT_42, 0.0, {**SPEC_42, "controller": {**SPEC_42["controller"],
                                                                "bounds": {"b0": [0, 100], "a1": [-1, 1],
                                                                           "a0": [0, 1000]}}}, params)
    assert want == 2
    assert not e.stable and e.unstable_poles == want


@pytest.mark.parametrize("seed", range(40))
def test_count_matches_mpmath_on_random_loops(seed: int) -> None:
    rng = np.random.default_rng(seed)
    poles = rng.uniform(-10, 3, rng.integers(1, 5))
    num = [float(rng.uniform(0.5, 20))]
    den = list(np.poly(poles))
    order = [int(rng.integers(0, 2)), 2]
    params = {"a1": float(rng.choice([0.0, rng.uniform(-0.5, 5)])), "a0": float(rng.uniform(0, 50)),
              **{f"b{i}": float(rng.uniform(-20, 20)) for i in range(order[0] + 1)}}
    spec = {"controller": {"type": "rational", "order": order,
                           "bounds": {k: [-100.0, 100.0] for k in params}},
            "requirements": [{"type": "bandwidth", "min": 0.1}]}
    cn, cd = controller_polys("rational", order, params)
    want = _mp_unstable(num, den, cn, cd)
    e = check_point(num, den, 0.0, spec, params)
    assert e.unstable_poles == want and e.stable == (want == 0)
