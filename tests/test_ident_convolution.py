"""The FFT-convolution problem (long records) against the casadi/IPOPT one: the same optimum and uncertainty on
random plants, delays, sensors, periodic and at-rest records, and weights (issue 16, item 1: speed)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.ident.simulate import simulate_plant
from synth.ident.timefit import fit_structure
from synth.plant import Plant

DT = 0.004


def _case(seed: int):
    rng = np.random.default_rng(seed)
    p1, p2 = rng.uniform(0.8, 2.0), rng.uniform(6.0, 20.0)
    z = rng.uniform(2.5, 5.0)
    k = p1 * p2 / z * rng.uniform(0.5, 2.0)
    sensor = f"{40 * 60}/((s+40)*(s+60))" if seed % 2 else None
    g = Plant.from_string(f"{k}*(s+{z})/((s+{p1})*(s+{p2}))")
    if sensor:
        g = g.series(Plant.from_string(sensor))
    delay = float(rng.uniform(0.005, 0.03))
    return Plant(g.num, g.den, delay), sensor, rng, {"k": k, "z": z, "p1": p1, "p2": p2, "delay": delay}


@pytest.mark.parametrize("seed, periodic, weighted", [(1, False, True), (2, True, False)])
def test_convolution_and_ipopt_reach_the_same_fit(seed, periodic, weighted):
    plant, sensor, rng, truth = _case(seed)
    n = 1000 if periodic else 2000
    t = np.arange(n) * DT
    if periodic:  # one period of a square wave, its periodic response (from many periods)
        u = np.where(t < n * DT / 2, 1.0, 0.0)
        y = simulate_plant(plant, np.arange(5 * n) * DT, np.tile(u, 5))[-n:]
    else:  # random telegraph from rest
        u = np.where(rng.random(n // 200 + 1) < 0.5, 0.0, 1.0)[(np.arange(n) // 200)]
        u[:100] = 0.0
        y = simulate_plant(plant, t, u)
    y = y + 0.01 * np.max(np.abs(y)) * rng.normal(size=n) + 2.0
    weights = (t >= 2.0).astype(float) if weighted else None
    rec = record_from_arrays(t, u, y)
    a, b = (fit_structure(rec, "k*(s+z)/((s+p1)*(s+p2))", "fit", sensor, periodic, weights=weights, solver=s)
            for s in ("ipopt", "convolution"))
    assert a.solver["success"] and b.solver["success"] and "Levenberg" in b.solver["method"]
    for name in a.parameters:
        assert abs(a.parameters[name] - b.parameters[name]) < 1e-3 * a.std[name], name
        assert abs(b.std[name] / a.std[name] - 1) < 1e-4, name
        assert abs(b.parameters[name] - truth[name]) < 5 * b.std[name], name
    assert abs(a.offset - b.offset) < 1e-3 * a.offset_std
    assert np.max(np.abs(a.yhat - b.yhat)) < 1e-3 * a.residual_std


def test_a_fit_started_where_an_earlier_one_was_reuses_its_build_and_its_answer():
    """The symbolic build is kept by structure, sensor, dt, start and delay mode: a re-fit started at the same
    coefficients (every grid point of a gap re-fit) reuses it, a different start or sensor builds its own, and the
    fit is the same either way."""
    from synth.ident.convolution_problem import ConvolutionProblem
    from synth.ident.structure import parse_structure

    st = parse_structure("k*(s+z)/((s+p1)*(s+p2))")
    theta = np.array([2.0, 3.0, 1.0, 9.0])
    sensor = Plant.from_string("2400/((s+40)*(s+60))")
    n = 400
    y = np.zeros(n)

    def make(th, sen=None, fit_delay=True):
        return ConvolutionProblem(st, sen, n, DT, False, th, fit_delay, y, False)

    first = make(theta)
    assert make(theta.copy())._mats is first._mats
    assert make(theta * (1 + 1e-12))._mats is not first._mats
    assert make(theta, sensor)._mats is not first._mats
    assert make(theta, fit_delay=False)._mats is not first._mats
    assert make(theta, fit_delay=False).q == 4 and first.q == 5

    plant, _, rng, truth = _case(2)  # no sensor
    t = np.arange(1500) * DT
    u = np.where(rng.random(9) < 0.5, 0.0, 1.0)[(np.arange(1500) // 200)]
    rec = record_from_arrays(t, u, simulate_plant(plant, t, u) + 0.01 * rng.normal(size=t.size))
    init = {k: truth[k] * 1.1 for k in ("k", "z", "p1", "p2")}
    fits = [fit_structure(rec, "k*(s+z)/((s+p1)*(s+p2))", delay="fit", initial={**init, "delay": 0.01},
                          solver="convolution") for _ in range(2)]
    assert fits[0].parameters == fits[1].parameters and fits[0].delay == fits[1].delay
    assert abs(fits[0].parameters["p1"] - truth["p1"]) < 0.1 * truth["p1"]
