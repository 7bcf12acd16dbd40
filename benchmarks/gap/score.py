"""Score :func:`synth.gap.attribution.heldout.diagnose_effects` on the withheld-effect benchmark.

Every case of :mod:`benchmarks.gap.generate` is diagnosed with the full candidate list
(:data:`synth.gap.effects.registry.DEFAULT_CANDIDATES`) and the defaults; the diagnosis sees only the
record and the mismatched nominal model. What is counted:

* **top-1** (cases with an effect): the first entry of ``verdict["effects"]`` is the true effect. An
  indistinguishable group counts only when the truth is listed first; ``lag(sensor)`` for a lag at
  the actuator counts as wrong (the data cannot tell them apart; the diagnosis lists ``lag`` first).
* **effect-free cases**: a parameter mismatch is present in every case, so ``["parameter_mismatch"]``
  is the right answer and ``[]`` is accepted too; a **false alarm** is any other effect named.
* **shrinkage error**: ``|reported - true|`` for cases whose verdict names the true effect first,
  the reported shrinkage that of the accepted effect and the true one ``1 - J_true / J_refit``
  (true model with the true effect, against the re-fit alone, on the same held-out half).

Goals (issue 6): top-1 >= 90 %, false alarms <= 5 %, shrinkage error <= 0.1.

Run:  python benchmarks/gap/score.py [--quick] [--workers 2] [--seed 0]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections import Counter, defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from benchmarks.gap.generate import SEVERITIES, case_list, make_case  # noqa: E402

GOALS = {"top1": 0.90, "false_alarm": 0.05, "shrinkage_error": 0.10}
OUT = ROOT / "reports" / "gap_benchmark"


def run_case(args: tuple[int, int]) -> dict[str, Any]:
    """Generate case ``index`` and diagnose it; one JSON-ready row."""
    import contextlib

    from synth.gap.attribution.heldout import diagnose_effects

    seed, index = args
    with open(os.devnull, "w") as null, contextlib.redirect_stderr(null):
        case = make_case(seed, index)
    t0 = time.perf_counter()
    fd = os.dup(2)  # casadi writes warnings straight to file descriptor 2
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
            dg = diagnose_effects(case.nominal, case.record)
    finally:
        os.dup2(fd, 2)
        os.close(fd)
    elapsed = time.perf_counter() - t0
    verdict = dg.verdict["effects"]
    first = verdict[0] if verdict else "none"
    reported = next((e for e in dg.effects if e.effect == first), None)
    truth = case.effect or "none"
    if case.effect is None:
        correct = verdict in ([], ["parameter_mismatch"])
    else:
        correct = first == case.effect
    row = {**case.to_dict(), "verdict": verdict, "first": first, "status": dg.verdict["status"],
           "indistinguishable": dg.verdict["indistinguishable"], "correct": bool(correct), "truth": truth,
           "reported_shrinkage": float(reported.shrinkage) if reported is not None else None,
           "reported_parameters": dict(reported.parameters) if reported is not None else None,
           "diag_j_refit": dg.j_refit, "threshold": dg.threshold, "noise_std": float(np.sqrt(dg.noise_floor)),
           "joint_fits": dg.split["joint_fits"], "seconds": elapsed}
    if case.effect is not None and correct:
        row["shrinkage_error"] = abs(row["reported_shrinkage"] - case.true_shrinkage)
    return row


def summarize(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Accuracy per effect and severity, false alarms, shrinkage errors, confusion matrix, time."""
    eff_rows = [r for r in rows if r["effect"] is not None]
    free = [r for r in rows if r["effect"] is None]
    per_effect: dict[str, list[bool]] = defaultdict(list)
    per_sev: dict[float, list[bool]] = defaultdict(list)
    for r in eff_rows:
        per_effect[r["effect"]].append(r["correct"])
        per_sev[r["severity"]].append(r["correct"])
    errs = [r["shrinkage_error"] for r in eff_rows if "shrinkage_error" in r]
    confusion = Counter((r["truth"], r["first"]) for r in rows)
    false_alarms = [r for r in free if not r["correct"]]
    return {
        "cases": len(rows), "effect_cases": len(eff_rows), "effect_free_cases": len(free),
        "top1": float(np.mean([r["correct"] for r in eff_rows])) if eff_rows else float("nan"),
        "top1_per_effect": {k: [int(sum(v)), len(v)] for k, v in sorted(per_effect.items())},
        "top1_per_severity": {str(k): [int(sum(v)), len(v)] for k, v in sorted(per_sev.items())},
        "false_alarm_rate": len(false_alarms) / len(free) if free else float("nan"),
        "false_alarms": [[r["index"], r["first"]] for r in false_alarms],
        "shrinkage_error_mean": float(np.mean(errs)) if errs else float("nan"),
        "shrinkage_error_max": float(np.max(errs)) if errs else float("nan"),
        "shrinkage_error_n": len(errs),
        "confusion": [[a, b, n] for (a, b), n in sorted(confusion.items())],
        "seconds_mean": float(np.mean([r["seconds"] for r in rows])),
        "seconds_max": float(np.max([r["seconds"] for r in rows])),
        "samples": sorted({r["samples"] for r in rows}),
    }


