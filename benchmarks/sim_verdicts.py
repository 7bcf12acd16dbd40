"""Benchmark: synth's step verdicts against an independent reference on random nonlinear loops.

    python benchmarks/sim_verdicts.py --n 100 --seed 104    # the README table (also 105, 106)
    python benchmarks/sim_verdicts.py --quick               # 12 loops
    python benchmarks/sim_verdicts.py --n 5 --ivp           # the reference's plant by solve_ivp

Loops come from ``benchmarks/sim_cases.py`` (seeded); the reference is
``benchmarks/sim_reference.py`` (written without synth). For each loop synth answers with
``synth.sim.verdict.step_verdict`` (no horizon given) and the reference with its own long run.
Compared: limit-cycle presence, the verdict, amplitude and period (relative), rise and settling
times (in samples). Both are timed in the same run.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.sim_cases import random_cases, synth_loop
from benchmarks.sim_reference import reference_run

__all__ = ["compare", "investigate", "main", "run_case"]


def run_case(case: dict[str, Any], method: str = "expm") -> dict[str, Any]:
    """synth's and the reference's answers for one case, with their times."""
    from synth.sim.verdict import step_verdict

    t0 = time.perf_counter()
    v = step_verdict(synth_loop(case), 0.0, case["step"], case["t_step"])
    t_synth = time.perf_counter() - t0
    t0 = time.perf_counter()
    ref = reference_run(case, method)
    t_ref = time.perf_counter() - t0
    m = v.metrics
    lc = m.limit_cycle
    ours = {"verdict": v.verdict, "amplitude": lc.amplitude, "period": lc.period, "periodic": lc.periodic,
            "amplitude_range": lc.amplitude_range, "period_range": lc.period_range,
            "rise_time": m.rise_time, "settling_time": m.settling_time, "horizon": v.evidence.horizon,
            "criterion": v.evidence.criterion, "cycles": v.evidence.cycles}
    return {"synth": ours, "reference": ref, "t_synth": t_synth, "t_reference": t_ref, "dt": case["dt"]}


def compare(row: dict[str, Any]) -> dict[str, Any]:
    """Agreement measures of one row of :func:`run_case`."""
    s, r, dt = row["synth"], row["reference"], row["dt"]
    out: dict[str, Any] = {"ambiguous": r["verdict"] == "ambiguous"}
    out["presence"] = (s["verdict"] == "limit_cycle") == (r["verdict"] == "limit_cycle") and \
        s["verdict"] != "undetermined"
    out["verdict"] = s["verdict"] == r["verdict"]
    if s["verdict"] == r["verdict"] == "limit_cycle" and s["periodic"] is not False:
        out["amplitude"] = abs(s["amplitude"] - r["amplitude"]) / r["amplitude"]
        out["period"] = abs(s["period"] - r["period"]) / r["period"]
    elif s["verdict"] == r["verdict"] == "limit_cycle":  # not periodic: is the reference inside synth's ranges?
        (a0, a1), (p0, p1) = s["amplitude_range"], s["period_range"]
        out["in_range"] = bool(0.98 * a0 <= r["amplitude"] <= 1.02 * a1 and 0.98 * p0 <= r["period"] <= 1.02 * p1)
    if s["verdict"] == r["verdict"] == "limit_cycle" and "repeats" in r:
        out["periodic_agrees"] = bool(s["periodic"] is not False) == r["repeats"]
    if s["verdict"] == r["verdict"] == "settled":
        if r.get("rise_time") is not None and np.isfinite(s["rise_time"]):
            out["rise"] = abs(s["rise_time"] - r["rise_time"]) / dt
        if r.get("settling_time") is not None and s["settling_time"] is not None:
            out["settling"] = abs(s["settling_time"] - r["settling_time"]) / dt
    return out


def investigate(row: dict[str, Any], max_samples: int = 1_000_000) -> dict[str, Any]:
    """The reference again over a longer run (4 times the longer of the two horizons, at most
    ``max_samples``), for a row where the two disagree: which side was wrong?"""
    case = row["case"]
    T = min(4 * max(row["synth"]["horizon"], row["reference"]["horizon"]), max_samples * case["dt"])
    ref = reference_run(case, horizon=T, longest=T, max_samples=max_samples)
    return ref


def _off(c: dict[str, Any], dt: float) -> str:
    parts = []
    if not c["verdict"]:
        parts.append("verdict")
    for key, tol, unit in (("amplitude", 0.02, "%"), ("period", 0.02, "%"), ("rise", 1.0, " samples"),
                           ("settling", 1.0, " samples")):
        if key in c and c[key] > tol:
            parts.append(f"{key} {100 * c[key]:.3g}{unit}" if unit == "%" else f"{key} {c[key]:.3g}{unit}")
    if c.get("in_range") is False:
        parts.append("reference outside synth's ranges")
    return ", ".join(parts)


def _summary(comps: list[dict[str, Any]]) -> list[tuple[str, str, str]]:
    """(measure, result, goal) rows of the agreement table."""
    decided = [c for c in comps if not c["ambiguous"]]

    def frac(key: str, tol: float) -> str:
        xs = [c[key] for c in comps if key in c]
        return f"{sum(x <= tol for x in xs)}/{len(xs)}" + (f" (worst {max(xs):.3g})" if xs else "")

    def count(key: str) -> str:
        xs = [c[key] for c in comps if key in c]
        return f"{sum(xs)}/{len(xs)}"

    presence = [c["presence"] for c in decided]
    return [
        ("limit-cycle presence agrees (reference decided)",
         f"{sum(presence)}/{len(presence)} = {100 * np.mean(presence):.1f} %", ">= 98 %"),
        ("same verdict (settled / limit cycle / diverging)", f"{sum(c['verdict'] for c in decided)}/{len(decided)}",
         ""),
        ("periodic cycles (synth): amplitude within 2 %", frac("amplitude", 0.02), "all"),
        ("periodic cycles (synth): period within 2 %", frac("period", 0.02), "all"),
        ("cycles not periodic (synth): reference's amplitude and period inside synth's ranges (+-2 %)",
         count("in_range"), "all"),
        ("periodic or not: synth agrees with the reference's own per-cycle test", count("periodic_agrees"), ""),
        ("rise time within one sample", frac("rise", 1.0), "all"),
        ("settling time within one sample", frac("settling", 1.0), "all"),
    ]


def _describe(case: dict[str, Any]) -> str:
    blocks = "+".join(k for k, _ in case["actuator"]) + (", sensor quantizer" if case["sensor"] else "")
    return f"{case['controller']['type']} n={len(case['poles'])} delay={case['delay']:.2g} {blocks}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--seed", type=int, default=15)
    ap.add_argument("--quick", action="store_true", help="12 loops")
    ap.add_argument("--ivp", action="store_true", help="reference plant by solve_ivp (slow)")
    ap.add_argument("--ivp-check", type=int, metavar="K", default=0,
                    help="only compare the reference's two plant propagators (expm, solve_ivp) on K loops over 20 s")
    ap.add_argument("--json", help="write every row to this file")
    ap.add_argument("--cases", help="only these loop indices (comma-separated), to look at disagreements")
    args = ap.parse_args(argv)
    n = 12 if args.quick else args.n
    cases = random_cases(n, args.seed)
    index = list(range(n)) if not args.cases else [int(i) for i in args.cases.split(",")]
    cases = [cases[i] for i in index]
    if args.ivp_check:
        from benchmarks.sim_reference import simulate_reference

        for i, case in enumerate(cases[:args.ivp_check]):
            a, b = simulate_reference(case, 20.0, "expm"), simulate_reference(case, 20.0, "ivp")
            ok = np.isfinite(a.y) & np.isfinite(b.y)
            print(f"{i:3d} {_describe(case):48s} max |expm - solve_ivp| = "
                  f"{np.max(np.abs(a.y[ok] - b.y[ok])) / max(abs(case['step']), 1e-12):.2g} steps")
        return 0
    from synth.sim.verdict import step_verdict  # warm numba's cache outside the timing
    step_verdict(synth_loop(cases[0]), 0.0, 1.0)
    rows, comps = [], []
    for i, case in enumerate(cases):
        row = run_case(case, "ivp" if args.ivp else "expm")
        c = compare(row)
        rows.append({"case": case, **row, "compare": c})
        comps.append(c)
        s, r = row["synth"], row["reference"]
        flag = "" if c["verdict"] else "  <-- differs"
        print(f"{index[i]:3d} {_describe(case):48s} synth {s['verdict']:12s} ref {r['verdict']:12s}"
              f" {row['t_synth']:6.2f}s {row['t_reference']:6.2f}s{flag}", flush=True)
    print("\nDisagreements, each checked by a longer run of the reference:\n")
    print("| loop | blocks | synth (horizon) | reference (horizon) | reference, longer run | what differs |")
    print("|---|---|---|---|---|---|")
    settled_by_longer = []
    for i, row in enumerate(rows):
        off = _off(row["compare"], row["dt"])
        if not off:
            settled_by_longer.append(row["compare"])
            continue
        s_, r_ = row["synth"], row["reference"]
        longer = investigate(row)
        row["reference_longer"] = longer
        again = compare({**row, "reference": longer})
        settled_by_longer.append(again)
        extra = (f" {longer['amplitude']:.4g} / {longer['period']:.4g} s" if longer["verdict"] == "limit_cycle"
                 else "")
        ours = (f" {s_['amplitude']:.4g} / {s_['period']:.4g} s" if s_["verdict"] == "limit_cycle" else "")
        if s_["verdict"] == "limit_cycle" and s_["periodic"] is False:
            ours += (f" not periodic: {s_['amplitude_range'][0]:.4g}-{s_['amplitude_range'][1]:.4g} / "
                     f"{s_['period_range'][0]:.4g}-{s_['period_range'][1]:.4g} s")
        theirs = (f" {r_['amplitude']:.4g} / {r_['period']:.4g} s" if r_["verdict"] == "limit_cycle" else "")
        still = _off(again, row["dt"]) or "agree"
        print(f"| {index[i]} | {_describe(row['case'])} | {s_['verdict']}{ours} ({s_['horizon']:.4g} s) | "
              f"{r_['verdict']}{theirs} ({r_['horizon']:.4g} s) | {longer['verdict']}{extra} ({longer['horizon']:.4g} s) "
              f"| {off}; after the longer run: {still} |", flush=True)
    ts = np.array([r["t_synth"] for r in rows])
    tr = np.array([r["t_reference"] for r in rows])
    verdicts = {k: sum(r["synth"]["verdict"] == k for r in rows) for k in
                ("settled", "limit_cycle", "diverging", "undetermined")}
    refs = {k: sum(r["reference"]["verdict"] == k for r in rows) for k in
            ("settled", "limit_cycle", "diverging", "ambiguous")}
    print()
    print("| measure | reference on its own horizon | reference rerun 4x longer where they differ | goal |")
    print("|---|---|---|---|")
    print(f"| loops (seed {args.seed}) | {n}; synth: {verdicts}; reference: {refs} | | >= 100 |")
    for (label, one, goal), (_, two, _) in zip(_summary(comps), _summary(settled_by_longer), strict=True):
        print(f"| {label} | {one} | {two} | {goal} |")
    print(f"| time per loop, synth (median / p95 / total) | {np.median(ts):.3f} / {np.percentile(ts, 95):.3f} / "
          f"{ts.sum():.1f} s | | |")
    print(f"| time per loop, reference (median / p95 / total) | {np.median(tr):.3f} / {np.percentile(tr, 95):.3f} / "
          f"{tr.sum():.1f} s | | |")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1, default=str))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
