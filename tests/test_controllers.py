import numpy as np
import pytest

from synth.controllers import Controller
from synth.errors import ModelError


@pytest.mark.parametrize("text, expected", [
    ("P(3)", {"kp": 3.0}),
    ("p(kp=2.5)", {"kp": 2.5}),
    ("PI(kp=1.2, ki=20)", {"kp": 1.2, "ki": 20.0}),
    ("PI(1.2, 20)", {"kp": 1.2, "ki": 20.0}),
    ("PID(1, 2, 0.1, 0.01)", {"kp": 1.0, "ki": 2.0, "kd": 0.1, "tf": 0.01}),
    ("leadlag(k=2, z=1, p=10)", {"k": 2.0, "z": 1.0, "p": 10.0}),
    ("P(-1e-1)", {"kp": -0.1}),
])
def test_parse(text, expected):
    assert Controller.from_string(text).parameters == expected


@pytest.mark.parametrize("text, fragment", [
    ("Q(3)", "unknown controller type"),
    ("P(3, 4)", "takes 1 parameter"),
    ("PI(kp=1)", "needs a value for ki"),
    ("PI(kp=1, kx=2)", "no parameter 'kx'"),
    ("P(kp='a')", "must be numbers"),
    ("PID(1, 2, 0.1, 0)", "tf must be > 0"),
    ("P 3", "cannot parse"),
    ("P(3, kp=4)", "twice"),
])
def test_parse_errors(text, fragment):
    with pytest.raises(ModelError, match=fragment):
        Controller.from_string(text)


def test_transfer_functions_match_their_formulas():
    w = np.geomspace(0.01, 1e3, 60)
    s = 1j * w
    cases = {
        "P(3)": 3 + 0 * s,
        "PI(kp=1.2, ki=20)": 1.2 + 20 / s,
        "PID(kp=1, ki=2, kd=0.1, tf=0.01)": 1 + 2 / s + 0.1 * s / (0.01 * s + 1),
        "leadlag(k=2, z=1, p=10)": 2 * (s + 1) / (s + 10),
    }
    for text, expected in cases.items():
        np.testing.assert_allclose(Controller.from_string(text).freqresp(w), expected, rtol=1e-12)


def test_dc_gain_and_text():
    assert Controller.from_string("P(3)").dc_gain() == 3.0
    assert np.isinf(Controller.from_string("PI(1, 2)").dc_gain())
    assert Controller.from_string("leadlag(2, 1, 10)").dc_gain() == pytest.approx(0.2)
    c = Controller.from_string("PI(kp=1.2, ki=20)")
    assert Controller.from_string(str(c)) == c
