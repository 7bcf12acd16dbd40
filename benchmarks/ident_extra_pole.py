"""``synth identify`` with one pole too many, and with the right structure: this checkout beside a baseline, in one run.

Each case draws a step train (period 2-8 s, 1-4 kHz sampling, 40-120 s; a random level and step) through either a
first-order plant ``k/(s+p)`` ("extra": the structure ``k/((s+p1)*(s+p2))`` has one pole too many, so its best fit
sends a pole to infinity and the solvers crawl along that ridge) or a second-order plant (``right``: the structure
fits), with white output noise of 0.3-3 % of the step's response. Each side runs the whole command,
``synth identify --data case.csv --structure "k/((s+p1)*(s+p2))" --json -``, one process per case; the sides run
side by side on the two cores. Reported per side and kind: exit codes, wall time (median and total), and whether the
answers (exit code; parameters to 6 significant digits, or the failure's first words) are the same.

Run:  python benchmarks/ident_extra_pole.py [--cases 12] [--baseline-ref main]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
STRUCTURE = "k/((s+p1)*(s+p2))"


def case(kind: str, seed: int, folder: Path) -> Path:
    """Write one step-train record as CSV; the plant is first order for ``extra``, second order for ``right``."""
    from scipy import signal

    rng = np.random.default_rng((1 if kind == "extra" else 2) * 100_000 + seed)
    dt = 1.0 / float(rng.choice([1000, 2000, 4000]))
    n = int(rng.uniform(40, 120) / dt)
    t = np.arange(n) * dt
    period = rng.uniform(2, 8)
    level, step = rng.uniform(-5, 5), rng.uniform(0.2, 5) * rng.choice([-1, 1])
    u = level + step * (np.floor(t / (period / 2)) % 2)
    p1 = 10 ** rng.uniform(0, 1.2)
    den = [1.0, p1] if kind == "extra" else np.poly([-p1, -p1 * 10 ** rng.uniform(0.3, 1.3)])
    b, a, _ = signal.cont2discrete(([rng.uniform(0.5, 3) * den[-1]], den), dt, method="zoh")
    y0 = signal.lfilter(np.squeeze(b), a, u - level)
    y = y0 + rng.uniform(-3, 3) + rng.uniform(0.003, 0.03) * np.ptp(y0) * rng.normal(size=n)
    path = folder / f"{kind}_{seed}.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="time,u,y", comments="", fmt="%.10g")
    return path


def run_side(root: Path, paths: list[Path]) -> list[dict]:
    """``synth identify`` of each record with ``root``'s synth; exit code, wall time, answer."""
    env = {**os.environ, "PYTHONPATH": str(root), "SYNTH_IDENTIFY_CACHE": "off"}
    rows = []
    with tempfile.TemporaryDirectory(prefix="synth-extra-pole-out-") as out:
        for path in paths:
            argv = [sys.executable, "-m", "synth", "identify", "--data", str(path), "--structure", STRUCTURE,
                    "--json", "-", "--no-figures", "--out", out, "--force"]
            start = time.perf_counter()
            proc = subprocess.run(argv, cwd=root, env=env, capture_output=True, text=True)
            wall = time.perf_counter() - start
            if proc.returncode == 0:
                answer = {k: float(f"{v:.6g}") for k, v in json.loads(proc.stdout)["parameters"].items()}
            else:
                answer = proc.stderr.strip().splitlines()[-1][:60] if proc.stderr.strip() else ""
            rows.append({"case": path.stem, "code": proc.returncode, "wall": wall, "answer": answer})
    return rows


def main() -> None:
    from concurrent.futures import ThreadPoolExecutor

    from benchmarks.cli_speed import baseline_tree

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=12, help="cases of each kind")
    parser.add_argument("--baseline-ref", default="main")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="synth-extra-pole-") as tmp, \
            baseline_tree(args.baseline_ref, "synth-extra-pole-base-") as base:
        paths = [case(kind, s, Path(tmp)) for kind in ("extra", "right") for s in range(args.cases)]
        with ThreadPoolExecutor(2) as pool:  # the two sides side by side, one core each
            mine, theirs = pool.map(lambda root: run_side(root, paths), (ROOT, base))
    print(f"`synth identify --structure \"{STRUCTURE}\"`, {args.cases} records of each kind")
    print("| kind | side | exit 0 / 1 / other | wall median [s] | wall total [s] | same answer as the baseline |")
    print("|---|---|---|---|---|---|")
    for kind in ("extra", "right"):
        for name, rows in (("this checkout", mine), (f"baseline {args.baseline_ref}", theirs)):
            sel = [r for r in rows if r["case"].startswith(kind)]
            codes = [sum(r["code"] == c for r in sel) for c in (0, 1)]
            other = len(sel) - sum(codes)
            same = sum(a["code"] == b["code"] and a["answer"] == b["answer"] for a, b in zip(
                sel, [r for r in theirs if r["case"].startswith(kind)]))
            walls = [r["wall"] for r in sel]
            print(f"| {kind} | {name} | {codes[0]} / {codes[1]} / {other} | {np.median(walls):.1f} | "
                  f"{sum(walls):.1f} | {same if name == 'this checkout' else ''} |")
    for a, b in zip(mine, theirs):
        if a["code"] != b["code"] or a["answer"] != b["answer"]:
            print(f"differs: {a['case']}: this checkout {a['code']} {a['answer']} ; baseline {b['code']} {b['answer']}")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
