"""``synth identify --delay fit`` on random step trains: this checkout beside a baseline, CPU time and answers.

Measures what SRIVC's filter bank costs a user (:mod:`synth.ident.filter_bank`: the deterministic start's
instrumental-variable iterations filter four signals through ``s^k/A(s)`` per iteration, over a grid of delays and
prefilter poles). Each case draws a plant of order 1-3 (real poles 0.5-60 rad/s, a zero in a third of the second-order
ones), a delay of 0-30 ms, and a step train (periodic with period 2-8 s, or aperiodic with holds of 0.5-4 s; random
levels), sampled at 1-4 kHz for 20-80 s, with white output noise of 0.3-3 % of the response's range. Both sides run the
whole command ``synth identify --data case.csv --structure S --delay fit --json -`` in a fresh process, one after
the other on the same record (so both see the same load); the time is the CPU time of the command's process and its
children. Answers are compared as exit code and every parameter to 6 significant digits, and as the largest relative
difference of the parameters.

Run:  python benchmarks/ident_srivc_speed.py [--cases 20] [--baseline-ref main] [--seed 0]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def case(seed: int, folder: Path) -> tuple[Path, str]:
    """Write one record as CSV; its path and the structure to fit (the plant's own)."""
    from scipy import signal

    rng = np.random.default_rng(seed)
    dt = 1.0 / float(rng.choice([1000, 2000, 4000]))
    n = int(rng.uniform(20, 80) / dt)
    t = np.arange(n) * dt
    if rng.random() < 0.5:
        period = rng.uniform(2, 8)
        u = rng.uniform(-5, 5) + rng.uniform(0.2, 5) * (np.floor(t / (period / 2)) % 2)
    else:
        holds = np.cumsum(rng.uniform(0.5, 4, size=int(t[-1] / 0.5) + 2))
        levels = rng.uniform(-5, 5, size=holds.size + 1)
        u = levels[np.searchsorted(holds, t)]
    order = int(rng.integers(1, 4))
    poles = np.sort(10 ** rng.uniform(np.log10(0.5), np.log10(60), size=order))
    zero = order == 2 and rng.random() < 1 / 3
    names = [f"p{i + 1}" for i in range(order)] if order > 1 else ["p"]
    den_text = "*".join(f"(s+{p})" for p in names)
    structure = f"k*(s+z)/({den_text})" if zero else f"k/({den_text})"
    den = np.poly(-poles)
    num = np.poly([-10 ** rng.uniform(-0.3, 1.5)]) if zero else np.array([1.0])
    num = num * rng.uniform(0.5, 3) * den[-1] / num[-1]
    delay = rng.uniform(0, 0.03)
    steps = round(delay / dt)
    b, a, _ = signal.cont2discrete((num, den), dt, method="zoh")
    y0 = signal.lfilter(np.squeeze(b), a, np.r_[np.full(steps, u[0]), u][:n] - u[0])
    y = y0 + rng.uniform(-3, 3) + rng.uniform(0.003, 0.03) * np.ptp(y0) * rng.normal(size=n)
    path = folder / f"case_{seed}.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="time,u,y", comments="", fmt="%.10g")
    return path, structure


def identify(root: Path, path: Path, structure: str, out: str) -> dict:
    """One ``synth identify`` with ``root``'s synth: exit code, CPU seconds, parameters (or the error's start)."""
    env = {**os.environ, "PYTHONPATH": str(root), "SYNTH_IDENTIFY_CACHE": "off", "SYNTH_JOBS": "1"}
    argv = [sys.executable, "-m", "synth", "identify", "--data", str(path), "--structure", structure, "--delay", "fit",
            "--json", "-", "--no-figures", "--out", out, "--force"]
    from benchmarks.cli_speed import timed_run

    _, cpu, proc = timed_run(argv, root, env)
    if proc.returncode == 0:
        answer: dict | str = {k: float(v) for k, v in json.loads(proc.stdout)["parameters"].items()}
    else:
        answer = proc.stderr.strip().splitlines()[-1][:70] if proc.stderr.strip() else ""
    return {"code": proc.returncode, "cpu": cpu, "answer": answer}


def relative_difference(a: dict | str, b: dict | str) -> float:
    """Largest relative difference of two answers' parameters (0 for equal failures, inf when they differ)."""
    if isinstance(a, str) or isinstance(b, str):
        return 0.0 if a == b else float("inf")
    return max(abs(a[k] - b[k]) / max(abs(b[k]), 1e-300) for k in b)


def main() -> None:
    from benchmarks.cli_speed import baseline_tree

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0, help="first case's seed")
    parser.add_argument("--baseline-ref", default="main")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory(prefix="synth-srivc-") as tmp, \
            baseline_tree(args.baseline_ref, "synth-srivc-base-") as base:
        for seed in range(args.seed, args.seed + args.cases):
            path, structure = case(seed, Path(tmp))
            mine = identify(ROOT, path, structure, tmp)
            theirs = identify(base, path, structure, tmp)
            rows.append((seed, structure, mine, theirs))
            print(f"case {seed} {structure}: this {mine['code']} {mine['cpu']:.1f} s; baseline {theirs['code']} "
                  f"{theirs['cpu']:.1f} s; relative difference {relative_difference(mine['answer'], theirs['answer']):.1e}",
                  flush=True)
    cpu_mine = np.array([r[2]["cpu"] for r in rows])
    cpu_base = np.array([r[3]["cpu"] for r in rows])
    diffs = np.array([relative_difference(r[2]["answer"], r[3]["answer"]) for r in rows])
    same_code = sum(r[2]["code"] == r[3]["code"] for r in rows)
    print(f"\n`synth identify --structure S --delay fit`, {len(rows)} random step trains (seeds {args.seed}-"
          f"{args.seed + len(rows) - 1})")
    print("| side | CPU median [s] | CPU total [s] | exit 0 |")
    print("|---|---|---|---|")
    print(f"| this checkout | {np.median(cpu_mine):.2f} | {cpu_mine.sum():.1f} | {sum(r[2]['code'] == 0 for r in rows)} |")
    print(f"| baseline {args.baseline_ref} | {np.median(cpu_base):.2f} | {cpu_base.sum():.1f} | "
          f"{sum(r[3]['code'] == 0 for r in rows)} |")
    print(f"\nsame exit code: {same_code} of {len(rows)}; parameters within 1e-6 / 1e-4 / 1e-2 relative: "
          f"{int(np.sum(diffs <= 1e-6))} / {int(np.sum(diffs <= 1e-4))} / {int(np.sum(diffs <= 1e-2))}; "
          f"median CPU ratio (this / baseline) {np.median(cpu_mine / cpu_base):.2f}")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
