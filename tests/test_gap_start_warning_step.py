"""diagnose: a record at rest until its first step is not warned about as not starting at rest.

One step at 0.5 s through a delay the model lacks: the residual is large at the step and decays, which the
start-transient test read as "the record may not start at rest ... give --burn-in 5", advice that would discard the
only step (a black-box helper). Quiet until the command first moves, the record did start at rest.
"""

from __future__ import annotations

import numpy as np

from synth.data import record_from_arrays
from synth.gap.where.residual import model_residual
from synth.gap.where.start import start_transient_warning
from synth.ident.simulate import simulate_plant
from synth.plant import Plant


def test_a_step_after_rest_is_no_start_transient():
    G = Plant.from_string("1/(s+1)")
    t = np.arange(0, 20, 0.01)
    u = np.where(t >= 0.5, 1.0, 0.0)
    noise = 0.01 * np.random.default_rng(0).normal(size=t.size)
    y = simulate_plant(Plant.from_string("1/(s+1)", delay=0.1), t, u) + noise
    assert start_transient_warning(G, model_residual(G, record_from_arrays(t, u, y))) == ""
    # the same record starting in motion (the output still settling from 1 at t = 0) is warned about
    y_moving = y + np.exp(-t)
    assert "may not start at rest" in start_transient_warning(G, model_residual(G, record_from_arrays(t, u, y_moving)))
