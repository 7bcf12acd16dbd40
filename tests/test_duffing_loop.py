"""The Duffing effect's compiled spring loop returns, bit for bit, what the same loop interpreted returns (numba's
``py_func``), on random plants, delays, records and springs of both signs; and a spring at rest holds
``y + cubic y^3 = G(0) u`` (an independent closed form)."""

from unittest import mock

import numpy as np
import pytest

from benchmarks.duffing_loop_speed import random_case
from synth.gap.effects import amplitude
from synth.ident.simulate import simulate_plant
from synth.plant import Plant


@pytest.mark.parametrize("seed", range(6))
def test_the_compiled_spring_loop_is_the_interpreted_one(seed):
    plant, u, dt, cubic = random_case(np.random.default_rng(seed))
    fast = amplitude.cubic_feedback(plant, u, dt, cubic)
    with mock.patch.object(amplitude, "_spring_inputs", amplitude._spring_inputs.py_func):
        slow = amplitude.cubic_feedback(plant, u, dt, cubic)
    assert np.array_equal(fast, slow, equal_nan=True)


@pytest.mark.parametrize("cubic", [0.3, -0.005])  # softening: still short of its turning point
def test_a_spring_driven_by_a_held_command_settles_where_the_closed_form_says(cubic):
    plant = Plant.from_string("40/(s^2+6*s+20)", delay=0.004)  # G(0) = 2
    t = np.arange(0, 6, 0.001)
    u = np.where(t < 1.0, 0.5, 1.5)
    y = simulate_plant(plant, t, amplitude.cubic_feedback(plant, u, 0.001, cubic))
    roots = np.roots([cubic, 0.0, 1.0, -2.0 * 1.5])
    y_rest = min(roots[np.abs(roots.imag) < 1e-9].real, key=lambda r: abs(r - 3.0))
    assert y[-1] == pytest.approx(y_rest, rel=1e-4)
    assert abs(y[-1] - 3.0) > 0.01  # the spring moved the rest point away from the linear one
