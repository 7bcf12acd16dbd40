"""identify: an integrating model on a record whose input steps at its first sample from 0.

The model is at rest only under the input that holds its output still, and a whole-record fit takes the first
input sample for that trim. A record that starts exactly at a step from 0 (here 0 -> 1.5) is not at rest under
that reading, the fit fails (right: a failure, not a result), and its message said "cut the record to start at
rest", which this record already does. It now says how the first sample is read and what the record needs.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.errors import FitError
from synth.ident.identification import identify


def _record(first_zero: bool):
    rng = np.random.default_rng(0)
    dt, n = 0.01, 1500
    t = np.arange(n) * dt
    u = np.where((t % 3.0) < 1.5, 1.5, 0.5)
    if first_zero:
        u[:50] = 0.0  # half a second at rest before the train
    b, a, _ = signal.cont2discrete(([2.0], [1.0, 1.0, 0.0]), dt, "zoh")
    y = signal.lfilter(b.ravel(), a, u) + 0.01 * rng.standard_normal(n)
    return record_from_arrays(t, u, y)


def test_the_failure_says_how_the_first_sample_is_read():
    with pytest.raises(FitError, match=r"the first input sample, 1\.5, is taken as that trim; a record whose input "
                                       r"steps to it at its first sample from 0 needs the samples before the step"):
        identify(_record(first_zero=False), "k/(s*(s+p))")


def test_with_the_samples_before_the_step_the_plant_is_identified():
    r = identify(_record(first_zero=True), "k/(s*(s+p))")
    assert r.fit.parameters["k"] == pytest.approx(2.0, rel=0.02) and r.fit.parameters["p"] == pytest.approx(1.0, rel=0.03)
