"""Up and down steps of an aperiodic train compared on the steps that start settled (synth.ident.directions.
settled_steps).

Session 70's black-box finding: on a train with random holds, the shortest hold left 37-43 % of a step when the next
came, and the comparison widened every parameter's standard error by twice that share of the parameter, so down
steps three times slower than up steps (T 0.12 s against 0.04 s, 60 steps) "agreed within their uncertainty"
(-0.8 sigma). Now, where more than 0.5 % was left, the directions are compared again on the steps that came after the
previous one had settled to 0.5 % by its direction's model, with windows that end before every next step."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.plant import Plant


def _train(seed: int, t_up: float, t_down: float, holds: tuple[float, float]):
    rng = np.random.default_rng(seed)
    edges = np.cumsum(np.r_[0.5, rng.uniform(*holds, 60)])
    t = np.arange(0.0, edges[-1] + 0.8, 1e-3)
    u = np.zeros(t.size)
    for k, edge in enumerate(edges):
        u[t >= edge] = (k + 1) % 2
    w_up = np.cumsum(np.maximum(np.diff(u, prepend=0.0), 0.0))
    y = (simulate_plant(Plant.from_string(f"2/({t_up}*s+1)"), t, w_up)
         + simulate_plant(Plant.from_string(f"2/({t_down}*s+1)"), t, u - w_up))
    return record_from_arrays(t, u, y + 0.01 * rng.normal(size=t.size))


@pytest.mark.parametrize("seed", [0, 1])
def test_three_times_slower_down_steps_are_found_on_a_train_of_random_holds(seed):
    d = identify(_train(seed, 0.04, 0.12, (0.1, 0.8)), "K/(T*s+1)", delay=0.0).directions
    assert d.significant, d.summary()  # was: "agree within their uncertainty", -0.8 sigma
    assert "settled to 0.5 %" in d.selected and d.unsettled <= 0.005
    for fit, truth in ((d.up, 0.04), (d.down, 0.12)):
        assert abs(fit.parameters["T"] - truth) < 4 * fit.std["T"] + 1e-3 * truth


def test_a_ten_percent_difference_is_found_and_a_linear_plant_is_not_called_direction_dependent():
    assert identify(_train(0, 0.04, 0.044, (0.05, 0.4)), "K/(T*s+1)", delay=0.0).directions.significant
    alarms = [identify(_train(seed, 0.04, 0.04, (0.05, 0.4)), "K/(T*s+1)", delay=0.0).directions.significant
              for seed in range(4)]
    assert not any(alarms)
