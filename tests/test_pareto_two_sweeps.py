"""Pareto fronts of two-parameter sweeps (issue 19, item 4): against a brute-force filter, drawn and listed."""

from __future__ import annotations

import csv
import io
import itertools

import numpy as np
import pytest

from synth.report.tradeoff_report import tradeoff_csv, write_tradeoff_report
from synth.spec import load_spec
from synth.synthesis.tradeoff import Sweep, TradeoffPoint, mark_pareto, tradeoff

TOL = 1e-6


def brute_force_front(points, paths, signs, sense):
    """The non-dominated feasible points, one pair at a time, written independently of synth."""
    feasible = [p for p in points if p.feasible and p.objective is not None]
    scale = max([abs(p.objective) for p in feasible] + [0.0]) or 1.0
    tol = TOL * scale
    ys = 1.0 if sense == "maximize" else -1.0
    front = set()
    for p in feasible:
        dominated = False
        for q in feasible:
            at_least_as_strict = all(s * q.values[k] >= s * p.values[k] for k, s in zip(paths, signs))
            at_least_as_good = ys * q.objective >= ys * p.objective - tol
            stricter = any(s * q.values[k] > s * p.values[k] for k, s in zip(paths, signs))
            better = ys * q.objective > ys * p.objective + tol
            if at_least_as_strict and at_least_as_good and (stricter or better):
                dominated = True
                break
        if not dominated:
            front.add(id(p))
    return front


def _random_points(rng, n, paths):
    points = []
    for _ in range(n):
        values = {k: float(rng.integers(0, 6)) for k in paths}  # a coarse grid: many ties on the demands
        feasible = bool(rng.random() > 0.2)
        objective = float(rng.integers(0, 8) + (rng.random() * 1e-8 if rng.random() < 0.3 else 0.0))  # ties + noise
        points.append(TradeoffPoint(values, feasible, objective if feasible else None, None, [], {}, "", 0.0))
    return points


@pytest.mark.parametrize("seed", range(60))
def test_front_matches_brute_force_on_random_sets(seed):
    rng = np.random.default_rng(seed)
    paths = ["requirements.a.min", "requirements.b.max_db"]
    points = _random_points(rng, int(rng.integers(1, 40)), paths)
    signs = [int(rng.choice([-1, 1])), int(rng.choice([-1, 1]))]
    sense = str(rng.choice(["maximize", "minimize"]))
    mark_pareto(points, [Sweep(paths[0], []), Sweep(paths[1], [])], sense, signs)
    expected = brute_force_front(points, paths, signs, sense)
    assert {id(p) for p in points if p.pareto} == expected
    if any(p.feasible for p in points):
        assert expected  # a finite non-empty set always has a non-dominated point


def test_one_sweep_unchanged_by_the_int_direction():
    rng = np.random.default_rng(7)
    for _ in range(20):
        points = _random_points(rng, 25, ["x"])
        for sign in (-1, 1):
            mark_pareto(points, [Sweep("x", [])], "maximize", sign)
            assert {id(p) for p in points if p.pareto} == brute_force_front(points, ["x"], [sign], "maximize")


def test_directions_come_from_the_requirement_classes():
    """Same points, opposite directions: the front moves to the other corner."""
    pts = [TradeoffPoint({"a": a, "b": b}, True, 1.0, None, [], {}, "", 0.0) for a, b in itertools.product((1, 2), (1, 2))]
    sweeps = [Sweep("a", [1, 2]), Sweep("b", [1, 2])]
    mark_pareto(pts, sweeps, "maximize", (+1, -1))
    assert [(p.values["a"], p.values["b"]) for p in pts if p.pareto] == [(2, 1)]
    mark_pareto(pts, sweeps, "minimize", (-1, +1))
    assert [(p.values["a"], p.values["b"]) for p in pts if p.pareto] == [(1, 2)]


@pytest.fixture(scope="module")
def x4_map():
    sweeps = [Sweep.parse("requirements.bandwidth.min=60:100:3"), Sweep.parse("requirements.slew_rate.max_error=2:8:3")]
    return tradeoff(load_spec("specs/x4_rotor.yaml"), sweeps, workers=1)


def test_x4_two_sweeps_front(x4_map):
    r = x4_map
    paths = [s.path for s in r.sweeps]
    # larger bandwidth floor and larger largest error are both stricter (the requirement classes say so)
    assert r.extras["stricter_when"] == {paths[0]: 1, paths[1]: 1}
    front = [(p.values[paths[0]], p.values[paths[1]], round(p.objective, 2)) for p in r.points if p.pareto]
    assert front == [(100.0, 5.0, 473.28), (100.0, 8.0, 301.18)]
    assert {id(p) for p in r.points if p.pareto} == brute_force_front(r.points, paths, [1, 1], "maximize")


def test_x4_two_sweeps_drawn_and_listed(x4_map, tmp_path):
    rows = list(csv.DictReader(io.StringIO(tradeoff_csv(x4_map))))
    assert [(r["requirements.bandwidth.min"], r["requirements.slew_rate.max_error"]) for r in rows
            if r["pareto"] == "True"] == [("100", "5"), ("100", "8")]
    files = write_tradeoff_report(x4_map, tmp_path / "t")
    html = files.html.read_text()
    assert ("Pareto front: requirements.bandwidth.min = 100, requirements.slew_rate.max_error = 5 &rarr; 473.3; "
            "requirements.bandwidth.min = 100, requirements.slew_rate.max_error = 8 &rarr; 301.2.") in html
    assert files.png.stat().st_size > 10_000


def test_two_sweeps_without_a_direction_still_design():
    sweeps = [Sweep.parse("requirements.bandwidth.min=60:60:1"), Sweep.parse("simulation.horizon=1:2:2")]
    r = tradeoff(load_spec("specs/x4_rotor.yaml"), sweeps, workers=1)
    assert all(p.feasible for p in r.points) and not any(p.pareto for p in r.points)
    assert r.extras["pareto_note"].startswith("no Pareto front: a swept value has no known direction")
    sweeps = [Sweep.parse("requirements.bandwidth.min=60:60:1"), Sweep.parse("controller.bounds.kp.1=20:20:1")]
    r = tradeoff(load_spec("specs/x4_rotor.yaml"), sweeps, workers=1)
    assert r.extras["stricter_when"] == {"requirements.bandwidth.min": 1, "controller.bounds.kp.1": -1}
