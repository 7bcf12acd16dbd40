"""freqresp: outputs moved earlier by the response's delay where the longest window is as long as a run.

Three runs of a sweep through a delayed plant: the default longest window is a whole run, and the runs shortened by
the move held no window of that length, so every spectrum was 0/0 and the coherence NaN everywhere ("coherent band:
none"). The shortened runs now take a window as long as they are.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import cont2discrete

from synth.data import record_from_arrays
from synth.ident.simulate import simulate_plant
from synth.ident.spectra import frequency_response
from synth.ident.sweep_design import design_sweep
from synth.plant import Plant


@pytest.mark.parametrize("runs, delay", [(3, 0.2), (4, 0.3), (5, 0.25)])
def test_three_or_more_delayed_runs_give_a_coherent_band(runs: int, delay: float) -> None:
    plant = Plant.from_string("1/(s+1)", delay=delay)
    t, u = design_sweep(0.5, 10).signal(sample_rate=50)
    y = simulate_plant(plant, t, u, "zero")
    rng = np.random.default_rng(runs)
    records = [record_from_arrays(t, u, y + 0.01 * rng.standard_normal(t.size)) for _ in range(runs)]
    r = frequency_response(records, 0.5, 25)
    assert np.all(np.isfinite(r.coherence)) and np.all(np.isfinite(r.H))
    assert any("moved" in n for n in r.notes)  # the aligned estimate, not the fallback
    assert r.band.found and r.band.w_min <= 0.6 and r.band.w_max >= 8.0
    inside = r.band.mask & (r.w <= 8.0)  # within the sweep's excitation (the band's top edge is another matter)
    b, a, _ = cont2discrete(([1.0], [1.0, 1.0]), 0.02, "zoh")  # the held input's response, sampled
    z = np.exp(1j * r.w[inside] * 0.02)
    truth = np.polyval(b.ravel(), z) / np.polyval(a, z) * np.exp(-1j * r.w[inside] * delay)
    rel = np.abs(r.H[inside] / truth - 1.0)
    assert np.max(rel) < 0.05  # 1 % output noise: the estimate within 5 % of the truth
