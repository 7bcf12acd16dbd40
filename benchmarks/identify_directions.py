"""``synth identify`` on seeded step trains of the size users log, beside a baseline checkout in the same run: the
time of the whole command and what it says of the up and down steps (issues 16 and 18).

Every step train is checked for direction-dependent dynamics: the up steps and the down steps are fitted apart and
compared. Since session 45 both fits start at the fit of both directions together; before, each started from the
deterministic (SRIVC) start and walked the delay intervals again. Problems unlike the worked example: a random
plant of order 1-2, with a zero or not, behind a random delay; down steps as fast as the up steps or 0.6 / 1.5
times their time constants; a square wave or two levels held 0.5-1.5 times
4-12 time constants; 20,000-60,000 samples at
1 kHz; output noise 0.5-3 % of the step. The reference for the verdict is the truth (directions differ or not);
the reference for the numbers is the baseline's own per-direction fits (JSON ``directions``), which the current
fits must match within a standard error.

Run:  python benchmarks/identify_directions.py [--cases 40] [--seed 0] [--baseline-ref HEAD~1 | --baseline DIR]
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
sys.path.insert(0, str(ROOT))

from benchmarks.cli_speed import baseline_checkout, remove_checkout, timed_run  # noqa: E402
from synth.ident.simulate import simulate_plant  # noqa: E402
from synth.plant import Plant  # noqa: E402

STRUCTURES = {1: "k/(t1*s+1)", 2: "k/((t1*s+1)*(t2*s+1))", 3: "k*(s+z)/((s+p1)*(s+p2))"}


def problem(index: int, seed: int = 0) -> dict:
    """Problem ``index`` of the seeded set: the record's arrays, the structure, the truth's direction ratio."""
    rng = np.random.default_rng([seed, index])
    kind = int(rng.integers(1, 4))
    ratio = [1.0, 0.6, 1.5][int(rng.integers(0, 3))]
    k, delay = float(rng.uniform(0.5, 20.0)), float(rng.uniform(0.0, 0.03))
    t1 = float(rng.uniform(0.02, 0.3))
    t2 = float(rng.uniform(0.05, 0.3)) * t1
    z = float(rng.uniform(1.5, 4.0)) / t1  # a zero between the poles 1/t1 and 1/t2 or above them

    def model(scale: float) -> str:
        a, b = scale * t1, scale * t2
        if kind == 1:
            return f"{k}/({a}*s+1)"
        if kind == 2:
            return f"{k}/(({a}*s+1)*({b}*s+1))"
        return f"{k * scale / (z * a * b)}*(s+{z / scale})/((s+{1 / a})*(s+{1 / b}))"  # static gain k

    hold = float(rng.uniform(4, 12)) * max(t1, t1 * ratio)
    n = int(rng.integers(20_000, 60_001))
    t = np.arange(n) * 0.001
    if rng.random() < 0.5:  # a square wave
        u = np.where((t % (2 * hold)) >= hold, 1.0, 0.0)
    else:  # two levels, each held a random 0.5-1.5 times the hold
        edges = np.cumsum(hold * rng.uniform(0.5, 1.5, size=int(t[-1] / (0.5 * hold)) + 2))
        u = (np.searchsorted(edges, t, side="right") % 2).astype(float)
    up = np.cumsum(np.maximum(np.diff(u, prepend=u[0]), 0.0))
    down = (u - u[0]) - up
    y = (simulate_plant(Plant.from_string(model(1.0), delay=delay), t, up)
         + simulate_plant(Plant.from_string(model(ratio), delay=delay), t, down))
    y = 10.0 + y + float(rng.uniform(0.005, 0.03)) * k * rng.normal(size=n)
    return {"t": t, "u": 2.0 + u, "y": y, "structure": STRUCTURES[kind], "ratio": ratio, "samples": n}


def run(root: Path, csv: Path, structure: str, out: Path) -> tuple[float, float, dict | None]:
    """Wall and CPU time of ``synth identify`` in ``root``, and its JSON (None where it exits 1)."""
    argv = [sys.executable, "-m", "synth", "identify", "--data", str(csv), "--structure", structure, "--delay", "fit",
            "--no-figures", "--quiet", "--out", str(out), "--json", str(out / "r.json"), "--force"]
    env = {**os.environ, "PYTHONPATH": str(root), "SYNTH_IDENTIFY_CACHE": "off"}
    wall, cpu, proc = timed_run(argv, root, env)
    return wall, cpu, json.loads((out / "r.json").read_text()) if proc.returncode == 0 else None


def same_fit(a: dict, b: dict) -> bool:
    """Every parameter of fit ``a`` within one standard error (``b``'s) of fit ``b``'s."""
    return all(abs(a["parameters"][k] - v) <= b["std"][k] for k, v in b["parameters"].items() if b["std"].get(k))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=40)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--baseline-ref", default="HEAD~1")
    parser.add_argument("--baseline", type=Path, help="an existing checkout to use as the baseline instead")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="synth-identify-directions-") as tmp_name:
        tmp = Path(tmp_name)
        base = args.baseline.resolve() if args.baseline else baseline_checkout(args.baseline_ref, tmp)
        sides = {"baseline": base, "current": ROOT}
        rows = []
        try:
            for index in range(args.cases):
                p = problem(index, args.seed)
                csv = tmp / f"case{index}.csv"
                np.savetxt(csv, np.column_stack([p["t"], p["u"], p["y"]]), delimiter=",", header="t,u,y",
                           comments="", fmt="%.10g")
                row = {"index": index, "structure": p["structure"], "ratio": p["ratio"], "samples": p["samples"]}
                for side, root in sides.items():
                    wall, cpu, result = run(root, csv, p["structure"], tmp / side)
                    row[side] = {"wall": wall, "cpu": cpu, "result": result}
                rows.append(row)
                print(f"case {index}: {p['structure']}, ratio {p['ratio']}, {p['samples']} samples: "
                      + ", ".join(f"{s} {row[s]['wall']:.1f} s" for s in sides), flush=True)
        finally:
            if not args.baseline:
                remove_checkout(base)
    summarize(rows, args)


def summarize(rows: list[dict], args: argparse.Namespace) -> None:
    """Print the table of times, verdicts and agreement."""
    def directions(row: dict, side: str) -> dict | None:
        result = row[side]["result"]
        return None if result is None else result.get("directions")

    compared = [r for r in rows if directions(r, "baseline") and directions(r, "current")]
    print()
    print(f"{len(rows)} cases (seed {args.seed}); both sides compared the directions in {len(compared)}; "
          f"load average {os.getloadavg()[0]:.1f}")
    print()
    print("| | baseline | current |")
    print("|---|---|---|")
    for label, key in (("total wall [s]", "wall"), ("total CPU [s]", "cpu")):
        print(f"| {label} | {sum(r['baseline'][key] for r in rows):.1f} | {sum(r['current'][key] for r in rows):.1f} |")
    for label, key in (("median wall [s]", "wall"),):
        print(f"| {label} | {np.median([r['baseline'][key] for r in rows]):.2f} | "
              f"{np.median([r['current'][key] for r in rows]):.2f} |")
    right = {s: sum(directions(r, s)["significant"] == (r["ratio"] != 1.0) for r in compared) for s in
             ("baseline", "current")}
    print(f"| verdict right (directions differ or not, as the truth) | {right['baseline']}/{len(compared)} | "
          f"{right['current']}/{len(compared)} |")
    agree = sum(directions(r, "baseline")["significant"] == directions(r, "current")["significant"] for r in compared)
    fits = sum(same_fit(directions(r, "current")[d], directions(r, "baseline")[d])
               for r in compared for d in ("up", "down"))
    print(f"| same verdict as the baseline | | {agree}/{len(compared)} |")
    print(f"| per-direction fits within a std of the baseline's | | {fits}/{2 * len(compared)} |")
    failed = {s: [r["index"] for r in rows if r[s]["result"] is None] for s in ("baseline", "current")}
    print(f"| identify exited 1 (cases) | {failed['baseline']} | {failed['current']} |")


if __name__ == "__main__":
    main()
