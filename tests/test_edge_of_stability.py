"""The distance of a loop from -1 (synth.edge) against a brute-force reference on random loops, and the warning
a feasible design carries when its requirements let it pass near -1."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from synth import Controller, Plant, load_spec
from synth.design import design
from synth.edge import NEAR_EDGE, edge_distance


def _random_loop(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float]:
    """Numerator, denominator and delay of a random strictly proper loop transfer function C G."""
    order = int(rng.integers(1, 5))
    den = np.array([1.0])
    for _ in range(order):
        if rng.random() < 0.3 and order >= 2:
            wn, zeta = 10 ** rng.uniform(-1, 2), 10 ** rng.uniform(-1.7, 0)
            den = np.polymul(den, [1.0, 2 * zeta * wn, wn * wn])
        else:
            den = np.polymul(den, [1.0, 10 ** rng.uniform(-1.5, 2)])
    num = np.array([1.0]) if rng.random() < 0.6 else np.array([1.0, 10 ** rng.uniform(-1, 2)])
    if num.size >= den.size:
        num = np.array([1.0])
    gain = 10 ** rng.uniform(-1, 1) * abs(np.polyval(den, 1j * 10 ** rng.uniform(-1, 1))
                                          / np.polyval(num, 1j * 10 ** rng.uniform(-1, 1)))
    delay = 0.0 if rng.random() < 0.5 else 10 ** rng.uniform(-3, -0.5)
    return gain * num, den, float(delay)


def _brute_force_distance(num: np.ndarray, den: np.ndarray, delay: float) -> float:
    """min |1 + L(jw)| on 400,000 log-spaced points over [1e-4, 1e5] rad/s, each local minimum polished."""
    def dist(w: np.ndarray | float) -> np.ndarray:
        s = 1j * np.asarray(w, dtype=float)
        return np.abs(1.0 + np.polyval(num, s) / np.polyval(den, s) * np.exp(-s * delay))

    w = np.logspace(-4, 5, 400_000)
    d = dist(w)
    best = float(min(d.min(), dist(0.0)))
    local = np.flatnonzero((d[1:-1] <= d[:-2]) & (d[1:-1] <= d[2:])) + 1
    for i in local[np.argsort(d[local])[:10]]:
        r = minimize_scalar(lambda x: float(dist(np.exp(x))), bounds=(np.log(w[i - 1]), np.log(w[i + 1])),
                            method="bounded", options={"xatol": 1e-12})
        best = min(best, float(r.fun))
    return best


@pytest.mark.parametrize("seed", range(40))
def test_distance_from_minus_one_matches_a_brute_force_search(seed: int) -> None:
    rng = np.random.default_rng(seed)
    num, den, delay = _random_loop(rng)
    plant = Plant(num, den, delay=delay)
    got = edge_distance([plant], Controller("P", {"kp": 1.0}))
    want = _brute_force_distance(num, den, delay)
    assert got.distance == pytest.approx(want, rel=1e-4, abs=1e-9)
    assert got.near == (want < NEAR_EDGE)


def test_the_worst_plant_is_named() -> None:
    far = Plant.from_string("1/(s+1)", label="far")
    close = Plant.from_string("1/(s*(s+1)*(s+2))", label="close")
    e = edge_distance([far, close], Controller("P", {"kp": 5.9}))
    assert e.plant == "close" and e.distance == pytest.approx(0.0071645, rel=1e-4)
    assert e.frequency == pytest.approx(1.40453, rel=1e-4)


def test_a_root_on_the_axis_is_distance_zero() -> None:
    # 1 + 6/(s(s+1)(s+2)) has roots at +-j sqrt(2): L passes through -1
    e = edge_distance([Plant.from_string("6/(s*(s+1)*(s+2))")], Controller("P", {"kp": 1.0}))
    assert e.distance < 1e-6 and e.near


def _write_spec(tmp_path, controller: dict, requirements: list[dict]) -> str:
    import yaml

    path = tmp_path / "edge.yaml"
    path.write_text(yaml.safe_dump({"name": "edge", "plant": {"tf": "1/(s*(s+1)*(s+2))"}, "controller": controller,
                                    "requirements": requirements, "objective": {"maximize": "bandwidth"}}))
    return str(path)


def test_a_design_at_the_edge_says_so_in_the_verdict_and_the_json(tmp_path) -> None:
    spec = load_spec(_write_spec(tmp_path, {"type": "P", "bounds": {"kp": [0.1, 5.9]}},
                                 [{"type": "bandwidth", "min": 0.1}]))
    result = design(spec)
    assert result.feasible and result.controller.parameters["kp"] == pytest.approx(5.9)
    assert "near the edge of stability" in result.verdict and "0.00716 of -1" in result.verdict
    edge = json.loads(json.dumps(result.to_dict()))["edge_of_stability"]
    assert edge["near"] is True and edge["distance"] == pytest.approx(0.0071645, rel=1e-4)


def test_a_design_kept_off_the_edge_carries_no_warning(tmp_path) -> None:
    spec = load_spec(_write_spec(tmp_path, {"type": "P", "bounds": {"kp": [0.1, 5.9]}},
                                 [{"type": "bandwidth", "min": 0.1},
                                  {"type": "margins", "gain_margin_db": 6, "phase_margin_deg": 30}]))
    result = design(spec)
    assert result.feasible and "edge of stability" not in result.verdict
    edge = result.to_dict()["edge_of_stability"]
    assert edge["near"] is False and edge["distance"] >= 0.25  # kp <= 3: L crosses the real axis at -1/2 or right
