"""A batch's gain-margin factors behind a delay against each loop's own search, on random batches.

:meth:`synth.loop_batch.LoopBatch.gain_margin_factors` (the margins requirement on a screen or a feasibility map)
is compared value by value with :func:`synth.stability_sets.gain_margin_factors` run on each loop alone (the
D-decomposition's boundaries by another route). Random batches: plants of order 1-3 with a lightly damped pair in
about a third, delays of 1 ms to 2 s; P, PI or PID (a fixed 10 ms derivative filter) over five decades of gain;
5-60 loops a batch. Prints the loops compared and those that differ, apart for closed-loop stable loops (where the
margins mean something) and unstable ones (where the requirement reports the instability instead, and the factors
near 1 are roots of a chain crossing the axis), each stable one listed, and the batch's and the single-loop
searches' times. To compare two versions of synth, run it under each one's ``PYTHONPATH``.

Run:  python benchmarks/batch_gain_margins.py --seed 0 --batches 30
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant


def batch(rng: np.random.Generator, max_loops: int = 60) -> tuple[Plant, list[Controller]]:
    """One random plant behind a delay and a batch of 5 to ``max_loops - 1`` controllers of one type."""
    poles = -np.exp(rng.uniform(np.log(0.05), np.log(50), rng.integers(1, 4)))
    den, k = np.poly(poles), np.exp(rng.uniform(np.log(0.1), np.log(100)))
    if rng.random() < 0.3:  # a lightly damped pair
        wn, zeta = np.exp(rng.uniform(0, 3)), rng.uniform(0.01, 0.3)
        den, k = np.polymul(den, [1, 2 * zeta * wn, wn * wn]), k * wn * wn
    delay = float(np.exp(rng.uniform(np.log(0.001), np.log(2.0))))
    plant = Plant(np.array([k * abs(np.prod(poles))]), den, delay)
    kind = str(rng.choice(["P", "PI", "PID"]))
    controllers = []
    for _ in range(int(rng.integers(5, max_loops))):
        gains = {"kp": float(np.exp(rng.uniform(np.log(1e-3), np.log(50))))}
        if kind != "P":
            gains["ki"] = float(np.exp(rng.uniform(np.log(1e-3), np.log(500 if kind == "PI" else 50))))
        if kind == "PID":
            gains.update(kd=float(np.exp(rng.uniform(np.log(1e-4), np.log(5)))), tf=0.01)
        controllers.append(Controller(kind, gains))
    return plant, controllers


def same(a: float, b: float) -> bool:
    """Equal to 1e-8 relative, or both infinite."""
    return (np.isinf(a) and np.isinf(b)) or bool(np.isclose(a, b, rtol=1e-8, atol=1e-12))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--batches", type=int, default=30)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    loops = differ = stable = stable_differ = 0
    batch_time = single_time = 0.0
    for b in range(args.batches):
        plant, controllers = batch(rng)
        t = time.perf_counter()
        k_lo, k_hi = LoopBatch(plant, controllers).gain_margin_factors()
        batch_time += time.perf_counter() - t
        for i, c in enumerate(controllers):
            t = time.perf_counter()
            own_lo, own_hi = Loop(plant, c).gain_factors[:2]
            single_time += time.perf_counter() - t
            loops += 1
            is_stable = Loop(plant, c).stability().stable
            stable += is_stable
            if not (same(k_lo[i], own_lo) and same(k_hi[i], own_hi)):
                differ += 1
                stable_differ += is_stable
                if is_stable:
                    print(f"batch {b}, {c} behind {plant.delay:.4g} s: batch ({k_lo[i]:.10g}, {k_hi[i]:.10g}), "
                          f"own search ({own_lo:.10g}, {own_hi:.10g})")
    print(f"seed {args.seed}: {loops} loops in {args.batches} batches; closed-loop stable {stable}, of which "
          f"{stable_differ} differ from their own search; unstable {loops - stable}, of which {differ - stable_differ} "
          f"differ; batch {batch_time:.2f} s, single-loop searches {single_time:.2f} s")


if __name__ == "__main__":
    main()
