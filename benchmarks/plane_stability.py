"""Benchmark: the exact plane search of a PI's (or two PID gains') stabilizing set against a brute-force grid.

    python benchmarks/plane_stability.py --seed 0 --n 200 [--json rows.jsonl]

Problems come from ``benchmarks/plane_stability_cases.py`` (random plants of order 1-4 with unstable poles,
right-half-plane zeros, integrators, lightly damped pairs and delays; PI or two free PID gains; boxes with and
without negative gains, many holding no stabilizing controller). The reference is
``benchmarks/plane_stability_reference.py``, written without synth: each point of a 161 x 161 grid counted by
polynomial roots or, with a delay, by the argument principle on a contour left of the axis. Compared with
:func:`synth.synthesis.stabilizing_plane.plane_search`:

- **false empty**: synth shows the box holds no stabilizing controller where the grid holds a (robustly) stable
  point: a wrong proof, must be 0;
- **false start**: synth's stabilizing controller is not stable for the reference: must be 0;
- agreement where the grid finds stable points (synth must find one), the empty boxes synth proves empty, the
  boxes synth leaves undecided (biproper loops, more strips than it decides), and where synth finds a start in a
  box whose grid holds none (a region thinner than the grid: checked at synth's point).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.plane_stability_cases import random_case
from benchmarks.plane_stability_reference import stable_grid

GRID = 161
"""Points per axis of the reference's grid."""


def reference_point(case: dict[str, Any], x: float, y: float) -> tuple[bool, bool]:
    """(stable, marginal) of the reference at one point."""
    _, _, stable, marginal = stable_grid(case["num"], case["den"], case["delay"], case["ctype"], case["fixed"],
                                         case["x_name"], (x, x), case["y_name"], (y, y), n=1)
    return bool(stable[0, 0]), bool(marginal[0, 0])


def run_case(case: dict[str, Any], grid: int = GRID) -> dict[str, Any]:
    """synth's answer and the reference's grid on one problem, classified."""
    from synth.plant import Plant
    from synth.synthesis.stabilizing_plane import plane_search

    plant = Plant(np.asarray(case["num"], float), np.asarray(case["den"], float), delay=float(case["delay"]))
    t0 = time.process_time()
    found = plane_search(case["ctype"], (case["x_name"], case["y_name"]), dict(case["fixed"]), [plant],
                         (tuple(case["x_box"]), tuple(case["y_box"])))
    synth_s = time.process_time() - t0
    t0 = time.process_time()
    _, _, stable, marginal = stable_grid(case["num"], case["den"], case["delay"], case["ctype"], case["fixed"],
                                         case["x_name"], tuple(case["x_box"]), case["y_name"], tuple(case["y_box"]),
                                         n=grid)
    ref_s = time.process_time() - t0
    robust = stable & ~marginal
    row: dict[str, Any] = {"case": {k: (list(v) if isinstance(v, tuple | np.ndarray) else v) for k, v in case.items()},
                           "synth_seconds": synth_s, "ref_seconds": ref_s, "ref_stable_points": int(robust.sum()),
                           "ref_marginal_points": int(marginal.sum())}
    if found is None:
        row.update(synth="undecided", outcome="undecided" + (" (grid stable)" if robust.any() else " (grid empty)"))
        return row
    row.update(synth="start" if found.start is not None else "empty", strips=found.strips, text=found.text)
    if found.start is None:
        row["outcome"] = "FALSE EMPTY" if robust.any() else "agree empty"
        return row
    point_stable, point_marginal = reference_point(case, found.start[case["x_name"]], found.start[case["y_name"]])
    row["start"] = found.start
    row["start_reference"] = {"stable": point_stable, "marginal": point_marginal}
    if not point_stable and not point_marginal:
        row["outcome"] = "FALSE START"
    elif robust.any():
        row["outcome"] = "agree stabilizable"
    else:
        row["outcome"] = "start the grid missed" if point_stable else "start at the reference's margin"
    return row


def summarize(rows: list[dict[str, Any]]) -> str:
    """The benchmark's table (markdown)."""
    counts: dict[str, int] = {}
    for r in rows:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    grid_stable = [r for r in rows if r["ref_stable_points"] > 0]
    grid_empty = [r for r in rows if r["ref_stable_points"] == 0]
    synth_t = [r["synth_seconds"] for r in rows]
    ref_t = [r["ref_seconds"] for r in rows]

    def p95(x: list[float]) -> float:
        return float(np.percentile(x, 95)) if x else float("nan")

    lines = ["| measure | value |", "|---|---|", f"| problems | {len(rows)} |"]
    lines += [f"| {k} | {v} |" for k, v in sorted(counts.items())]
    proved = sum(r["outcome"] == "agree empty" for r in grid_empty)
    found = sum(r["outcome"] == "agree stabilizable" for r in grid_stable)
    lines += [f"| grid holds stable points: synth finds a stabilizing controller | {found} of {len(grid_stable)} |",
              f"| grid holds none: synth proves the box empty | {proved} of {len(grid_empty)} |",
              f"| synth CPU per problem, median / p95 [s] | {statistics.median(synth_t):.3f} / {p95(synth_t):.3f} |",
              f"| reference CPU per problem ({GRID} x {GRID} grid), median / p95 [s] | "
              f"{statistics.median(ref_t):.3f} / {p95(ref_t):.3f} |"]
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--json", help="write one JSON row per problem (streamed)")
    ap.add_argument("--summarize", nargs="+", metavar="JSONL", help="only print the table of stored rows")
    args = ap.parse_args()
    if args.summarize:
        rows = [json.loads(line) for f in args.summarize for line in open(f, encoding="utf-8") if line.strip()]
        print(summarize(rows))
        return
    rows = []
    out = open(args.json, "w", encoding="utf-8") if args.json else None
    try:
        for i in range(args.start, args.start + args.n):
            row = run_case(random_case(args.seed, i))
            row["index"] = i
            rows.append(row)
            if out:
                out.write(json.dumps(row, default=float) + "\n")
                out.flush()
            flag = "" if row["outcome"] in ("agree empty", "agree stabilizable") else "   <--"
            print(f"{i:4d} {row['outcome']:32s} synth {row['synth_seconds']:.2f}s ref {row['ref_seconds']:.2f}s{flag}",
                  flush=True)
    finally:
        if out:
            out.close()
    print()
    print(summarize(rows))


if __name__ == "__main__":
    main()
