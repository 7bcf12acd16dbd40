import control
import numpy as np
import pytest

from synth.errors import ModelError
from synth.plant import Plant

from .conftest import X4_PLANT


def test_delay_is_exact_in_frequency_domain():
    G = Plant.from_string(X4_PLANT, delay=0.02)
    G0 = Plant.from_string(X4_PLANT)
    w = np.geomspace(0.1, 1e4, 200)
    np.testing.assert_allclose(np.abs(G.freqresp(w)), np.abs(G0.freqresp(w)), rtol=1e-12)
    # the ratio is exactly exp(-j w tau) at every frequency; a Pade approximation would drift
    np.testing.assert_allclose(G.freqresp(w) / G0.freqresp(w), np.exp(-0.02j * w), rtol=1e-10)


def test_dc_gain_of_seed_plant():
    assert Plant.from_string(X4_PLANT).dc_gain() == pytest.approx(23 * 0.43 / (9.6 * 0.54), rel=1e-12)
    assert Plant.from_string(X4_PLANT).dc_gain() == pytest.approx(1.908, abs=5e-4)


def test_python_control_round_trip():
    G = Plant.from_string(X4_PLANT)
    sys = G.to_control()
    w = np.geomspace(0.01, 1e3, 40)
    np.testing.assert_allclose(sys(1j * w), G.freqresp(w), rtol=1e-12)
    back = Plant.from_control(sys, delay=0.01)
    np.testing.assert_allclose(back.num, G.num)
    np.testing.assert_allclose(back.den, G.den)
    assert back.delay == 0.01
    ss = control.tf2ss(sys)
    np.testing.assert_allclose(Plant.from_control(ss).freqresp(w), G.freqresp(w), rtol=1e-9)


def test_to_control_refuses_silent_delay_loss_and_pade_is_explicit():
    G = Plant.from_string(X4_PLANT, delay=0.02)
    with pytest.raises(ModelError, match="pade_order"):
        G.to_control()
    approx = G.to_control(pade_order=6)
    w = np.geomspace(0.1, 50, 20)
    np.testing.assert_allclose(approx(1j * w), G.freqresp(w), rtol=1e-6)


def test_text_round_trip():
    for text in [X4_PLANT, "exp(-0.1*s)/(s^2+s+1)", "4*exp(-0.05*s)/(s*(0.1*s+1))", "(s-2)/((s+1)*(s+3))"]:
        G = Plant.from_string(text)
        back = Plant.from_string(G.to_string(12))
        w = np.geomspace(0.01, 100, 30)
        np.testing.assert_allclose(back.freqresp(w), G.freqresp(w), rtol=1e-9)


def test_invalid_plants():
    with pytest.raises(ModelError):
        Plant(np.array([1.0, 0, 0]), np.array([1.0, 1.0]))
    with pytest.raises(ModelError, match="delay"):
        Plant(np.array([1.0]), np.array([1.0, 1.0]), delay=-1.0)
