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


def test_the_reference_reads_a_controller_with_poles_on_the_axis() -> None:
    """Seed 31 #26: synth designed a rational controller with poles at 0 and +-46.75j (a0 = a2 = 0) on an
    unstable plant behind 41 ms, peak |S| 8.9914 dB against a bound of 8.99169 dB. The reference's grid holds
    the pole's frequency (it adds points around axis roots), where C = inf made 1/(1 + L) NaN: "false feasible".
    It now evaluates S = den cd / (den cd + num cn e^{-s delay}), finite there; the peak agrees with 1/(1 + L)
    on a dense grid that steps around the pole."""
    import numpy as np

    from benchmarks.design_reference import check_point

    spec = {"name": "rand_31_26", "plant": {"tf": "921596/((s-1.35446)*(s+56.1443)*(s+93.6049)*(s+2.35737))",
                                            "delay": 0.0409807},
            "controller": {"type": "rational", "order": [2, 3],
                           "bounds": {"b0": [-262210.0, 262210.0], "b1": [-20372.9, 20372.9], "b2": [-1582.92, 1582.92],
                                      "a0": [0.0, 2878190.0], "a1": [0.0, 223627.0], "a2": [0.0, 17375.2]}},
            "requirements": [{"type": "peak_sensitivity", "max_db": 8.99169}], "objective": {"maximize": "bandwidth"}}
    num, den = [921596.0], np.poly([1.35446, -56.1443, -93.6049, -2.35737]).tolist()
    params = {"b0": 0.7383344842725702, "b1": 570.7369962451746, "b2": 131.86008522616646, "a0": 0.0,
              "a1": 2185.5567628997396, "a2": 0.0}
    ev = check_point(num, den, 0.0409807, spec, params)
    assert ev.stable and np.isfinite(ev.values["0:peak_sensitivity"])
    w = np.geomspace(1e-3, 1e4, 400_001)
    w = w[np.abs(w - np.sqrt(params["a1"])) > 1e-6]
    s = 1j * w
    L = 921596.0 / np.polyval(den, s) * np.exp(-0.0409807 * s) * np.polyval([params["b2"], params["b1"], params["b0"]], s) \
        / np.polyval([1.0, 0.0, params["a1"], 0.0], s)
    assert ev.values["0:peak_sensitivity"] == pytest.approx(20 * np.log10(np.max(np.abs(1 / (1 + L)))), abs=1e-4)
    assert ev.slacks["0:peak_sensitivity"] > 0  # met: 8.9914 dB <= 8.99169 dB
