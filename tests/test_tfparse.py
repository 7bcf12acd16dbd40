import numpy as np
import pytest

from synth.errors import ModelError
from synth.tfparse import parse_tf


@pytest.mark.parametrize("text, num, den, delay", [
    ("23*(s+0.43)/((s+9.6)*(s+0.54))", [23, 23 * 0.43], [1, 10.14, 9.6 * 0.54], 0.0),
    ("1/(s^2+s+1)", [1], [1, 1, 1], 0.0),
    ("1/(s**2+s+1)", [1], [1, 1, 1], 0.0),
    ("exp(-0.02*s)*23*(s+0.43)/((s+9.6)*(s+0.54))", [23, 9.89], [1, 10.14, 5.184], 0.02),
    ("23(s+0.43)/((s+9.6)(s+0.54))", [23, 9.89], [1, 10.14, 5.184], 0.0),
    ("2s/(s+1)^2", [2, 0], [1, 2, 1], 0.0),
    ("1e-3/(s+1e2)", [1e-3], [1, 100], 0.0),
    ("exp(-0.1*s)/(s*(s+1))", [1], [1, 1, 0], 0.1),
    ("(2*s + 4)/(2*s^2 + 2)", [1, 2], [1, 0, 1], 0.0),
    ("1/(s+1) + 1/(s+1)", [2], [1, 1], 0.0),
    ("exp(-0.01*s)*exp(-0.02*s)/(s+1)", [1], [1, 1], 0.03),
    ("4*exp(-0.05*s)/(s*(0.1*s+1))", [40], [1, 10, 0], 0.05),
    ("(s+1)^-1", [1], [1, 1], 0.0),
])
def test_parses(text, num, den, delay):
    tf = parse_tf(text)
    np.testing.assert_allclose(tf.num, num, rtol=1e-12)
    np.testing.assert_allclose(tf.den, den, rtol=1e-12)
    assert tf.delay == pytest.approx(delay, abs=1e-15)


def test_parsed_response_matches_direct_evaluation():
    tf = parse_tf("exp(-0.02*s)*23*(s+0.43)/((s+9.6)*(s+0.54))")
    w = np.geomspace(0.01, 1e3, 50)
    s = 1j * w
    direct = 23 * (s + 0.43) / ((s + 9.6) * (s + 0.54)) * np.exp(-0.02 * s)
    got = np.polyval(tf.num, s) / np.polyval(tf.den, s) * np.exp(-tf.delay * s)
    np.testing.assert_allclose(got, direct, rtol=1e-12)


@pytest.mark.parametrize("text, fragment", [
    ("s^2/(s+1)", "improper"),
    ("s", "improper"),
    ("1/(x+1)", "unknown name 'x'"),
    ("1/(s+", "cannot parse"),
    ("exp(0.1*s)/(s+1)", "predictor"),
    ("1/(s^0.5+1)", "non-integer power"),
    ("exp(-0.1*s)/(s+1) + 1/(s+2)", "different delays"),
    ("sin(s)", "unknown function"),
    ("1/0", "division by zero"),
    ("", "empty"),
    ("1/(s-s)", "division by zero"),
])
def test_rejects(text, fragment):
    with pytest.raises(ModelError, match=fragment):
        parse_tf(text)
