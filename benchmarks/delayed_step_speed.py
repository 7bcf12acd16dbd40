"""Delayed linear step responses: the augmented system (the delayed inputs as states, 64 samples per matrix
product) and a delay's length at a time (both ``synth.delayed_blocks``) against the loop stepped one sample at
a time in numpy (the baseline, what ran before either) and compiled with numba, in the same run.

Random stable loops (P, PI, PID, lead-lag on plants of order 1-3, poles 0.03-20 rad/s, behind 0.3-300 ms of
delay, log-uniform), each simulated
over ``synth.timeresp``'s own horizon and step (up to 200,000 steps); the table gives the median and largest
time per response, by the delay's length in steps, and the largest difference from the stepped loop
(relative to the response's peak).

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
from synth.delayed_blocks import delayed_loop_augmented, delayed_loop_in_blocks
from synth.loop import Loop
from synth.plant import Plant
from synth.timeresp import AUGMENTED_UP_TO, default_horizon, discrete_loop


def delayed_loop_stepped(Ac, Bc, Cc, Dc, Ap, Bp, Cp, Dp, m: int, steps: int) -> np.ndarray:
    """:func:`synth.delayed_step.delayed_loop` in numpy, step by step (no compilation, nor numba's import).

    Examples
    --------
    >>> e = np.exp(-0.01)  # 1/(s+1) held over 10 ms, a gain of 1, 5 steps of delay: y settles at 1/2
    >>> y = delayed_loop_stepped(np.zeros((0, 0)), np.zeros(0), np.zeros(0), 1.0, np.array([[e]]),
    ...                          np.array([1 - e]), np.array([1.0]), 0.0, 5, 3000)
    >>> round(float(y[-1]), 6)
    0.5
    """
    xc = np.zeros(Ac.shape[0])
    xp = np.zeros(Ap.shape[0])
    buffer = np.zeros(m)  # u[k - m] is read at step k
    y_hist = np.empty(steps + 1)
    for k in range(steps + 1):
        u_delayed = buffer[k % m]
        y = (float(Cp @ xp) if Ap.size else 0.0) + Dp * u_delayed
        y_hist[k] = y
        e = 1.0 - y
        u = (float(Cc @ xc) if Ac.size else 0.0) + Dc * e
        if Ac.size:
            xc = Ac @ xc + Bc * e
        if Ap.size:
            xp = Ap @ xp + Bp * u_delayed
        buffer[k % m] = u
    return y_hist


def _loop(rng: np.random.Generator) -> Loop | None:
    poles = -10.0 ** rng.uniform(-1.5, 1.3, int(rng.integers(1, 4)))
    gain = float(np.prod(-poles) * rng.uniform(0.5, 3.0))
    plant = Plant(np.array([gain]), np.poly(poles), delay=float(10.0 ** rng.uniform(-3.5, -0.5)))
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
            if kernel_args[-1] <= 200_000:
                cases.append(kernel_args)
    t = time.perf_counter()
    from synth.delayed_step import delayed_loop  # numba's import is part of its first call

    delayed_loop(*cases[0])  # numba: import it and load the compiled loop once, outside the per-response timing
    first_numba = time.perf_counter() - t
    kernels = {"stepped in numpy (baseline)": delayed_loop_stepped, "numba": delayed_loop,
               "blocks": delayed_loop_in_blocks, "augmented": delayed_loop_augmented}
    times: dict[str, list[float]] = {name: [] for name in kernels}
    worst = {"blocks": 0.0, "augmented": 0.0}
    for a in cases:
        outs = {}
        for name, fn in kernels.items():
            t = time.perf_counter()
            outs[name] = np.asarray(fn(*a))
            times[name].append(time.perf_counter() - t)
        ref = outs["stepped in numpy (baseline)"]
        for name in worst:
            worst[name] = max(worst[name], float(np.max(np.abs(outs[name] - ref)) / max(1.0, np.max(np.abs(ref)))))
    steps = [a[-1] for a in cases]
    delays = np.array([a[-2] for a in cases])
    print(f"{len(cases)} loops; steps per response median {statistics.median(steps):.0f} (max {max(steps)}), "
          f"delay in steps median {statistics.median(delays):.0f} (min {min(delays)}, max {max(delays)})\n")
    short = delays <= AUGMENTED_UP_TO
    print(f"| kernel | median ms, delay <= {AUGMENTED_UP_TO} steps ({int(short.sum())} loops) | max ms | "
          f"median ms, longer delays ({int((~short).sum())}) | max ms |")
    print("|---|---|---|---|---|")
    for name, ts in times.items():
        cells = []
        for part in (short, ~short):
            chosen = [x for x, keep in zip(ts, part) if keep]
            cells += [f"{1e3 * statistics.median(chosen):.1f}", f"{1e3 * max(chosen):.1f}"] if chosen else ["-", "-"]
        print(f"| {name} | " + " | ".join(cells) + " |")
    print(f"\nnumba's first call in the process (import, loading the cached compiled loop): {first_numba:.2f} s")
    for name, w in worst.items():
        print(f"largest |{name} - stepped| / peak: {w:.1e}")


if __name__ == "__main__":
    main()
