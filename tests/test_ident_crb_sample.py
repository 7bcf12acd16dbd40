"""A seeded sample of the randomized step-train benchmark (benchmarks/ident_crb.py, issue 16 item 1): on each case
the fit lands within a few Cramer-Rao bounds of the truth and reports standard errors near the bound, the bound
computed independently of synth (scipy simulation, finite-difference sensitivities). The full benchmark (50 cases
x 20 noise seeds, the empirical std and bias against the bound) is in benchmarks/README.md."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.ident_crb import DT, make_case, matched, sensor_text
from synth.ident.identification import identify


@pytest.mark.parametrize("index", [1])  # a periodic train entered from rest (test_ident_steptrain_crb: an aperiodic one)
def test_benchmark_sample_fits_near_the_independent_cramer_rao_bound(index):
    case = make_case(index, 16000)
    bound = case.bound
    t = np.arange(case.samples) * DT
    y = 3.0 + case.y0 + case.sigma * np.random.default_rng(99).normal(size=case.samples)
    res = identify((t, case.u, y), case.structure, "fit" if case.fit_delay else case.delay, sensor_text(case.sensor),
                   compare_directions=False)
    names = bound["names"]
    truth = np.array([case.truth.get(n, case.delay) for n in names])
    value, std = matched(names, res.fit.parameters, res.fit.std, dict(zip(names, truth)))
    assert np.all(np.abs(value - truth) < 4.5 * bound["std"]), dict(zip(names, (value - truth) / bound["std"]))
    assert np.all((std > 0.75 * bound["std"]) & (std < 1.4 * bound["std"])), dict(zip(names, std / bound["std"]))
