"""A fitted delay longer than a step train's period, or than the spacing of its steps (a black-box test, session 62).

The averaged period of a train fits a delay ``d`` as well as ``d + j P``, and a train holding its two levels alike
as well as ``d + P/2 + j P`` with the gain reversed: a model 2.3 s behind a 2 s train came out 0.3 s behind it,
and one 1.3 s behind with the gain negative, exit 0. Edge windows shorter than the delay led the whole record's
refit to K = -0.71 at a 21 % fit. The records here are simulated by scipy alone (zero-order hold at a tenth of
the sample time, the delay a whole number of those steps), not by synth.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.ident_delay_alias import DT, case, simulate
from synth.data import record_from_arrays
from synth.ident.delay_alias import screen_aliases
from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.plant import Plant


def square_train(n: int, rest: float, period: float, duty: float) -> np.ndarray:
    t = np.arange(n) * DT
    phase = np.mod(t - rest, period)
    return np.where(t < rest, 0.0, (phase < duty * period - 1e-9).astype(float))


def test_the_screen_scores_every_alias_as_a_direct_residual_would():
    """The FFT sums against shifting, subtracting and weighting each alias directly (odd period: half samples)."""
    rng = np.random.default_rng(3)
    n, period = 3000, 151
    t = np.arange(n) * DT
    u = square_train(n, 2.0, period * DT, 0.5)
    y = rng.normal(size=n) + simulate([3.0], [0.3, 1.0], u, 0.52)
    weights = (t >= 0.5).astype(float)
    model = Plant([3.0], [0.3, 1.0], delay=0.52)
    scr = screen_aliases(t, u, y, model, period, weights, 20.0)
    for delay, sign, ssr in zip(scr.delays, scr.signs, scr.ssr):
        yhat = sign * simulate_plant(Plant([3.0], [0.3, 1.0], delay=float(delay)), t, u, initial="zero")
        r = (y - yhat)[weights > 0]
        assert ssr == pytest.approx(float(np.sum((r - r.mean()) ** 2)), rel=1e-9)
    assert scr.delays[0] == 0.52 and scr.delays.max() <= 20.0 + 1e-9
    assert sorted(np.round(np.diff(np.sort(scr.delays)), 9)) == [round(period * DT / 2, 9)] * (scr.delays.size - 1)


CASES = [  # (num, den, delay [s], period [s], duty): delays past the period, past half of it, on fast and slow plants
    ([1.0], [0.2, 1.0], 2.3, 2.0, 0.5),
    ([1.0], [0.2, 1.0], 1.3, 2.0, 0.5),
    ([10.0], [1.0, 7.0, 10.0], 1.8, 3.0, 0.5),
    ([1.5], [0.1, 1.0], 2.05, 1.6, 0.5),
    ([0.8], [0.4, 1.0], 0.9, 3.2, 0.5),
]
STRUCTURES = {1: "K/(T*s+1)", 2: "k/((s+p1)*(s+p2))"}


@pytest.mark.slow
@pytest.mark.parametrize("case", range(len(CASES)))
def test_a_train_entered_from_rest_gives_the_true_delay_not_an_alias(case):
    num, den, delay, period, duty = CASES[case]
    rng = np.random.default_rng(case)
    n = round((4.0 + 12 * period) / DT)  # 4 s at rest, then 12 periods
    u = square_train(n, 4.0, period, duty)
    y = simulate(num, den, u, delay) + 0.01 * rng.normal(size=n)
    structure = STRUCTURES[len(den) - 1] if len(num) == 1 else "k*(s+z)/((s+p1)*(s+p2))"
    res = identify(record_from_arrays(np.arange(n) * DT, u, y), structure, delay="fit")
    assert not res.fit.periodic  # the whole record, from rest
    assert abs(res.fit.delay - delay) <= max(4 * res.fit.std["delay"], 0.002), (res.fit.delay, res.whole_record_note)
    truth = Plant(num, den)
    assert res.fit.plant.dc_gain() == pytest.approx(truth.dc_gain(), rel=0.02)
    assert res.fit.fit_percent > 90


@pytest.mark.slow
def test_edge_windows_shorter_than_the_delay_give_the_true_delay():
    rng = np.random.default_rng(0)
    n = 8000
    t = np.arange(n) * DT
    edges = 3 + np.cumsum(rng.uniform(1.0, 3.0, 60))
    u = np.zeros(n)
    for i, e in enumerate(edges[edges < t[-1]]):
        u[t >= e] = (i + 1) % 2
    y = simulate([1.0], [0.2, 1.0], u, 2.5) + 0.02 * rng.normal(size=n)
    res = identify(record_from_arrays(t, u, y), "K/(T*s+1)", delay="fit")
    assert res.average is not None and res.average.mode == "edge"
    assert res.fit.parameters["K"] == pytest.approx(1.0, abs=0.01)
    assert res.fit.delay == pytest.approx(2.5, abs=0.002)


def test_a_record_cut_out_of_a_running_train_says_the_delay_is_known_only_up_to_the_period():
    n, cut = 6000, 2050  # the record starts 20.5 s into the train, in its periodic steady state
    u = square_train(n + cut, 0.0, 2.0, 0.5)
    y = simulate([1.0], [0.2, 1.0], u, 0.3) + 0.01 * np.random.default_rng(1).normal(size=n + cut)
    res = identify(record_from_arrays(np.arange(n) * DT, u[cut:], y[cut:]), "K/(T*s+1)", delay="fit")
    note = res.to_dict()["whole_record"]
    assert res.fit.periodic and "known only up to the 2 s period" in note
    assert res.fit.delay == pytest.approx(0.3, abs=0.002)


def test_edge_windows_of_an_unequal_train_shorter_than_the_delay_give_the_true_delay():
    # the edge fit's model (K = -0.63, no delay) settles within its windows, so no refit was asked for: it is now
    # refitted because it misses the whole record by far more than the record's noise (synth.ident.edge_check)
    n = 6000
    u = square_train(n, 4.0, 1.6, 0.3)
    y = simulate([1.5], [0.1, 1.0], u, 2.05) + 0.01 * np.random.default_rng(4).normal(size=n)
    res = identify(record_from_arrays(np.arange(n) * DT, u, y), "K/(T*s+1)", delay="fit")
    assert res.fit.delay == pytest.approx(2.05, abs=0.002) and res.fit.parameters["K"] == pytest.approx(1.5, rel=0.01)
    assert "misses the whole record by" in res.whole_record_note


@pytest.mark.parametrize("index", [0, 9, 10, 13])
def test_a_seeded_sample_of_the_benchmark_gets_delay_and_gain(index):
    # benchmarks/ident_delay_alias.py --seed 1: the session's start put each of these at another alias
    c = case(1, index, "trains")
    res = identify(c["record"], c["structure"], delay="fit")
    assert abs(res.fit.delay - c["delay"]) <= max(4 * res.fit.std["delay"], 2 * DT), (index, res.fit.delay, c["delay"])
    assert res.fit.plant.dc_gain() == pytest.approx(c["gain"], rel=0.05)
