"""A loop's frequency range covers its gain crossovers: the peaks of |S| and |T| sit near them, and they move with
the gain, not with the corners of C and G. Against an independent dense evaluation of |S| (numpy, no synth code)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant
from synth.requirements import PeakComplementary, PeakSensitivity


def _dense_peak_db(num, den, cnum, cden, lo=1e-4, hi=1e7, n=400_001) -> float:
    """Peak of |1/(1 + C G)| in dB from the polynomials: a dense log grid, its maximum refined by scipy's bounded
    scalar search between the neighbouring grid points."""
    from scipy.optimize import minimize_scalar

    def mag(w):
        s = 1j * np.asarray(w, float)
        L = np.polyval(cnum, s) * np.polyval(num, s) / (np.polyval(cden, s) * np.polyval(den, s))
        return np.abs(1.0 / (1.0 + L))

    w = np.geomspace(lo, hi, n)
    k = int(np.argmax(mag(w)))
    a, b = w[max(k - 1, 0)], w[min(k + 1, n - 1)]
    best = minimize_scalar(lambda x: -float(mag(x)), bounds=(a, b), method="bounded", options={"xatol": 1e-12 * b})
    return float(20 * np.log10(max(-best.fun, float(mag(w[k])))))


def test_a_crossover_far_below_every_corner_is_inside_the_range():
    """Seed 13 #7 of the design benchmark: C = (0.0369 s + 115.1)/s on 2.52/s, its only corner at 3116 rad/s, its
    crossover at 17 rad/s with a 45 dB peak of |S|. The range of the corners alone started at 31 rad/s and a
    peak |S| <= 8.5 dB was called met."""
    G = Plant.from_string("2.52253/s")
    c = Controller("rational", {"b0": 115.12860186835321, "b1": 0.03694594446907026, "a0": 0.0})
    loop = Loop(G, c)
    lo, hi = loop.frequency_range
    assert lo < 17.0 / 50 and hi > 3116.0 * 50
    r = PeakSensitivity(max_db=8.53046).evaluate(loop)
    cnum, cden = c.tf()
    assert not r.met
    assert r.value == pytest.approx(_dense_peak_db(G.num, G.den, cnum, cden), abs=0.05)
    assert PeakSensitivity(max_db=8.53046).batch_slack(LoopBatch(G, [c]))[0] == pytest.approx(r.slack, rel=1e-6)


@pytest.mark.parametrize("seed", range(4))
def test_peaks_of_integrating_loops_with_low_crossovers_match_a_dense_grid(seed):
    """Random PIs with a small proportional gain on integrators (lightly damped closed loops whose crossover lies
    decades below the PI's zero): the peak of |S| and |T|, one loop and batched, against the dense evaluation."""
    rng = np.random.default_rng(900 + seed)
    G = Plant(np.array([float(rng.uniform(0.5, 5.0))]), np.array([1.0, 0.0]))
    cs = [Controller("PI", {"kp": float(10 ** rng.uniform(-3, -1)), "ki": float(10 ** rng.uniform(0, 3))})
          for _ in range(6)]
    batch = LoopBatch(G, cs)
    s_batch = PeakSensitivity(max_db=0.0).batch_slack(batch)
    t_batch = PeakComplementary(max_db=0.0).batch_slack(batch)
    for k, c in enumerate(cs):
        loop = Loop(G, c)
        cnum, cden = c.tf()
        value = PeakSensitivity(max_db=0.0).evaluate(loop).value
        assert value == pytest.approx(_dense_peak_db(G.num, G.den, cnum, cden), abs=0.05), c
        assert s_batch[k] == pytest.approx(PeakSensitivity(max_db=0.0).slack(loop), rel=1e-6, abs=1e-9)
        assert t_batch[k] == pytest.approx(PeakComplementary(max_db=0.0).slack(loop), rel=1e-6, abs=1e-9)


def test_a_gain_that_overflows_the_magnitude_keeps_the_corners_range():
    """|L|^2's coefficients overflow for a gain of 1e300: the range is the corners' (no crossovers), one loop and
    batched, without an error."""
    G = Plant.from_string("1/(s+1)")
    huge, usual = Controller("PI", {"kp": 1e300, "ki": 1.0}), Controller("PI", {"kp": 0.037, "ki": 115.0})
    assert Loop(G, huge).frequency_range == (0.01, 100.0)
    ranges = LoopBatch(G, [huge, usual]).frequency_ranges
    assert ranges[0].tolist() == [0.01, 100.0] and ranges[1].tolist() == list(Loop(G, usual).frequency_range)
