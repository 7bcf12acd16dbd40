"""diagnose: an output clip seen in the data is among the default candidates.

A sensor clipping at 0.35 with every default candidate: the verdict was an input saturation with a lower limit the
truth does not have ("saturation (lower = -0.5762, upper = 0.3719)"), while the summary itself said the output rests
on its maximum; only --candidates with saturation(output) named it (a black-box helper). Clipped over half its
samples, the record also had a noise floor of 0 from the residual's second differences where the output rests.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.gap.diagnose import diagnose
from synth.plant import Plant


@pytest.mark.slow
def test_a_clipped_output_is_named_with_the_default_candidates():
    rng = np.random.default_rng(32)
    dt, n = 0.01, 2500
    t = np.arange(n) * dt
    u = np.repeat(rng.choice([-1.0, 1.0], n // 100), 100)  # levels held 1 s
    b, a, _ = signal.cont2discrete(([1.0], [0.5, 1.0]), dt, "zoh")
    y = np.minimum(signal.lfilter(b.ravel(), a, u) + 0.005 * rng.standard_normal(n), 0.35)  # the sensor's range
    d = diagnose(Plant.from_string("1/(0.5*s+1)"), (t, u, y), n_null=9)
    assert d.verdict["effects"] == ["saturation(output)"]
    fit = next(e for e in d.attribution.effects if e.effect == "saturation(output)")
    assert fit.parameters["upper"] == pytest.approx(0.35, abs=0.03)  # noise clipped with the signal: a bit lower
    # the output rests on its clip over half the record, where it holds no noise: the floor from the samples that
    # move (before: 3e-9, and "the held-out error is inf times the noise floor")
    assert d.attribution.noise_floor == pytest.approx(0.005**2, rel=0.2)