def _met(value: float, goal: float, upper: bool) -> str:
    ok = value <= goal if upper else value >= goal
    return "met" if ok else "NOT met"


def render(summary: dict[str, Any], command: str, wall: float) -> str:
    """The scorecard as markdown."""
    s = summary
    lines = ["# Withheld-effect benchmark scorecard", "",
             f"Command: `{command}` ({s['cases']} cases: {s['effect_cases']} with one hidden effect, "
             f"{s['effect_free_cases']} effect-free; records of {', '.join(map(str, s['samples']))} samples; "
             f"wall time {wall:.0f} s).", "",
             "| measure | value | goal | |", "|---|---|---|---|",
             f"| top-1 accuracy (cases with an effect) | {100 * s['top1']:.1f} % | >= 90 % | "
             f"{_met(s['top1'], GOALS['top1'], False)} |",
             f"| false alarms (effect-free cases naming an effect) | {100 * s['false_alarm_rate']:.1f} % | <= 5 % | "
             f"{_met(s['false_alarm_rate'], GOALS['false_alarm'], True)} |",
             f"| mean abs(reported - true shrinkage), n = {s['shrinkage_error_n']} | {s['shrinkage_error_mean']:.3f} "
             f"| <= 0.1 | {_met(s['shrinkage_error_mean'], GOALS['shrinkage_error'], True)} |",
             f"| max abs(reported - true shrinkage) | {s['shrinkage_error_max']:.3f} | | |",
             f"| mean time per diagnosis | {s['seconds_mean']:.1f} s (max {s['seconds_max']:.1f} s) | | |", "",
             "## Top-1 per effect", "", "| effect | correct | cases |", "|---|---|---|"]
    for k, (c, n) in s["top1_per_effect"].items():
        lines.append(f"| {k} | {c} | {n} |")
    lines += ["", "## Top-1 per severity (effect RMS / noise)", "", "| severity | correct | cases |", "|---|---|---|"]
    for k, (c, n) in s["top1_per_severity"].items():
        lines.append(f"| {k} | {c} | {n} |")
    lines += ["", "## Confusion (truth -> first named)", "", "| truth | first named | cases |", "|---|---|---|"]
    for a, b, n in s["confusion"]:
        lines.append(f"| {a} | {b} | {n} |")
    lines += ["", "Counting: top-1 = the first entry of `verdict.effects` is the true effect (an indistinguishable "
              "group counts only with the truth first; `lag(sensor)` for an actuator lag is wrong). Effect-free: "
              "`[\"parameter_mismatch\"]` (every case has a 2-5 % mismatch) or `[]` is right; any other effect named "
              "is a false alarm. Shrinkage error over the cases whose verdict names the true effect.", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    """CLI."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="every 5th case only")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args(argv)
    from tqdm import tqdm

    n = len(case_list())
    indices = list(range(0, n, 5)) if args.quick else list(range(n))
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(tqdm(pool.map(run_case, [(args.seed, i) for i in indices]), total=len(indices),
                         desc="diagnoses", file=sys.stderr))
    wall = time.perf_counter() - t0
    summary = summarize(rows)
    command = "python benchmarks/gap/score.py" + (" --quick" if args.quick else "") + (
        f" --seed {args.seed}" if args.seed else "")
    text = render(summary, command, wall)
    args.out.mkdir(parents=True, exist_ok=True)
    name = "scorecard_quick" if args.quick else "scorecard"
    (args.out / f"{name}.md").write_text(text)
    (args.out / f"{name}.json").write_text(json.dumps({"summary": summary, "severities": list(SEVERITIES),
                                                       "goals": GOALS, "wall_seconds": wall, "cases": rows},
                                                      indent=1, default=float))
    print(text)


if __name__ == "__main__":
    main()
