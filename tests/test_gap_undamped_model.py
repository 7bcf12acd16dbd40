"""A model written with an undamped pair (``k/(s^2 + w^2)``) against a record of the damped plant: the re-fit frees
the missing damping coefficient (a value between nonzero ones, not structure), so the verdict is a parameter
mismatch. Before, the re-fit held ``s^1`` at zero and a black-box test's record (``4/(s^2+3s+2)``, no effect) was
"explained by lag (tau = 1.53): it removes 80 % of the held-out error", accepted with confidence.
Random damped truths; the reference is the truth the record was simulated from (scipy ``lsim``).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.gap.diagnose import diagnose
from synth.plant import Plant


@pytest.mark.parametrize("seed", range(2))
def test_an_undamped_model_of_a_damped_plant_is_a_parameter_mismatch_with_the_damping_refitted(seed: int) -> None:
    rng = np.random.default_rng(seed)
    wn, zeta, gain = rng.uniform(1.0, 4.0), rng.uniform(0.3, 0.8), rng.uniform(0.5, 3.0)
    dt, n = 0.01, 4000
    t = np.arange(n) * dt
    u = np.zeros(n)
    k = 100
    while k < n:  # an uneven step train
        u[k:] = rng.uniform(-2.0, 2.0)
        k += int(rng.uniform(150, 450))
    num, den = [gain * wn**2], [1.0, 2 * zeta * wn, wn**2]
    _, y, _ = signal.lsim((num, den), u, t, interp=False)
    y = y + rng.normal(0.0, 0.01, n)
    model = Plant([gain * wn**2], [1.0, 0.0, wn**2])  # the damping left out
    dg = diagnose(model, record_from_arrays(t, u, y), candidates=["lag", "delay", "rate_limit"], n_null=9)
    assert dg.verdict["effects"] == ["parameter_mismatch"], dg.verdict
    refit = dg.to_dict()["attribution"]["parameter_mismatch"]["refit"]["nominal"]
    assert refit["d1"] == pytest.approx(2 * zeta * wn, rel=0.02)
    assert refit["d0"] == pytest.approx(wn**2, rel=0.02)
