"""fit_structure's rtol (convolution solver): a looser stop costs at most rtol of the SSR, and fewer iterations."""

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.ident.simulate import simulate_plant
from synth.ident.timefit import fit_structure
from synth.plant import Plant


@pytest.mark.parametrize("seed", range(3))
def test_rtol_stops_earlier_within_its_share_of_the_ssr(seed):
    rng = np.random.default_rng(seed)
    t = np.arange(6000) * 0.01
    u = np.repeat(rng.uniform(-1, 1, 6000 // 150 + 1), 150)[:6000]
    true = Plant.from_string(f"{rng.uniform(1, 5)}/((s+{rng.uniform(0.5, 2)})*(s+{rng.uniform(4, 9)}))")
    y = simulate_plant(true, t, np.tanh(2 * u)) + 0.02 * rng.standard_normal(t.size)  # misspecified: no tanh
    rec = record_from_arrays(t, u, y)
    start = {"k": 2.0, "p1": 1.0, "p2": 5.0}
    exact = fit_structure(rec, "k/((s+p1)*(s+p2))", delay=0.0, initial=start, solver="convolution")
    loose = fit_structure(rec, "k/((s+p1)*(s+p2))", delay=0.0, initial=start, solver="convolution", rtol=1e-4)
    ssr_exact = float(np.sum(exact.residuals ** 2))
    ssr_loose = float(np.sum(loose.residuals ** 2))
    assert ssr_exact <= ssr_loose <= ssr_exact * (1 + 2e-4)
    assert loose.solver["iterations"] < exact.solver["iterations"]
