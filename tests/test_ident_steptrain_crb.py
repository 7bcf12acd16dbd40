"""Step trains whose slow mode does not settle between steps (issue 16, item 1): the issue's example plant,
fitted on the whole record, against a Cramer-Rao bound computed here independently (numerical sensitivities
of the simulated output, F = J^T J / sigma^2)."""

from __future__ import annotations

import numpy as np

from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

SENSOR = "442/((s+45)*(s+9.7))"  # the X-4 sensor
STRUCTURE = "k*(s+z)/((s+p1)*(s+p2))"
TRUTH = {"k": 15.0, "z": 0.8, "p1": 12.0, "p2": 0.9, "delay": 0.015}
SIGMA = 1.5
T = np.arange(0, 40, 0.001)


def _input(seed=100):
    """+-25 around 200, a new level every 2 s (random telegraph): the 1.1 s slow mode never settles."""
    levels = np.where(np.random.default_rng(seed).random(20) < 0.5, 175.0, 225.0)
    levels[:2] = (175.0, 225.0)
    return levels[(T // 2.0).astype(int)]


def _output(theta, u):
    k, z, p1, p2, d = theta
    f = Plant.from_string(f"{k}*(s+{z})/((s+{p1})*(s+{p2}))").series(Plant.from_string(SENSOR))
    return simulate_plant(Plant(f.num, f.den, d), T, u - u[0])


def _crb(u):
    theta = np.array(list(TRUTH.values()))
    cols = []
    for i in range(theta.size):
        h = 1e-5 * abs(theta[i])
        up, dn = theta.copy(), theta.copy()
        up[i] += h
        dn[i] -= h
        cols.append((_output(up, u) - _output(dn, u)) / (2 * h))
    J = np.column_stack([*cols, np.ones(T.size)])  # the output offset is a nuisance parameter
    return dict(zip(TRUTH, np.sqrt(np.diag(np.linalg.inv(J.T @ J / SIGMA**2)))[:-1]))


def test_unsettled_train_is_fitted_whole_near_the_cramer_rao_bound():
    u = _input()
    y = 800 + _output(list(TRUTH.values()), u) + SIGMA * np.random.default_rng(3).normal(size=T.size)
    res = identify((T, u, y), STRUCTURE, delay="fit", sensor=SENSOR)
    assert res.average.mode == "edge" and "fitted the whole record" in res.whole_record_note
    # the reported standard error is the bound (the first 5.6 s, a start-up from rest here, are not fitted)
    _at_the_bound(res, u, 1.4)


def _at_the_bound(res, u, upper):
    """Every estimate within 4 bounds of the truth, every reported standard error within 0.9-``upper`` bounds."""
    p, sd = dict(res.fit.parameters), dict(res.fit.std)
    if p["p1"] < p["p2"]:
        p["p1"], p["p2"], sd["p1"], sd["p2"] = p["p2"], p["p1"], sd["p2"], sd["p1"]
    crb = _crb(u)
    for name, truth in TRUTH.items():
        assert abs(p[name] - truth) < 4 * crb[name], (name, p[name], crb[name])
        assert 0.9 * crb[name] < sd[name] < upper * crb[name], (name, sd[name], crb[name])


def test_periodic_train_after_a_short_rest_is_fitted_whole_near_the_cramer_rao_bound():
    """A square wave (1 s half periods: the 1.1 s slow mode never settles) after 1.5 s at the low level: the
    periodic average, its mean removed, loses the static gain that the transition from rest carries, and its
    standard errors were 2-7 times the bound on such records (``benchmarks/ident_crb.py --rest 0.3``)."""
    u = np.where(T < 1.5, 175.0, np.where(((T - 1.5) // 1.0) % 2 == 0, 225.0, 175.0))
    y = 800 + _output(list(TRUTH.values()), u) + SIGMA * np.random.default_rng(5).normal(size=T.size)
    res = identify((T, u, y), STRUCTURE, delay="fit", sensor=SENSOR)
    assert res.average.mode == "cycle" and res.whole_record_note.startswith("the whole record, from rest")
    _at_the_bound(res, u, 1.2)
