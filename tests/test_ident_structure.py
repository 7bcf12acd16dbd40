"""Parametric structures: coefficients against hand expansion, casadi agrees with numpy, clear errors."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from synth.errors import ModelError
from synth.ident.structure import parse_structure


def test_x4_structure_matches_hand_expansion():
    st = parse_structure("k*(s+z)/((s+p1)*(s+p2))")
    num, den = st.coefficients({"k": 23.0, "z": 0.43, "p1": 9.6, "p2": 0.54})
    assert np.allclose(num, [23.0, 23.0 * 0.43])
    assert np.allclose(den, [1.0, 9.6 + 0.54, 9.6 * 0.54])


def test_time_constant_form_and_delay_parameter():
    st = parse_structure("K*exp(-Td*s)/(T1*s+1)^2")
    assert st.parameters == ("K", "T1") and st.delay_parameter == "Td"
    G = st.plant({"K": 245.5, "T1": 0.147, "Td": 0.035})
    w = np.array([0.0, 1.0, 7.0])
    expected = 245.5 * np.exp(-0.035j * w) / (0.147j * w + 1) ** 2
    assert np.allclose(G.freqresp(w), expected, rtol=1e-12)


def test_fixed_numeric_delay_and_implicit_products():
    st = parse_structure("2k*(s+z)exp(-0.02*s)/((s+p)(s+q))")
    assert st.delay == pytest.approx(0.02) and st.parameters == ("k", "z", "p", "q")
    num, den = st.coefficients([1.5, 2.0, 3.0, 4.0])
    assert np.allclose(num, [3.0, 6.0]) and np.allclose(den, [1.0, 7.0, 12.0])


def test_casadi_coefficients_equal_numpy_and_give_exact_derivatives():
    st = parse_structure("K*w^2/(s^2+2*zeta*w*s+w^2)")
    th = ca.SX.sym("th", 3)
    num, den = st.casadi_coefficients(th)
    f = ca.Function("f", [th], [ca.vertcat(*num, *den)])
    x = np.array([2.0, 5.0, 0.3])
    n_np, d_np = st.coefficients(x)
    assert np.allclose(np.asarray(f(x)).ravel(), np.r_[n_np, d_np])
    jac = np.asarray(ca.Function("j", [th], [ca.jacobian(ca.vertcat(*den), th)])(x))
    # d(2 zeta w)/dw = 2 zeta, d(w^2)/dw = 2 w
    assert jac[1, 1] == pytest.approx(2 * 0.3) and jac[2, 1] == pytest.approx(2 * 5.0)


@pytest.mark.parametrize("formula, message", [
    ("k*s^2/(s+p)", "improper"),
    ("(s+1)/(s+2)", "no parameters"),
    ("k/(s+p", "cannot parse"),
    ("k/(s+p)+exp(-Td*s)", "only multiply"),
    ("k/(s+Td)*exp(-Td*s)", "also appears"),
    ("k/(s+p)*exp(-2*Td*s)", "one parameter"),
    ("k/(s+p)*exp(0.1*s)", "predictor"),
    ("k/sin(s)", "unknown function"),
    ("k(s+z)/(s+p)", "write k\\*"),
    ("k/(s+p)$", "unexpected character"),
    ("", "empty"),
])
def test_bad_formulas_raise_one_line_model_errors(formula, message):
    with pytest.raises(ModelError, match=message) as err:
        parse_structure(formula)
    assert "\n" not in str(err.value)


def test_wrong_number_of_values():
    with pytest.raises(ModelError, match="2 parameters"):
        parse_structure("k/(s+p)").coefficients([1.0])
