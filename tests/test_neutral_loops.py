"""A biproper plant with a delay: the loop turns neutral where |L(j inf)| reaches 1.

Beyond that gain the closed loop has infinitely many roots with Re s -> ln|L(j inf)| / delay > 0. synth used to
raise "neutral type ... make the loop strictly proper" as bad input (exit 2) as soon as any trial controller
crossed it, so a PI design over (s+2)/(s+1) e^{-0.05 s} with kp in [0, 10] stopped before it started. Now such a
controller is an unstable candidate, and the D-decomposition knows the boundary (at infinite frequency).
The reference here is independent: Newton's method on the characteristic quasi-polynomial, started on the
asymptotic root chain.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

from synth.controllers import Controller
from synth.design import design
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant
from synth.spec import parse_spec
from synth.stability_sets import affine_stability_intervals

PLANT = "(s+2)/(s+1)"
DELAY = 0.05


def _root_near(kp: float, k: int) -> complex:
    """A root of (s+1) + kp (s+2) e^{-DELAY s} near the k-th asymptotic one, ln(kp)/DELAY + j(2k+1)pi/DELAY."""
    def f(x: np.ndarray) -> list[float]:
        s = complex(x[0], x[1])
        v = (s + 1) + kp * (s + 2) * np.exp(-DELAY * s)
        return [v.real, v.imag]

    x = fsolve(f, [np.log(kp) / DELAY, (2 * k + 1) * np.pi / DELAY], xtol=1e-13)
    assert abs(complex(*f(x))) < 1e-8
    return complex(x[0], x[1])


@pytest.mark.parametrize("kp", [1.05, 1.5, 3.0])
def test_beyond_the_neutral_gain_the_loop_is_unstable_with_the_reason(kp: float) -> None:
    assert _root_near(kp, 3).real > 0  # the reference: a root in the right half-plane
    st = Loop(PLANT, f"P({kp})", delay=DELAY).stability()
    assert not st.stable and st.neutral_gain == pytest.approx(kp)
    assert "neutral type" in st.describe() and "right half-plane" in st.describe()


def test_below_the_neutral_gain_the_loop_is_stable() -> None:
    for kp in (0.3, 0.9, 0.99):
        assert all(_root_near(kp, k).real < 0 for k in range(5))
        assert Loop(PLANT, f"P({kp})", delay=DELAY).stability().stable


def test_the_stabilizing_set_ends_where_the_first_root_of_the_chain_crosses_the_axis() -> None:
    # |L| = kp |jw+2|/|jw+1| stays above kp: just below kp = 1 the delayed Nyquist curve meets -1 near
    # w = pi/DELAY. The reference solves (jw+1) + kp (jw+2) e^{-j w DELAY} = 0 for (w, kp) by Newton.
    def f(x: np.ndarray) -> list[float]:
        w, kp = x
        v = (1j * w + 1) + kp * (1j * w + 2) * np.exp(-1j * w * DELAY)
        return [v.real, v.imag]

    w_star, kp_star = fsolve(f, [np.pi / DELAY, 1.0], xtol=1e-14)
    assert 0.999 < kp_star < 1.0
    [piece] = affine_stability_intervals(None, (np.array([1.0]), np.array([1.0])), np.array([1.0, 2.0]),
                                         np.array([1.0, 1.0]), DELAY, 0.0, 5.0)
    assert piece.lo == 0.0 and piece.hi == pytest.approx(kp_star, rel=1e-9)
    assert piece.hi_frequency == pytest.approx(w_star, rel=1e-6)
    # the pointwise test agrees on both sides
    assert Loop(PLANT, f"P({kp_star * (1 - 1e-6)})", delay=DELAY).stability().stable
    assert not Loop(PLANT, f"P({kp_star * (1 + 1e-6)})", delay=DELAY).stability().stable


def test_the_gain_set_ends_at_the_neutral_boundary_and_a_pi_design_proceeds() -> None:
    spec = parse_spec(f"""
name: biproper_p
plant: {{tf: "{PLANT}", delay: {DELAY}}}
controller: {{type: P, bounds: {{kp: [0, 5]}}}}
requirements:
  - {{type: margins, gain_margin_db: 3, phase_margin_deg: 30}}
objective: {{maximize: bandwidth}}
""")
    result = design(spec)
    assert result.status == "feasible"
    # the phase crosses -180 deg near pi/DELAY, where |L| = kp |jw+2|/|jw+1|: 3 dB of gain margin there
    w180 = brentq(lambda w: np.arctan(w / 2) - np.arctan(w) - DELAY * w + np.pi, 40.0, 80.0, xtol=1e-14)
    kp_max = 10 ** (-3 / 20) / abs((1j * w180 + 2) / (1j * w180 + 1))
    assert result.gain_set.as_list()[-1][1] == pytest.approx(kp_max, rel=1e-6)
    assert "stable only for kp in [0, 0.9996)" in result.verdict
    pi = parse_spec(f"""
