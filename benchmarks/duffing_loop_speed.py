"""The Duffing effect's spring loop (``synth.gap.effects.amplitude.cubic_feedback``) compiled against the same
loop interpreted (numba's ``py_func``, the baseline), on random plants and records: CPU time and agreement.

Plants of order 1-3 (a lightly damped pair in half of those of order 2 and up, a zero in 40 %), delays of 0, 3 or
10 ms, records of 100-20,000 samples of a random walk, hardening and softening springs over four decades.

Run:  python benchmarks/duffing_loop_speed.py [--cases 40] [--seed 0]
"""

from __future__ import annotations

import argparse
import time
from unittest import mock

import numpy as np

from synth.gap.effects import amplitude
from synth.plant import Plant


def random_case(rng: np.random.Generator) -> tuple[Plant, np.ndarray, float, float]:
    """``(plant, command, sample time, cubic)`` with a finite, nonzero static gain."""
    order = int(rng.integers(1, 4))
    den = np.real(np.poly(-(10 ** rng.uniform(-0.5, 2, order))))
    if order >= 2 and rng.random() < 0.5:
        wn, zeta = 10 ** rng.uniform(0, 2), 10 ** rng.uniform(-2, -0.5)
        den = np.polymul(np.real(np.poly(-(10 ** rng.uniform(-0.5, 2, order - 2)))), [1.0, 2 * zeta * wn, wn * wn])
    num = np.array([10 ** rng.uniform(-1, 2) * den[-1] * rng.choice([1.0, -1.0])])
    if rng.random() < 0.4:
        num = np.polymul(num, [1 / 3.0, 1.0])
    plant = Plant(num, den, delay=float(rng.choice([0.0, 0.01, 0.003])))
    u = np.cumsum(rng.normal(size=int(rng.integers(100, 20000)))) * 0.1
    return plant, u, 0.001 * int(rng.integers(1, 10)), float(rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(-3, 1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    amplitude.cubic_feedback(Plant.from_string("1/(s+1)"), np.ones(10), 0.01, 0.1)  # compiled (or loaded) first
    compiled_cpu = interpreted_cpu = 0.0
    same = samples = 0
    for _ in range(args.cases):
        plant, u, dt, cubic = random_case(rng)
        t = time.process_time()
        fast = amplitude.cubic_feedback(plant, u, dt, cubic)
        compiled_cpu += time.process_time() - t
        with mock.patch.object(amplitude, "_spring_inputs", amplitude._spring_inputs.py_func):
            t = time.process_time()
            slow = amplitude.cubic_feedback(plant, u, dt, cubic)
            interpreted_cpu += time.process_time() - t
        same += int(np.array_equal(fast, slow, equal_nan=True))
        samples += u.size
    print(f"{args.cases} random cases, {samples} samples (seed {args.seed})\n")
    print("| | interpreted loop (baseline) | compiled loop |")
    print("|---|---|---|")
    print(f"| CPU [s] | {interpreted_cpu:.2f} | {compiled_cpu:.3f} ({interpreted_cpu / compiled_cpu:.0f}x less) |")
    print(f"| cases with bit-identical inputs | - | {same} of {args.cases} |")


if __name__ == "__main__":
    main()
