"""The delayed Nyquist count does not step over a lightly damped pair.

Seed 12's problem #53: a resonant controller (poles at 0.1 rad/s, damping 0.074) on a lightly damped plant
with 20 ms of delay. The count sampled the axis at 0, 0.67 and 1.35 rad/s only (a segment starting at 0 had no
logarithmic points), saw no step worth refining, and called the loop stable; its closed-loop roots are at
0.661 +- 0.763j (Newton on the quasi-polynomial; a 10th-order Pade model agrees). The reference here is a brute
force: the winding of 1 + L on 400,000 logarithmic and linear points, written apart from synth/stability.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.stability import closed_loop_stability


def _brute_unstable_count(num: np.ndarray, den: np.ndarray, delay: float) -> tuple[int, float]:
    w = np.unique(np.concatenate([[0.0], np.geomspace(1e-5, 1e4, 300_000), np.linspace(0.0, 1e3, 100_000)]))
    s = 1j * w
    f = 1.0 + np.polyval(num, s) / np.polyval(den, s) * np.exp(-delay * s)
    half = float(np.sum(np.angle(f[1:] / f[:-1]))) - float(np.angle(f[-1]))  # tail: f -> 1 (strictly proper)
    p_rhp = int(np.sum(np.roots(den).real > 0))
    return round(-2 * half / (2 * np.pi)) + p_rhp, float(np.min(np.abs(f)))


def test_seed_12_problem_53_is_unstable() -> None:
    plant_num = 0.0461366 * np.array([1, 1.9123])
    plant_den = np.polymul(np.polymul([1, 0.0373154, 0.114002], [1, 1.4439]), [1, 0.326127])
    cn = np.array([0.1865318540899738, 23.99063913043579, 0.05314613576854376])
    cd = np.array([1, 0.014811469065340536, 0.009997103818898475])
    num, den = np.polymul(plant_num, cn), np.polymul(plant_den, cd)
    st = closed_loop_stability(num, den, 0.0198529)
    assert not st.stable and st.unstable_poles == 2
    assert _brute_unstable_count(num, den, 0.0198529)[0] == 2


@pytest.mark.parametrize("seed", range(120))  # the count before the fix failed 3 of these (46, 77, 113)
def test_random_lightly_damped_loops_match_the_brute_force_count(seed: int) -> None:
    # the trap: no pole on the axis (the count starts at w = 0), a short delay (few linear samples) and lightly
    # damped pairs well below the crossover, where |L| is large and 1 + L may wind round the origin
    rng = np.random.default_rng([2112, seed])
    den = np.array([1.0])
    for _ in range(int(rng.integers(1, 3))):
        wn, zeta = 10 ** rng.uniform(-1.5, -0.3), 10 ** rng.uniform(-2.5, -1.0)
        den = np.polymul(den, [1.0, 2 * zeta * wn, wn * wn])
    for _ in range(int(rng.integers(0, 3))):
        den = np.polymul(den, [1.0, 10 ** rng.uniform(-1.0, 1.0) * (1 if rng.random() < 0.85 else -1)])
    num = np.array([1.0])
    for _ in range(int(rng.integers(0, den.size - 2))):
        num = np.polymul(num, [1.0, 10 ** rng.uniform(-1.0, 1.0)])
    wc = 10 ** rng.uniform(-0.2, 0.5)  # |L| = 1 to 3 there
    num = num * 10 ** rng.uniform(0.0, 0.5) / abs(np.polyval(num, 1j * wc) / np.polyval(den, 1j * wc))
    delay = float(10 ** rng.uniform(-3.0, -1.0))
    count, closest = _brute_unstable_count(num, den, delay)
    if closest < 1e-3:  # a root next to the axis: neither count is meaningful
        pytest.skip(f"|1 + L| comes within {closest:.1e} of 0")
    st = closed_loop_stability(num, den, delay)
    assert st.stable == (count == 0) and st.unstable_poles == count, (num, den, delay)
