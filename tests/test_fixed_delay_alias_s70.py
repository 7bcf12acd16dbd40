"""A fixed delay off by half a train period fits as well with the gain reversed (black-box helper, session 70):
the record's start-up from rest is screened and a note says which delay it prefers."""

from __future__ import annotations

import re

import numpy as np
import pytest

from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.plant import Plant


def _case(seed):
    """A first-order plant behind a delay, a 0/1 square train of half period `hold` after a constant start."""
    rng = np.random.default_rng(4200 + seed)
    k, tau = rng.uniform(0.5, 5.0), rng.uniform(0.05, 0.6)
    hold = rng.uniform(6, 10) * tau
    delay = rng.uniform(0.05, 0.8) * hold
    rest = rng.uniform(0.5, 2.0) * hold
    dt = 0.01
    t = np.arange(0.0, rest + 20 * hold, dt)
    u = np.where(t < rest, 0.0, ((t - rest) // hold) % 2 == 0).astype(float)
    y = simulate_plant(Plant.from_string(f"{k}/({tau}*s+1)", delay=delay), t, u)
    y = y + 0.01 * k * rng.normal(size=t.size)
    return (t, u, y), k, delay, hold


@pytest.mark.parametrize("seed", range(4))
def test_a_half_period_alias_of_a_fixed_delay_is_named_and_the_true_one_is_not(seed):
    record, k, delay, hold = _case(seed)
    wrong = identify(record, "k/(T*s+1)", delay=delay + hold)  # half a period (2 holds) later
    assert wrong.fit.parameters["k"] < 0  # the periodic average fits it, reversed
    preferred = re.search(r"prefers a delay of ([0-9.e+-]+) s with the gain reversed", wrong.whole_record_note)
    assert preferred is not None and float(preferred.group(1)) == pytest.approx(delay, abs=0.011)  # whole samples
    right = identify(record, "k/(T*s+1)", delay=delay)
    assert right.fit.parameters["k"] == pytest.approx(k, rel=0.02)
    assert "was given as" not in right.whole_record_note
