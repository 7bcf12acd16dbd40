"""Fits from a far start that end worse than the start itself: returned as results, or reported as failures.

The problems and the three wrong starts are :mod:`pair_relocation`'s (a near cancellation, starts that put the
pair where the record cannot tell it apart). Each record is fitted by IPOPT from each start (the solver the
small records use). The start's own fit percent is computed apart from the fitter, by simulating the start's
model (:func:`synth.ident.simulate.simulate_plant`, the output's mean over the first second as its offset). A fit
"returned worse than its start" is one that comes back without a failure and with a fit percent below the start's:
the solver moved away from a better point and said nothing (issue 16, item 2). Session 34 made
:func:`synth.ident.timefit.fit_structure` retry such a fit from scaled starts and otherwise fail it.

Run:  PYTHONPATH=<checkout> python benchmarks/fit_against_start.py --first 0 --last 60 --json out.jsonl
(records above ``--max-samples`` samples are skipped: the large ones take the Levenberg-Marquardt path)
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from pair_relocation import problem, wrong_start

from synth.data import record_from_arrays
from synth.errors import SynthError
from synth.ident.simulate import simulate_plant
from synth.ident.structure import parse_structure
from synth.ident.timefit import fit_structure
from synth.plant import Plant


def start_fit_percent(p: dict, start: dict[str, float]) -> float:
    """The fit percent of the start's own model (sensor in series when the problem has one)."""
    structure = parse_structure(p["structure"])
    model = structure.plant(np.array([start[k] for k in structure.parameters]), delay=p["delay"])
    if p["sensor"]:
        model = model.series(Plant.from_string(p["sensor"]))
    y0 = float(np.mean(p["y"][p["t"] < 1.0])) + simulate_plant(model, p["t"], p["u"] - p["u"][0])
    return float(100.0 * (1.0 - np.linalg.norm(p["y"] - y0) / np.linalg.norm(p["y"] - p["y"].mean())))


def rows(seed: int, max_samples: int) -> list[dict]:
    """One row per wrong start of problem ``seed``: the fit, its failure (if any), the start's fit, CPU time."""
    p = problem(seed)
    if p["t"].size > max_samples:
        return []
    record, structure = record_from_arrays(p["t"], p["u"], p["y"]), parse_structure(p["structure"])
    out = []
    for kind in range(3):
        start = {**wrong_start(p["truth"], kind), "delay": p["delay"]}
        cpu = time.process_time()
        try:
            fit = fit_structure(record, structure, p["delay_option"], p["sensor"], initial=start, solver="ipopt")
            row = {"fit": fit.fit_percent, "failure": fit.solver.get("failure", ""), "status": fit.solver.get("status")}
        except SynthError as exc:
            row = {"fit": None, "failure": "raised: " + str(exc)[:80], "status": None}
        out.append({**row, "seed": seed, "kind": kind, "start_fit": start_fit_percent(p, start),
                    "cpu": time.process_time() - cpu})
    return out


def summary(records: list[dict]) -> str:
    """Fits returned as results, those of them worse than their start, failures, CPU time."""
    returned = [r for r in records if r["fit"] is not None and not r["failure"]]
    worse = [r for r in returned if r["fit"] < r["start_fit"]]
    cpu = [r["cpu"] for r in records]
    listed = ", ".join(f"problem {r['seed']} start {r['kind']}: {r['fit']:.2f} % against {r['start_fit']:.2f} %"
                       for r in worse) or "none"
    return (f"{len(records)} fits: {len(returned)} returned as results, {len(worse)} of them worse than their start "
            f"({listed}); {len(records) - len(returned)} failures; CPU {sum(cpu):.1f} s in all, median "
            f"{np.median(cpu):.2f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--last", type=int, default=60, help="problems first..last-1")
    parser.add_argument("--max-samples", type=int, default=8000)
    parser.add_argument("--json", help="write one JSON line per fit")
    parser.add_argument("--summarize", nargs="+", help="only summarize these JSON-lines files")
    args = parser.parse_args()
    if args.summarize:
        for path in args.summarize:
            print(path + ": " + summary([json.loads(line) for line in open(path, encoding="utf-8")]))
        return
    records = []
    out = open(args.json, "w", encoding="utf-8") if args.json else None
    for seed in range(args.first, args.last):
        for row in rows(seed, args.max_samples):
            records.append(row)
            if out is not None:
                out.write(json.dumps(row) + "\n")
                out.flush()
    print(summary(records))


if __name__ == "__main__":
    main()
