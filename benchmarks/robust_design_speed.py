"""``synth design`` on the robust (multi-plant) problems of ``benchmarks/robust_problems.py``: this checkout beside a
baseline, CPU time and answers.

Each problem's spec (a nominal plant with 1-4 variants, a controller structure, 1-3 requirements, an objective) is
written as YAML and designed by the whole command ``synth design SPEC --no-report --json -`` in a fresh process,
this checkout's and the baseline's one after the other (so both see the same load). The time is the CPU time of the
command's process and its children; a command still running at ``--cap`` CPU-equivalent wall seconds is stopped and
counted at the cap ("capped"). Answers are compared as the exit code and every controller parameter to 1e-4
relative.

Run:  python benchmarks/robust_design_speed.py [--seed 7] [--n 100] [--controllers PI PID] [--baseline-ref main]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]


def design(root: Path, spec: Path, cap: float) -> dict:
    """One ``synth design`` with ``root``'s synth: exit code (``None`` when capped), CPU seconds, parameters."""
    env = {**os.environ, "PYTHONPATH": str(root), "SYNTH_JOBS": "1"}
    argv = [sys.executable, "-m", "synth", "design", str(spec), "--no-report", "--json", "-", "--quiet"]
    from benchmarks.cli_speed import timed_run

    try:
        wall, cpu, proc = timed_run(argv, root, env, codes=(0, 1, 2, 3), timeout=cap)
        code, out = proc.returncode, proc.stdout
    except subprocess.TimeoutExpired:
        wall, cpu, code, out = cap, cap, None, ""
    params: dict[str, float] = {}
    if code in (0, 1, 3) and out.strip():
        controller = json.loads(out).get("controller") or {}
        params = {k: float(v) for k, v in (controller.get("parameters") or {}).items()}
    return {"code": code, "cpu": cpu, "wall": wall, "params": params}


def same_answer(a: dict, b: dict) -> bool:
    """The same exit code and every parameter within 1e-4 relative (1e-9 absolute)."""
    if a["code"] != b["code"] or set(a["params"]) != set(b["params"]):
        return False
    return all(abs(a["params"][k] - b["params"][k]) <= 1e-4 * abs(b["params"][k]) + 1e-9 for k in b["params"])


def main() -> None:
    from benchmarks.cli_speed import baseline_tree
    from benchmarks.robust_problems import problem

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--n", type=int, default=100, help="problems 0..n-1 of the seed, filtered by --controllers")
    parser.add_argument("--controllers", nargs="+", default=["PI", "PID"])
    parser.add_argument("--cap", type=float, default=120.0, help="wall seconds per command")
    parser.add_argument("--baseline-ref", default="main")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory(prefix="synth-robust-") as tmp, \
            baseline_tree(args.baseline_ref, "synth-robust-base-") as base:
        for index in range(args.n):
            p = problem(args.seed, index)
            if p.spec["controller"]["type"] not in args.controllers:
                continue
            spec = Path(tmp) / f"robust_{args.seed}_{index}.yaml"
            spec.write_text(yaml.safe_dump(p.spec, sort_keys=False))
            mine, theirs = design(ROOT, spec, args.cap), design(base, spec, args.cap)
            rows.append((index, p.spec["controller"]["type"], mine, theirs))
            print(f"#{index} {p.spec['controller']['type']}: this {mine['code']} {mine['cpu']:.1f} s; baseline "
                  f"{theirs['code']} {theirs['cpu']:.1f} s; same answer {same_answer(mine, theirs)}", flush=True)
    cpu_mine = np.array([r[2]["cpu"] for r in rows])
    cpu_base = np.array([r[3]["cpu"] for r in rows])
    print(f"\n`synth design SPEC --no-report`, {len(rows)} robust problems of seed {args.seed} "
          f"({', '.join(args.controllers)}), cap {args.cap:g} s")
    print("| side | CPU median [s] | CPU p90 [s] | CPU total [s] | capped | exit 0 / 1 / 3 |")
    print("|---|---|---|---|---|---|")
    for name, cpu, k in (("this checkout", cpu_mine, 2), (f"baseline {args.baseline_ref}", cpu_base, 3)):
        codes = [r[k]["code"] for r in rows]
        print(f"| {name} | {np.median(cpu):.2f} | {np.percentile(cpu, 90):.2f} | {cpu.sum():.1f} | "
              f"{codes.count(None)} | {codes.count(0)} / {codes.count(1)} / {codes.count(3)} |")
    print(f"\nsame answer (exit code, parameters to 1e-4): {sum(same_answer(r[2], r[3]) for r in rows)} of {len(rows)}; "
          f"median CPU ratio (this / baseline) {np.median(cpu_mine / cpu_base):.2f}")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
