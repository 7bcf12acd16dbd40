"""freqresp: the whole-run ratio's rest level from the samples before the input moves.

The whole-run ratio below a sweep's longest window took the output's rest level as its mean over the run's first
2 %, which hold the sweep's fade-in: 1.2 % of the output's range off on a sweep through a lightly damped mode, and
the transforms' sum over the run turned that into 10-16 % at the lowest points (noise-free), 70-85 times the
error stated there.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import cont2discrete

from synth.data import record_from_arrays
from synth.ident.simulate import simulate_plant
from synth.ident.spectra import frequency_response
from synth.ident.sweep_design import design_sweep
from synth.ident.whole_run import rest_level
from synth.plant import Plant


def _held_truth(num: list[float], den: list[float], delay: float, dt: float, w: np.ndarray) -> np.ndarray:
    b, a, _ = cont2discrete((num, den), dt, "zoh")
    z = np.exp(1j * w * dt)
    return np.polyval(b.ravel(), z) / np.polyval(a, z) * np.exp(-1j * w * delay)


@pytest.mark.parametrize("num, den, delay, level", [
    ([9.0], [1.0, 1.2, 9.0], 0.08, 0.0),
    ([2.0, 1.0], [1.0, 0.9, 4.0], 0.0, 5.0),
    ([0.5], [1.0, 0.7], 0.2, -3.0),
])
def test_lowest_points_within_their_stated_error(num: list[float], den: list[float], delay: float,
                                                 level: float) -> None:
    plant = Plant(np.array(num), np.array(den), delay=delay)
    t, u = design_sweep(0.5, 15).signal(sample_rate=60)
    y = level + simulate_plant(plant, t, u, "zero")
    rng = np.random.default_rng(7)
    noise = 0.003 * float(np.std(y))
    runs = [record_from_arrays(t, u, y + noise * rng.standard_normal(t.size)) for _ in range(2)]
    r = frequency_response(runs)
    assert any("whole runs' transforms" in n for n in r.notes)
    low = r.band.mask & (r.w < 0.6)
    assert low.sum() >= 3
    ratio = r.H[low] / _held_truth(num, den, delay, t[1] - t[0], r.w[low])
    miss = np.maximum(np.abs(np.log(np.abs(ratio))), np.abs(np.angle(ratio)))
    assert np.all(miss <= 3.0 * r.random_error[low] + 0.002)


def test_rest_level_before_the_input_moves() -> None:
    t = np.arange(0.0, 100.0, 0.01)
    u = np.where(t >= 0.05, 0.5 + np.sin(t), 0.0)  # moves at the sixth sample
    y = 2.0 + np.where(t >= 0.06, 0.3 * (1.0 - np.cos(t - 0.06)), 0.0)  # and the output after it
    mean, var = rest_level(record_from_arrays(t, u, y))
    assert mean == pytest.approx(2.0, abs=1e-12) and var == pytest.approx(0.0, abs=1e-20)
