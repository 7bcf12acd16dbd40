"""A short record that cannot tell two effects apart says so (a helper's case, session 53).

300 samples of a digital PI loop (scipy, exact zero-order hold) around 20/((s+2)(s+5)) with 5 samples of delay
the model lacks: three reference steps, the first half (the training part) holds one and a half of them. The
nominal coefficients re-fitted with a rate limit and with a delay both drift on so little data, and both fits
miss the held-out half alike, each its own way (their held-out outputs 6.5 noise deviations apart, their held-out
errors the same within the bootstrap interval). The diagnosis named the rate limit alone, "shrinkage 1.00
[0.99, 1.00]"; the data prefer neither, and the delay is now in the leader's indistinguishable group.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.data.record import record_from_arrays
from synth.gap.diagnose import diagnose
from synth.plant import Plant
from tests.pi_loop import digital_pi_loop

pytestmark = pytest.mark.slow


def _record() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    levels = np.random.default_rng(1027).uniform(-1.0, 1.0, 3)
    r = np.concatenate([np.zeros(50), np.repeat(levels, 100)[:250]])
    noise = 0.005 * np.random.default_rng(27).standard_normal(300)
    u, y = digital_pi_loop([20.0], [1.0, 7.0, 10.0], 1.0, 3.0, r, noise, 0.01, delay_samples=5,
                           integrate_after=True)
    return np.arange(300) * 0.01, u, y


def test_a_short_record_groups_the_effects_it_cannot_tell_apart():
    t, u, y = _record()
    dg = diagnose(Plant.from_string("20/((s+2)*(s+5))"), record_from_arrays(t, u, y), n_boot=200)
    lead = dg.verdict["effects"]
    assert len(lead) == 1
    named = {lead[0]} | {e for g in dg.verdict["indistinguishable"] if g[0] == lead[0] for e in g}
    assert "delay" in named, (lead, dg.verdict["indistinguishable"])
    if lead != ["delay"]:
        assert "cannot tell it from" in dg.summary and "delay" in dg.summary
