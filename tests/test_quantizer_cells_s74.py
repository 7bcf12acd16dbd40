"""The quantizer search's points: distinct cells, each at its largest-margin point.

For a fixed linear model the fit of a command quantizer depends on its ``(step, offset)`` only through the cell:
which lattice index each command value rounds to. The dense search (``QuantizationEffect.screen_grid``) returns
its best few cells, each as the point of the cell farthest from every rounding boundary. Checked here on seeded
random records (smooth commands, step trains, random walks) against a linear program written for this test:
for the rounding pattern of each returned point, maximize the margin ``m`` (in steps) over ``a = 1/step`` and
``b = offset/step`` with ``n_i - 1/2 + m <= a u_i - b <= n_i + 1/2 - m``.

Before session 74 the program was solved for every searched point and two points of one cell could come back
with answers a few ulps apart, so the search returned the same cell twice (seeds 12 and 25 below: 4 distinct
cells of 5).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from synth.gap.effects import QuantizationEffect
from synth.plant import Plant

SEEDS = [1, 2, 4, 7, 12, 25]


def _problem(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, Plant]:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(400, 3000))
    t = np.arange(n) * 0.01
    kind = seed % 3
    if kind == 0:
        u = 1.0 + 0.8 * np.sin(rng.uniform(0.5, 4) * t) * np.sin(rng.uniform(0.1, 0.5) * t)
    elif kind == 1:
        u = np.repeat(rng.uniform(-3, 5, n // 100 + 1), 100)[:n]
    else:
        u = np.cumsum(rng.standard_normal(n)) * 0.1
    tau = rng.uniform(0.05, 0.5)
    plant = Plant.from_string(f"{rng.uniform(0.5, 3):.4f}/({tau:.4f}*s+1)")
    q = rng.uniform(0.01, 0.2) * np.ptp(u)
    y = QuantizationEffect().apply(plant, t, u, {"step": q, "offset": rng.uniform(0, q)})
    y = y + rng.normal(0, rng.choice([0, 1e-3, 1e-2]) * np.std(y), n)
    return t, u, y, plant


def _indices(levels: np.ndarray, point: dict[str, float]) -> np.ndarray:
    return np.floor((levels - point["offset"]) / point["step"] + 0.5)


def _margin(levels: np.ndarray, point: dict[str, float]) -> float:
    """Distance in steps from the nearest rounding boundary."""
    x = (levels - point["offset"]) / point["step"]
    return float(np.min(0.5 - np.abs(x - np.floor(x + 0.5))))


def _best_margin(levels: np.ndarray, n: np.ndarray) -> float:
    ones = np.ones_like(levels)
    a_ub = np.vstack([np.column_stack([-levels, ones, ones]), np.column_stack([levels, -ones, ones])])
    res = linprog([0.0, 0.0, -1.0], A_ub=a_ub, b_ub=np.concatenate([0.5 - n, n + 0.5]),
                  bounds=[(1e-9, None), (None, None), (0.0, 0.5)], method="highs")
    assert res.success
    return float(res.x[2])


@pytest.mark.parametrize("seed", SEEDS)
def test_the_points_are_distinct_cells_at_their_largest_margin(seed: int) -> None:
    t, u, y, plant = _problem(seed)
    points = QuantizationEffect().screen_grid(t, u, y, plant)
    levels = np.unique(u)
    patterns = [_indices(levels, p) for p in points]
    assert len(points) == 5
    for i in range(len(points)):
        for j in range(i):  # a whole shift of every index is the same cell (the lattice relabelled)
            assert np.ptp(patterns[i] - patterns[j]) > 0, (i, j, points[i], points[j])
    for p, n in zip(points, patterns):
        assert _margin(levels, p) == pytest.approx(_best_margin(levels, n), abs=1e-6)