name: biproper_pi
plant: {{tf: "{PLANT}", delay: {DELAY}}}
controller: {{type: PI, bounds: {{kp: [0, 10], ki: [0, 10]}}}}
requirements:
  - {{type: peak_sensitivity, max_db: 6}}
objective: {{maximize: integral_gain}}
""")
    designed = design(pi)
    assert designed.status == "feasible" and designed.controller.parameters["kp"] < 1.0


def test_the_gain_margin_of_a_loop_rising_to_its_limit_is_the_neutral_factor() -> None:
    # |G| = |jw+1|/|jw+2| rises to 1: the phase crossings' factors 1/|L(w_k)| fall towards 1/0.8 and never reach it;
    # at the factor 1.25 itself |L(j inf)| = 1 (neutral). Both the batch and the scalar margins say 1.25.
    plant = Plant.from_string("(s+1)/(s+2)", delay=DELAY)
    k_lo, k_hi = LoopBatch(plant, [Controller("P", {"kp": 0.8})]).gain_margin_factors()
    assert k_hi[0] == pytest.approx(1.25, rel=1e-12) and k_lo[0] == 0.0
    assert Loop(plant, "P(0.8)").margins().gain_margin_db == pytest.approx(20 * np.log10(1.25), rel=1e-12)
    assert not Loop(plant, "P(1.0)").stability().stable  # 0.8 x 1.25


def test_batch_and_scalar_gain_margins_agree_on_random_biproper_delayed_loops() -> None:
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(12):
        z, p, g, tau = rng.uniform(0.2, 20), rng.uniform(0.2, 20), rng.uniform(0.3, 3), rng.uniform(0.01, 1.0)
        plant = Plant.from_string(f"{g:.4g}*(s+{z:.4g})/(s+{p:.4g})", delay=round(tau, 4))
        controllers = [Controller("PI", {"kp": float(rng.uniform(0.01, 1.2) / g), "ki": float(rng.uniform(0, 2))})
                       for _ in range(4)]
        k_lo, k_hi = LoopBatch(plant, controllers).gain_margin_factors()
        for i, c in enumerate(controllers):
            loop = Loop(plant, c)
            if not loop.stability().stable:
                continue
            batch = min(20 * np.log10(k_hi[i]) if np.isfinite(k_hi[i]) else np.inf,
                        -20 * np.log10(k_lo[i]) if k_lo[i] > 0 else np.inf)
            assert batch == pytest.approx(loop.margins().gain_margin_db, rel=1e-6, abs=1e-9), (plant, c)
            checked += 1
    assert checked >= 20


def test_without_a_delay_a_root_passes_through_infinity_where_l_at_infinity_is_minus_one() -> None:
    # seed 21 (biproper) #35, a false "infeasible": G(j inf) = -1.4268 (a right-half-plane zero), so 1 + kp G loses
    # its leading term at kp = 1/1.4268 and a root comes back from infinity in the right half-plane. The
    # D-decomposition had no boundary there and called all of [0, 21.9] unstable.
    plant = Plant.from_string("2.96776*(1-s/2.07997)*(s+0.678772)*(s+0.662767)/((s+0.318357)*(s+3.89044)*(s+0.44403))")
    edge = -1.0 / (plant.num[0] / plant.den[0])
    [piece] = affine_stability_intervals(None, (np.array([1.0]), np.array([1.0])), plant.num, plant.den, 0.0, 0.0,
                                         21.8883)
    assert piece.lo == 0.0 and piece.hi == pytest.approx(edge, rel=1e-12) and piece.hi_frequency == np.inf
    for kp, stable in ((0.99 * edge, True), (1.01 * edge, False)):  # the reference: numpy's polynomial roots
        roots = np.roots(np.polyadd(plant.den, kp * plant.num))
        assert bool(np.all(roots.real < 0)) is stable
        assert Loop(plant, f"P({kp})").stability().stable is stable
    assert not Loop(plant, f"P({edge})").stability().stable  # the root at infinity: not bad input
    # the gain margin counts the phase crossover at w -> inf (L(j inf) < 0): kp = 0.3 has edge/0.3 to go
    _, k_hi = LoopBatch(plant, [Controller("P", {"kp": 0.3})]).gain_margin_factors()
    assert k_hi[0] == pytest.approx(edge / 0.3, rel=1e-12)
    assert Loop(plant, "P(0.3)").margins().gain_margin_db == pytest.approx(20 * np.log10(edge / 0.3), rel=1e-9)
    result = design(parse_spec({"name": "b35", "plant": {"tf": "2.96776*(1-s/2.07997)*(s+0.678772)*(s+0.662767)/"
                                                                 "((s+0.318357)*(s+3.89044)*(s+0.44403))"},
                                "controller": {"type": "P", "bounds": {"kp": [0, 21.8883]}},
                                "requirements": [{"type": "margins", "phase_margin_deg": 64.4244}],
                                "objective": {"maximize": "bandwidth"}}))
    assert result.status == "feasible" and 0.642 < result.gain_set.as_list()[-1][1] <= edge
