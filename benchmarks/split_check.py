"""The split-record check against the Monte-Carlo scatter of the estimates (issue 16: stds that say what they rest on).

Cases are the Cramer-Rao benchmark's randomized step trains (``benchmarks/ident_crb.py``: plants of order 1-3 with
zeros and near cancellations, fitted or known delays, a sensor or none, periodic, aperiodic and multi-amplitude
trains), each with three kinds of output noise of the case's std:

- ``white``: white Gaussian noise (the stds assume it);
- ``ar``: AR(1) noise with coefficient 0.95 (coloured: the stds are too small);
- ``walk``: white noise plus a random walk whose end is about 2 noise stds away (a slow drift).

For each case and noise kind, ``--seeds`` realizations are identified (``synth.ident.identify``) and the estimates'
scatter over them divided by their mean reported std (``emp/rep``, the largest over the parameters) is the
reference: written here from the fits' numbers alone, apart from the split check's own test. Seed 0's record is
then split-checked (``synth.ident.split_check``, ``--parts`` parts). The table counts, per noise kind, the verdicts
where the reference says the stds are right (``emp/rep`` at most 1.5: a "stds too small" there is a false alarm)
and where it says they are too small (``emp/rep`` above 2: "consistent" there is a miss).

Run:  nice -n 10 python benchmarks/split_check.py [--first 0] [--cases 30] [--seeds 8] [--parts 5] [--json rows.json]
      python benchmarks/split_check.py --merge rowsA.json rowsB.json   # the table of runs split over processes
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.ident_crb import DT, make_case, sensor_text  # noqa: E402
from synth.data import record_from_arrays  # noqa: E402
from synth.errors import SynthError  # noqa: E402
from synth.ident.identification import identify  # noqa: E402
from synth.ident.split_check import split_check  # noqa: E402

NOISES = ("white", "ar", "walk")


def noise(kind: str, sigma: float, n: int, rng: np.random.Generator) -> np.ndarray:
    """Output noise of std ``sigma`` (the walk: white of std ``sigma`` plus a walk ending about 2 ``sigma`` away)."""
    white = rng.normal(size=n)
    if kind == "white":
        return sigma * white
    if kind == "ar":
        out = np.empty(n)
        state = 0.0
        for k in range(n):
            state = 0.95 * state + white[k]
            out[k] = state
        return sigma * out * np.sqrt(1 - 0.95**2)
    return sigma * (white + np.cumsum(rng.normal(size=n)) * 2.0 / np.sqrt(n))


def run(index: int, kind: str, seeds: int, parts: int, samples: int) -> dict[str, Any]:
    case = make_case(index, samples)
    t = np.arange(case.samples) * DT
    delay = "fit" if case.fit_delay else case.delay
    sensor = sensor_text(case.sensor)
    est: list[list[float]] = []
    rep: list[list[float]] = []
    names: list[str] = []
    failed = 0
    records = []
    for seed in range(seeds):
        y = 3.0 + case.y0 + noise(kind, case.sigma, case.samples, np.random.default_rng(1000 * index + seed))
        records.append(y)
        try:
            fit = identify((t, case.u, y), case.structure, delay, sensor, compare_directions=False).fit
        except SynthError:
            failed += 1
            continue
        names = fit.names[:-1]
        est.append([float(fit.parameters.get(k, fit.delay)) for k in names])
        rep.append([float(fit.std.get(k, np.nan)) for k in names])
    row: dict[str, Any] = {"case": index, "label": case.label(), "noise": kind, "fits": len(est), "failed": failed}
    if len(est) >= 3:
        e, r = np.array(est), np.array(rep)
        with np.errstate(all="ignore"):
            ratio = e.std(axis=0, ddof=1) / np.nanmean(r, axis=0)
        row["emp_over_rep"] = dict(zip(names, ratio.tolist()))
        row["worst_emp_over_rep"] = float(np.nanmax(ratio)) if np.any(np.isfinite(ratio)) else float("nan")
    t0 = time.perf_counter()
    check = split_check(record_from_arrays(t, case.u, records[0]), case.structure, delay, sensor, parts=parts)
    row["split_seconds"] = time.perf_counter() - t0
    row["verdict"] = check.verdict
    row["split_ratio"] = check.ratio
    row["split_worst"] = max(check.ratio.values()) if check.ratio else float("nan")
    return row


def summary(rows: list[dict[str, Any]]) -> str:
    lines = ["| noise | reference: stds right (emp/rep <= 1.5) | false 'too small' | reference: stds too small "
             "(emp/rep > 2) | caught | in between | undetermined | split ratio / emp/rep (median) |",
             "|---|---|---|---|---|---|---|---|"]
    for kind in NOISES:
        mine = [r for r in rows if r["noise"] == kind and "worst_emp_over_rep" in r]
        right = [r for r in mine if r["worst_emp_over_rep"] <= 1.5 and r["verdict"] != "undetermined"]
        small = [r for r in mine if r["worst_emp_over_rep"] > 2 and r["verdict"] != "undetermined"]
        between = [r for r in mine if 1.5 < r["worst_emp_over_rep"] <= 2]
        undetermined = [r for r in mine if r["verdict"] == "undetermined"]
        false = sum(r["verdict"] == "stds too small" for r in right)
        caught = sum(r["verdict"] == "stds too small" for r in small)
        scale = [r["split_worst"] / r["worst_emp_over_rep"] for r in small if r["verdict"] == "stds too small"]
        shown = f"{np.median(scale):.2f}" if scale else "-"
        lines.append(f"| {kind} | {len(right)} | {false} | {len(small)} | {caught} | {len(between)} | "
                     f"{len(undetermined)} | {shown} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", type=int, default=30)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--parts", type=int, default=5)
    ap.add_argument("--samples", type=int, default=16000)
    ap.add_argument("--json", help="write the rows here")
    ap.add_argument("--merge", nargs="+", metavar="JSON", help="only print the table of these row files")
    args = ap.parse_args()
    if args.merge:
        print(summary([r for path in args.merge for r in json.loads(Path(path).read_text())]))
        return
    rows = []
    t0 = time.perf_counter()
    for i in range(args.first, args.first + args.cases):
        for kind in NOISES:
            rows.append(run(i, kind, args.seeds, args.parts, args.samples))
            r = rows[-1]
            print(f"case {i} {kind}: emp/rep {r.get('worst_emp_over_rep', float('nan')):.2f}, split {r['verdict']} "
                  f"({r['split_worst']:.2f}) [{time.perf_counter() - t0:.0f} s]", file=sys.stderr, flush=True)
            if args.json:
                Path(args.json).write_text(json.dumps(rows, indent=1))
    print(summary(rows))
    print(f"\n{args.cases} cases x {len(NOISES)} noises x {args.seeds} seeds, {args.parts} parts: "
          f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
