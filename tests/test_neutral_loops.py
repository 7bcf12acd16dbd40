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

from synth.design import design
from synth.loop import Loop
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
