"""A feasible start the user gives is never lost: each stored design problem is designed again with the
independent reference's best point as ``controller.initial``, and synth's answer must score at least as well
as that point wherever the point passes synth's own check.

The problems and reference points come from the records of ``benchmarks/design_verification.py`` (JSON lines
under ``reports/design_verification/``): the reference (``benchmarks/design_reference.py``) imports nothing
from synth, so its points are starts synth's own stages did not produce. Problems where the reference found
nothing, or whose point fails synth's check (the reference's slack tolerance is 1e-3), are skipped and counted.

Run:  python benchmarks/design_initial.py reports/design_verification/seed22_s38.jsonl [--json out.jsonl]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def rows(paths: list[str]) -> list[dict]:
    """The stored problems whose reference found a feasible point."""
    out = []
    for p in paths:
        for line in Path(p).read_text(encoding="utf-8").splitlines():
            if line.strip():
                r = json.loads(line)
                if r.get("ref_feasible") and r.get("ref_best"):
                    out.append(r)
    return out


def run_one(row: dict) -> dict:
    """Design ``row``'s spec from the reference's point; what the start and the answer score."""
    from synth import check, design
    from synth.controllers import Controller
    from synth.loop import Loop
    from synth.objectives import score
    from synth.spec import parse_spec
    from synth.synthesis.integral_action import objective_terms

    spec_dict = json.loads(json.dumps(row["spec"]))
    start = {k: float(v) for k, v in row["ref_best"]["params"].items()}
    spec_dict["controller"]["initial"] = start
    spec = parse_spec(spec_dict)
    controller = Controller(spec.controller.type, start)
    terms = objective_terms(spec)
    out = {"index": row["index"], "controller": row["controller"], "spec": row["spec"]["name"]}
    if not check(spec, controller).feasible:
        return {**out, "outcome": "start fails synth's check"}
    nominal = spec.nominal_plant()
    start_score = float(score(Loop(nominal, controller), terms))
    t0 = time.process_time()
    try:
        result = design(spec)
    except Exception as exc:  # a crash is a finding
        return {**out, "outcome": "error", "error": f"{type(exc).__name__}: {exc}"}
    seconds = time.process_time() - t0
    if not result.feasible:
        return {**out, "outcome": "lost (no design)", "status": result.status, "cpu_seconds": seconds}
    got = float(score(Loop(nominal, result.controller), terms))
    kept = got == start_score or got >= start_score - 1e-9 * max(1.0, abs(start_score))  # inf == inf: kept
    return {**out, "outcome": "kept" if kept else "lost", "start_score": start_score, "design_score": got,
            "chosen": result.extras.get("synthesis", {}).get("chosen"), "cpu_seconds": seconds}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("records", nargs="+", help="JSON-lines records of design_verification.py")
    ap.add_argument("--json", help="write one row per problem (streamed)")
    ap.add_argument("--only", type=int, nargs="*", help="only these problem indices")
    args = ap.parse_args()
    todo = [r for r in rows(args.records) if not args.only or r["index"] in args.only]
    sink = open(args.json, "w", encoding="utf-8") if args.json else None
    results = []
    for r in todo:
        res = run_one(r)
        results.append(res)
        print(f"#{res['index']:<4} {res['controller']:<9} {res['outcome']:<26} "
              + (f"start {res['start_score']:.6g} -> design {res['design_score']:.6g} ({res['chosen']}, "
                 f"{res['cpu_seconds']:.1f} s)" if "design_score" in res else res.get("error", "")), flush=True)
        if sink:
            sink.write(json.dumps(res) + "\n")
            sink.flush()
    counts: dict[str, int] = {}
    for res in results:
        counts[res["outcome"]] = counts.get(res["outcome"], 0) + 1
    cpu = sorted(res["cpu_seconds"] for res in results if "cpu_seconds" in res)
    print("\n| outcome | problems |\n|---|---|")
    for k, v in sorted(counts.items()):
        print(f"| {k} | {v} |")
    if cpu:
        print(f"| design CPU median / max [s] | {cpu[len(cpu) // 2]:.1f} / {cpu[-1]:.1f} |")


if __name__ == "__main__":
    main()
