"""Certified designs whose structural parameter is free (a PID's filter, a lead-lag's pole) under step limits:
the surrogate's bisection with that parameter held at the design without the step limits, against the code of a
baseline (``--baseline-ref``, a git worktree on ``PYTHONPATH``), in one run, one process each.

The problems are ``benchmarks/step_design_verification.py``'s (plants of order 1-3, half of them delayed) with the
controller replaced: even indices a PID whose filter ``tf`` is free over two decades, odd ones a lead-lag
maximizing the bandwidth; every second pair adds ``peak |S| <= 8 dB``, every fourth pair minimizes the control
effort instead. Each row: feasible, objective, controller, CPU seconds.

Run: ``python benchmarks/held_structure.py --seed 71 --n 16 --baseline-ref <commit>`` (rows to ``--json``);
``--summarize FILE`` prints the table of a finished run.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.append(str(ROOT))  # after PYTHONPATH: a baseline worktree there supplies its own synth


def spec_of(seed: int, index: int) -> dict[str, Any]:
    """The ``index``-th problem of ``seed`` (see the module's docstring).

    Examples
    --------
    >>> s = spec_of(71, 0)
    >>> s["controller"]["type"], s["controller"]["bounds"]["tf"][1] / s["controller"]["bounds"]["tf"][0]
    ('PID', 100.0)
    """
    from benchmarks.step_design_verification import problem

    p = problem(seed, index, 0.5)
    spec, slow = p["spec"], p["slow"]
    b = spec["controller"]["bounds"]
    if index % 2 == 0:
        spec["controller"] = {"type": "PID", "bounds": {"kp": b["kp"], "ki": b["ki"], "kd": [0.0, 0.2 * b["kp"][1] / slow],
                                                        "tf": [0.002 / slow, 0.2 / slow]}}
    else:
        spec["controller"] = {"type": "leadlag", "bounds": {"k": [0.0, b["kp"][1]], "z": [0.05 * slow, 50 * slow],
                                                            "p": [0.1 * slow, 200 * slow]}}
        spec["objective"] = {"maximize": "bandwidth"}
    if index % 4 >= 2:
        spec["requirements"].append({"type": "peak_sensitivity", "max_db": 8.0})
        if index % 8 >= 4:
            spec["objective"] = {"minimize": "control_effort"}
    return spec


def run_rows(seed: int, indices: list[int], out: Path) -> None:
    """Design each problem with the ``synth`` on the path; one JSON row per problem, appended to ``out``."""
    import synth

    warnings.simplefilter("ignore")
    for i in indices:
        spec = spec_of(seed, i)
        t = time.process_time()
        try:
            r = synth.design(synth.parse_spec(spec))
            row = {"index": i, "feasible": bool(r.feasible), "objective": (r.objective or {}).get("value"),
                   "controller": dict(r.controller.parameters) if r.controller else None}
        except Exception as e:  # a failed design is a row of the table
            row = {"index": i, "error": repr(e)[:200]}
        row |= {"cpu": time.process_time() - t, "type": spec["controller"]["type"], "objective_spec": spec["objective"]}
        with open(out, "a", encoding="utf-8") as fh:
            fh.write(json.dumps(row) + "\n")


def summarize(rows: dict[str, list[dict]]) -> str:
    """The table of a run: per problem, both sides' objectives and CPU; then the totals."""
    base, new = ({r["index"]: r for r in rows[k]} for k in ("baseline", "current"))
    lines = ["| # | controller | objective | baseline: objective (CPU s) | current: objective (CPU s) | current better |",
             "|---|---|---|---|---|---|"]
    for i in sorted(set(base) & set(new)):
        a, b = base[i], new[i]
        (sense, name), = b["objective_spec"].items()
        gain = ""
        if a.get("objective") and b.get("objective"):
            rel = (b["objective"] - a["objective"]) / abs(a["objective"])
            gain = f"{(rel if sense == 'maximize' else -rel) * 100:+.2f} %"
            if b["objective_spec"].get("minimize") == "control_effort":  # in dB: the difference in dB
                gain = f"{a['objective'] - b['objective']:+.3f} dB"
        cells = [f"{r['objective']:.6g}" if r.get("objective") is not None else str(r.get("error"))[:40] for r in (a, b)]
        lines.append(f"| {i} | {b['type']} | {sense} {name} | {cells[0]} ({a['cpu']:.1f}) | {cells[1]} ({b['cpu']:.1f}) "
                     f"| {gain} |")
    both = sorted(set(base) & set(new))
    cpu = [sum(side[i]["cpu"] for i in both) for side in (base, new)]
    lines.append(f"\nCPU: baseline {cpu[0]:.1f} s, current {cpu[1]:.1f} s over {len(both)} problems")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=71)
    ap.add_argument("--n", type=int, default=16)
    ap.add_argument("--baseline-ref", help="git commit of the baseline (a worktree is made and removed)")
    ap.add_argument("--json", type=Path, help="rows: {'baseline': [...], 'current': [...]}")
    ap.add_argument("--summarize", type=Path)
    ap.add_argument("--rows", nargs=3, metavar=("SEED", "INDICES", "OUT"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.rows:
        run_rows(int(args.rows[0]), [int(i) for i in args.rows[1].split(",")], Path(args.rows[2]))
        return
    if args.summarize:
        print(summarize(json.loads(args.summarize.read_text(encoding="utf-8"))))
        return
    indices = ",".join(str(i) for i in range(args.n))
    with tempfile.TemporaryDirectory() as tmp:
        sides = {"current": (str(ROOT), Path(tmp) / "current.jsonl")}
        if args.baseline_ref:
            tree = Path(tmp) / "baseline"
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "-f", "-q", str(tree), args.baseline_ref], check=True)
            sides["baseline"] = (str(tree), Path(tmp) / "baseline.jsonl")
        try:
            env = {**os.environ, "SYNTH_JOBS": "1"}
            procs = [subprocess.Popen([sys.executable, __file__, "--rows", str(args.seed), indices, str(out)],
                                      env={**env, "PYTHONPATH": path}) for path, out in sides.values()]
            for p in procs:
                p.wait()
            rows = {k: [json.loads(line) for line in out.read_text(encoding="utf-8").splitlines()] if out.exists() else []
                    for k, (_, out) in sides.items()}
        finally:
            if args.baseline_ref:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=False)
    if args.json:
        args.json.write_text(json.dumps(rows) + "\n", encoding="utf-8")
    if "baseline" in rows:
        print(summarize(rows))


if __name__ == "__main__":
    main()
