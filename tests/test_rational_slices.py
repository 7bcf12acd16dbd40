"""Exact stabilizing starts of rational controllers (synth.synthesis.rational_slices) and the convex stage scaled at
the bandwidth floor (synth.synthesis.rational_rescale), checked against closed-loop roots computed here."""

from __future__ import annotations

import numpy as np
import pytest

from synth.plant import Plant
from synth.spec import parse_spec
from synth.synthesis.convex_settings import ConvexSettings
from synth.synthesis.parametrization import parametrize
from synth.synthesis.rational_rescale import bandwidth_floor, rescaled_run
from synth.synthesis.rational_slices import rational_slices


def _random_problem(rng: np.random.Generator) -> tuple[Plant, tuple[int, int], dict[str, tuple[float, float]], float]:
    """A delay-free plant of order 1-3 with an unstable pole in half the draws, a right-half-plane zero in a
    third, and a rational order with coefficient bounds over several decades."""
    order = int(rng.integers(1, 4))
    poles = -(10 ** rng.uniform(-1, 1.5, order))
    if rng.random() < 0.5:
        poles[0] = -poles[0]
    zeros = np.array([10 ** rng.uniform(-0.5, 1.5)]) if order > 1 and rng.random() < 1 / 3 else np.zeros(0)
    gain = float(10 ** rng.uniform(-0.5, 1.5))
    num = gain * (np.poly(zeros) if zeros.size else np.ones(1))
    plant = Plant(num, np.poly(poles))
    m, n = int(rng.integers(0, 3)), int(rng.integers(1, 4))
    m = min(m, n)
    w0 = float(np.sqrt(np.prod(np.abs(poles))) ** (1 / max(order, 1)))
    scale = 10 ** rng.uniform(2, 4)
    bounds = {f"b{i}": (-scale * w0 ** (n - i), scale * w0 ** (n - i)) for i in range(m + 1)}
    bounds |= {f"a{i}": (0.0, scale * w0 ** (n - i)) for i in range(n)}
    return plant, (m, n), bounds, w0


def _closed_loop_roots(plant: Plant, num: np.ndarray, den: np.ndarray) -> np.ndarray:
    return np.roots(np.polyadd(np.polymul(plant.num, num), np.polymul(plant.den, den)))


def test_every_slice_stabilizes_and_stays_in_bounds_on_random_plants():
    rng = np.random.default_rng(40)
    unstable_with_starts = 0
    for _ in range(30):
        plant, (m, n), bounds, w0 = _random_problem(rng)
        par = parametrize("rational", bounds, order=(m, n), w0=w0)
        starts = list(rational_slices(par, [plant], draws=12))
        if np.all(np.roots(plant.den).real < 0):  # a small enough gain around stable poles is stabilizing
            assert starts, plant
        else:
            unstable_with_starts += bool(starts)
        for rho in starts:
            c = par.controller(rho)
            for name, value in c.parameters.items():
                lo, hi = bounds[name]
                assert lo - 1e-9 * abs(lo) <= value <= hi + 1e-9 * abs(hi), (name, value, bounds[name])
            b = np.array([c.parameters[f"b{i}"] for i in range(m, -1, -1)])
            a = np.concatenate([[1.0], [c.parameters[f"a{i}"] for i in range(n - 1, -1, -1)]])
            roots = _closed_loop_roots(plant, b, a)
            assert np.all(roots.real < 0), (plant, c, roots)
    assert unstable_with_starts >= 4  # 5 of the 16 unstable plants here (not every one can be, at these orders)


def test_slices_honour_an_integrator_fixed_by_the_bounds():
    bounds = {"b0": (-100.0, 100.0), "b1": (-100.0, 100.0), "a0": (0.0, 0.0), "a1": (0.0, 100.0)}
    par = parametrize("rational", bounds, order=(1, 2), w0=1.0)
    plant = Plant.from_string("1/((s+1)*(s+3))")
    starts = list(rational_slices(par, [plant], draws=8))
    assert starts
    for rho in starts:
        assert par.controller(rho).parameters["a0"] == 0.0


def test_bandwidth_floor_reads_the_highest_minimum():
    spec = parse_spec({"name": "x", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "P"},
                       "requirements": [{"type": "bandwidth", "min": 2.0}, {"type": "bandwidth", "min": 5.0},
                                        {"type": "peak_sensitivity", "max_db": 6.0}]})
    assert bandwidth_floor(list(spec.requirements)) == 5.0


SEED23_5 = {
    "name": "rand_23_5",
    "plant": {"tf": "3.66752*1/((s-0.424971))", "delay": 0.0},
    "controller": {"type": "rational", "order": [0, 3],
                   "bounds": {"b0": [-14416.4, 14416.4], "a0": [0.0, 65260.0], "a1": [0.0, 17914.7],
                              "a2": [0.0, 4917.81]}},
    "requirements": [{"type": "sensitivity_static", "max_db": -19.7313},
                     {"type": "peak_complementary", "max_db": 4.65162},
                     {"type": "bandwidth", "min": 3.62588}],
    "objective": {"minimize": "peak_sensitivity"},
}


@pytest.mark.slow
def test_rescaled_run_finds_the_feasible_corner_of_seed23_problem5():
    """The design benchmark's seed 23 #5: an unstable plant whose feasible rational controllers sit at b0's bound
    with poles near 10-30 rad/s, two decades above the plant's 0.42 rad/s. The run scaled at the bandwidth floor
    reaches every requirement; the result is checked here on the closed-loop roots and the DC gain."""
    spec = parse_spec(SEED23_5)
    rescaled = rescaled_run(spec, ConvexSettings(), ["s0", "t", "bw"], ("peak_sensitivity", "minimize"))
    assert rescaled is not None
    _, result = rescaled
    assert result.status == "optimal", result.note
    assert "bandwidth floor 3.626 rad/s" in result.note
    c = result.controller.parameters
    plant = spec.plants()[0]
    roots = _closed_loop_roots(plant, np.array([c["b0"]]), np.array([1.0, c["a2"], c["a1"], c["a0"]]))
    assert np.all(roots.real < 0)
    dc_loop = 3.66752 / -0.424971 * c["b0"] / c["a0"]
    assert 20 * np.log10(abs(1 / (1 + dc_loop))) <= -19.7313 + 1e-3
