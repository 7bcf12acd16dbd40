"""A seeded sample of benchmarks/split_check.py: randomized cases of the Cramer-Rao generator (a first-order
periodic train, a second-order aperiodic train with a zero, a first-order train at 1 % noise) whose Monte-Carlo
scatter over 5 seeds was within 1.2-1.6 times the reported std under white noise and 4.2-5.0 times under AR(1)
noise (0.95): the split check says "consistent" and "stds too small" there, with a factor above 3."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.ident_crb import DT, make_case, sensor_text
from benchmarks.split_check import noise
from synth.data import record_from_arrays
from synth.ident.split_check import split_check


@pytest.mark.parametrize("index", [0, 2, 14])
def test_white_noise_is_consistent_and_coloured_noise_is_caught(index):
    case = make_case(index, 16000)
    t = np.arange(case.samples) * DT
    delay = "fit" if case.fit_delay else case.delay
    verdicts = {}
    for kind in ("white", "ar"):
        y = 3.0 + case.y0 + noise(kind, case.sigma, case.samples, np.random.default_rng(1000 * index))
        verdicts[kind] = split_check(record_from_arrays(t, case.u, y), case.structure, delay,
                                     sensor_text(case.sensor), parts=5)
    assert verdicts["white"].verdict == "consistent", verdicts["white"].text()
    assert verdicts["ar"].verdict == "stds too small" and max(verdicts["ar"].ratio.values()) > 3
