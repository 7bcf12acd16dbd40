"""The screen's exact bandwidths: ``batch_bandwidths`` (every loop at once) against ``Loop.bandwidth`` loop by
loop (the baseline, what the screen ran before), on random plants and controllers: CPU time and agreement.

Plants of order 1-4 (unstable poles, integrators, lightly damped pairs, biproper in a fifth, delays in half),
P, PI, PID and lead-lag controllers with parameters drawn over five decades, 50-400 controllers per plant.

Run:  python benchmarks/batch_bandwidth_speed.py [--plants 40] [--seed 0]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from synth.batch_bandwidth import batch_bandwidths
from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant

KINDS = ("P", "PI", "PID", "leadlag")


def random_plant(rng: np.random.Generator) -> Plant:
    """A plant of order 1-4: a pole in the right half-plane in 15 % of draws, an integrator in a fifth, a pair of
    damping 0.01-0.5 in 30 % of those of order 2 and up, biproper in a fifth, a delay of 1-300 ms in half."""
    order = int(rng.integers(1, 5))
    poles = -(10 ** rng.uniform(-1.5, 2, order)) * np.where(rng.random(order) < 0.15, -1, 1)
    if rng.random() < 0.2:
        poles[0] = 0.0
    den = np.real(np.poly(poles))
    if order >= 2 and rng.random() < 0.3:
        wn, zeta = 10 ** rng.uniform(-0.5, 2), 10 ** rng.uniform(-2, -0.3)
        den = np.polymul(np.real(np.poly(poles[:-2])), [1.0, 2 * zeta * wn, wn * wn])
    zeros = int(rng.integers(0, order + 1 if rng.random() < 0.2 else order))
    num = 10 ** rng.uniform(-1, 2) * np.real(np.poly(-(10 ** rng.uniform(-1, 2, zeros))
                                                      * np.where(rng.random(zeros) < 0.2, -1, 1)))
    return Plant(num, den, delay=0.0 if rng.random() < 0.5 else 10 ** rng.uniform(-3, -0.5))


def random_controller(rng: np.random.Generator, kind: str) -> Controller:
    """A controller of ``kind`` with every parameter drawn log-uniformly (a PI without integral action in 10 %)."""
    def g(lo: float, hi: float) -> float:
        return float(10 ** rng.uniform(lo, hi))

    if kind == "P":
        return Controller("P", {"kp": g(-3, 2)})
    if kind == "PI":
        return Controller("PI", {"kp": g(-3, 2), "ki": g(-3, 2) * float(rng.random() > 0.1)})
    if kind == "PID":
        return Controller("PID", {"kp": g(-3, 2), "ki": g(-3, 2), "kd": g(-4, 1), "tf": g(-4, -1)})
    return Controller("leadlag", {"k": g(-3, 2), "z": g(-1, 3), "p": g(-1, 3)})


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plants", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    loops = exact = 0
    worst = 0.0
    cpu_batch = cpu_loop = 0.0
    for _ in range(args.plants):
        plant = random_plant(rng)
        kind = str(rng.choice(KINDS))
        controllers = [random_controller(rng, kind) for _ in range(int(rng.integers(50, 400)))]
        with np.errstate(all="ignore"):
            t = time.process_time()
            batch = batch_bandwidths(LoopBatch(plant, controllers))
            cpu_batch += time.process_time() - t
            t = time.process_time()
            own = np.array([Loop(plant, c).bandwidth() for c in controllers])
            cpu_loop += time.process_time() - t
            same = (batch == own) | (np.isnan(batch) & np.isnan(own))
            both = np.isfinite(batch) & np.isfinite(own)
            rel = np.where(both, np.abs(batch - own) / np.where(both, np.abs(own), 1.0), 0.0)
        if np.any(~same & ~both):
            raise SystemExit(f"disagreement beyond rounding on {plant} ({kind})")
        loops += len(controllers)
        exact += int(np.sum(same))
        worst = max(worst, float(np.max(rel)))
    print(f"{args.plants} plants, {loops} loops (seed {args.seed})\n")
    print("| | Loop.bandwidth loop by loop (baseline) | batch_bandwidths |")
    print("|---|---|---|")
    print(f"| CPU [s] | {cpu_loop:.2f} | {cpu_batch:.2f} ({cpu_loop / cpu_batch:.1f}x less) |")
    print(f"| bit-identical to the baseline | - | {exact} of {loops} ({100 * exact / loops:.2f} %) |")
    print(f"| largest relative difference | - | {worst:.2g} |")


if __name__ == "__main__":
    main()
