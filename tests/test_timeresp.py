import control
import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.timeresp import step_metrics, step_response

from .conftest import X4_PLANT


def test_delay_free_step_matches_python_control():
    loop = Loop(Plant.from_string(X4_PLANT), Controller("P", {"kp": 3.0}))
    t, y, dt = step_response(loop, 0.3)
    T = control.feedback(3 * control.tf(loop.plant.num, loop.plant.den), 1)
    _, yc = control.step_response(T, t)
    assert dt == 0.0
    np.testing.assert_allclose(y, yc, atol=1e-9)
    m = step_metrics(t, y, y_final=loop.T0())
    assert m.rise_time == pytest.approx(0.025, abs=0.001)  # the seed's linear prediction, about 0.025 s


def test_delayed_step_matches_pade_model():
    loop = Loop(Plant.from_string(X4_PLANT, delay=0.01), Controller("P", {"kp": 3.0}))
    t, y, dt = step_response(loop, 0.3)
    sys = 3 * control.tf(loop.plant.num, loop.plant.den) * control.tf(*control.pade(0.01, 6))
    _, yc = control.step_response(control.feedback(sys, 1), t)
    assert dt > 0
    assert np.all(y[t <= 0.01 - dt] == 0.0)  # nothing moves before the delay (a Pade model wiggles)
    late = t > 5 * 0.01
    np.testing.assert_allclose(y[late], yc[late], atol=2e-3)


def test_step_metrics_first_order_closed_form():
    t = np.linspace(0, 10, 100001)
    m = step_metrics(t, 1 - np.exp(-t), y_final=1.0)
    assert m.rise_time == pytest.approx(np.log(9), abs=1e-4)
    assert m.settling_time == pytest.approx(-np.log(0.02), abs=1e-3)
    assert m.overshoot == 0.0
    wn, z = 1.0, 0.3
    sys = control.tf([wn**2], [1, 2 * z * wn, wn**2])
    tt, yy = control.step_response(sys, np.linspace(0, 60, 60001))
    m2 = step_metrics(tt, yy, y_final=1.0)
    assert m2.overshoot == pytest.approx(100 * np.exp(-z * np.pi / np.sqrt(1 - z * z)), abs=1e-3)
