"""Delayed linear step responses: a delay's length at a time (``synth.delayed_blocks``) against the loop stepped
one sample at a time in numpy (the baseline, what ran before) and compiled with numba, in the same run.

Random stable loops (P, PI, PID, lead-lag on plants of order 1-3 behind 1-300 ms of delay), each simulated
over ``synth.timeresp``'s own horizon and step; the table gives the median and largest time per response and
the largest difference from the stepped loop (relative to the response's peak).

Run:  python benchmarks/delayed_step_speed.py [--n 60]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from synth.controllers import Controller
from synth.delayed_blocks import delayed_loop_in_blocks
from synth.loop import Loop
from synth.plant import Plant
from synth.timeresp import BLOCK_FROM, default_horizon, delayed_loop_stepped, discrete_loop


def _loop(rng: np.random.Generator) -> Loop | None:
    poles = -rng.uniform(0.3, 20.0, int(rng.integers(1, 4)))
    gain = float(np.prod(-poles) * rng.uniform(0.5, 3.0))
    plant = Plant(np.array([gain]), np.poly(poles), delay=float(rng.uniform(0.001, 0.3)))
    kind = ["P", "PI", "PID", "leadlag"][int(rng.integers(0, 4))]
    kp = float(rng.uniform(0.1, 1.0))
    params = {"P": {"kp": kp}, "PI": {"kp": kp, "ki": float(rng.uniform(0.05, 1.0))},
              "PID": {"kp": kp, "ki": float(rng.uniform(0.05, 1.0)), "kd": float(rng.uniform(0, 0.1)), "tf": 0.02},
              "leadlag": {"k": kp, "z": float(rng.uniform(0.5, 5)), "p": float(rng.uniform(5, 50))}}[kind]
    loop = Loop(plant, Controller(kind, params))
    return loop if loop.stability().stable else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=60)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    cases: list[tuple] = []  # each loop as synth.timeresp simulates it: the kernels' arguments
    while len(cases) < args.n:
        loop = _loop(rng)
        if loop is not None:
            kernel_args = discrete_loop(loop, default_horizon(loop))[0]
            if kernel_args[-2] >= BLOCK_FROM and kernel_args[-1] <= 200_000:
                cases.append(kernel_args)
    t = time.perf_counter()
    from synth.delayed_step import delayed_loop  # numba's import is part of its first call

    delayed_loop(*cases[0])  # numba: import it and load the compiled loop once, outside the per-response timing
    first_numba = time.perf_counter() - t
    times: dict[str, list[float]] = {"stepped in numpy (baseline)": [], "numba": [], "blocks": []}
    worst = 0.0
    for a in cases:
        outs = {}
        for name, fn in zip(times, (delayed_loop_stepped, delayed_loop, delayed_loop_in_blocks)):
            t = time.perf_counter()
            outs[name] = np.asarray(fn(*a))
            times[name].append(time.perf_counter() - t)
        ref = outs["stepped in numpy (baseline)"]
        worst = max(worst, float(np.max(np.abs(outs["blocks"] - ref)) / max(1.0, np.max(np.abs(ref)))))
    steps = [a[-1] for a in cases]
    delays = [a[-2] for a in cases]
    print(f"{len(cases)} loops; steps per response median {statistics.median(steps):.0f} (max {max(steps)}), "
          f"delay in steps median {statistics.median(delays):.0f} (min {min(delays)}, max {max(delays)})\n")
    print("| kernel | median ms per response | max ms |")
    print("|---|---|---|")
    for name, ts in times.items():
        print(f"| {name} | {1e3 * statistics.median(ts):.1f} | {1e3 * max(ts):.1f} |")
    print(f"\nnumba's first call in the process (import, loading the cached compiled loop): {first_numba:.2f} s")
    print(f"largest |blocks - stepped| / peak: {worst:.1e}")


if __name__ == "__main__":
    main()
