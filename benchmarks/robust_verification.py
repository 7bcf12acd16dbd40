"""Randomized check of synth's robust (multi-plant) designs against an independent reference.

For each seeded problem of ``benchmarks/robust_problems.py`` (a spec whose plant has ``variants``): ``synth.design``
(CPU-time limit, ``SYNTH_JOBS=1``), the reference search of ``benchmarks/robust_reference.py`` (every requirement on
every plant from its definition, exact delay, dense grid, stability counted per plant), the reference's dense check
of synth's design on every plant, and ``synth.check`` of synth's design compared with the reference plant by plant.
Outcomes:

- ``false infeasible``: synth said infeasible, the reference holds a point that passes its dense check on every
  plant (``synth.check`` of that point is recorded: does synth agree it is feasible?);
- ``false feasible``: synth's design fails the reference's dense check (slack below ``-TOL``) on some plant; the
  record names every failing plant and requirement with the reference's value and slack;
- ``undetermined``: synth answered "undetermined" or hit the CPU-time limit; ``declined``: one of synth's one-line
  errors; ``error``: any other exception (a crash);
- ``agree feasible`` (objective gap measured), ``agree infeasible`` (evidence only), ``ref missed`` (synth's design
  passes the reference check, the reference found nothing).

Objective gap: the reference's nominal-plant objective of synth's design against the reference's best,
``(best - synth)/best`` for a maximized objective, in linear magnitude for a minimized dB objective (positive: synth
worse). Check agreement: for synth's design, ``synth.check``'s per-plant values and slacks against the reference's
on the same plant (relative differences above ``1e-3`` listed; dB values compared as linear magnitudes).

Run: ``nice -n 5 python benchmarks/robust_verification.py --n 100 --seed 7 --time-limit 60 --json out.jsonl``;
``--summarize out.jsonl`` re-reads records. Specs of every disagreement are written as YAML next to the JSON file.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import time
import traceback
import warnings
from pathlib import Path
from typing import Any

import numpy as np

os.environ.setdefault("SYNTH_JOBS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.robust_problems import RobustProblem, generate
from benchmarks.robust_reference import MAXIMIZED, check_point, reference

__all__ = ["SYNTH_ERRORS", "TOL", "classify", "compare_check", "objective_gap", "run_problem", "summarize"]

SYNTH_ERRORS = ("SynthError", "SpecError", "ModelError", "DataError")
TOL = 1e-3
"""Slack (nepers, radians) by which synth's design may miss in the reference check."""
REL = 1e-3
"""Relative difference above which a check value is listed as a disagreement."""


class _TimeoutError(BaseException):
    """The CPU-time limit: a ``BaseException``, so that a design stage's ``except Exception`` does not swallow it
    (with an ``Exception`` the limit was lost: 375 s of CPU against a 60 s limit), re-raised every second until
    the design returns."""


def _alarm(signum: int, frame: Any) -> None:
    raise _TimeoutError()


def _plants(p: RobustProblem | dict[str, Any]) -> list[tuple[str, list[float], list[float], float]]:
    plants = p.plants if isinstance(p, RobustProblem) else p["plants"]
    return [(q.label, q.num, q.den, q.delay) if not isinstance(q, dict) else (q["label"], q["num"], q["den"],
                                                                            q["delay"]) for q in plants]


def objective_gap(spec: dict[str, Any], ref_obj: float, synth_obj: float) -> float:
    """Relative gap of synth's objective to the reference's best (positive: synth worse).

    Examples
    --------
    >>> objective_gap({"objective": {"maximize": "bandwidth"}}, 10.0, 9.0)
    0.1
    >>> round(objective_gap({"objective": {"minimize": "peak_sensitivity"}}, 3.0, 3.0), 12)
    0.0
    """
    name = next(iter(spec["objective"].values()))
    if name in MAXIMIZED:
        if not np.isfinite(ref_obj):
            return 0.0 if not np.isfinite(synth_obj) else 1.0
        return float((ref_obj - synth_obj) / ref_obj) if ref_obj > 0 else 0.0
    return float(10 ** ((synth_obj - ref_obj) / 20) - 1.0)


def _rel(a: float, b: float, db: bool) -> float:
    if a is None or b is None:
        return np.nan
    a, b = float(a), float(b)
    if a == b:
        return 0.0
    if not (np.isfinite(a) and np.isfinite(b)):
        return np.inf
    if db:
        return float(abs(10 ** ((a - b) / 20) - 1))
    return float(abs(a - b) / max(abs(a), abs(b), 1e-300))


def compare_check(spec: dict[str, Any], check: dict[str, Any], ref: dict[str, Any]) -> list[dict[str, Any]]:
    """``synth.check``'s per-plant values and slacks against the reference's: the differences above ``REL``.

    ``check`` is ``synth.check(...).to_dict()``, ``ref`` the reference's ``RobustEvaluation.to_dict()``.

    Examples
    --------
    >>> spec = {"requirements": [{"type": "bandwidth", "min": 1}]}
    >>> chk = {"per_plant": {"nominal": [{"type": "stability"}, {"type": "bandwidth", "value": 2.0, "slack": 0.69,
    ...                                    "unit": "rad/s", "details": {}}]}}
    >>> ref = {"per_plant": {"nominal": {"stable": True, "values": {"0:bandwidth": 2.1}, "slacks": {}}}}
    >>> [round(d["rel"], 4) for d in compare_check(spec, chk, ref)]
    [0.0476]
    """
    out: list[dict[str, Any]] = []
    for label, rows in (check.get("per_plant") or {}).items():
        rp = (ref.get("per_plant") or {}).get(label)
        if rp is None or not rp["stable"]:
            continue
        reqs = [r for r in rows if r["type"] != "stability"]
        for k, (row, r) in enumerate(zip(reqs, spec["requirements"])):
            key = f"{k}:{r['type']}"
            if row.get("value") is None or isinstance(row.get("value"), str):
                out.append({"plant": label, "requirement": key, "what": "value", "synth": row.get("value"),
                            "reference": rp["values"].get(key), "rel": np.inf})
                continue
            pairs: list[tuple[str, Any, Any, bool]] = []
            if r["type"] == "margins":
                d = row.get("details") or {}
                if "gain_margin_db" in r:
                    up, low = d.get("gain_margin_db"), d.get("lower_gain_margin_db")
                    near = None if up is None else min(float(up), -float(low) if low is not None else np.inf)
                    pairs.append(("gain margin dB (nearer side)", near, rp["values"].get(key + ":gm"), False))
                if "phase_margin_deg" in r:
                    pairs.append(("phase margin deg", d.get("phase_margin_deg"), rp["values"].get(key + ":pm"), False))
                if "delay_margin" in r:
                    pairs.append(("delay margin s", d.get("delay_margin"), rp["values"].get(key + ":dm"), False))
            else:
                pairs.append(("value", row["value"], rp["values"].get(key), row.get("unit") == "dB"))
            for what, a, b, db in pairs:
                rel = _rel(a, b, db)
                if not rel <= REL:
                    out.append({"plant": label, "requirement": key, "what": what, "synth": a, "reference": b,
                                "rel": rel})
            sa, sb = row.get("slack"), rp["slacks"].get(key)
            if sa is not None and sb is not None and np.isfinite(sa) and np.isfinite(sb) and abs(sa - sb) > REL:
                out.append({"plant": label, "requirement": key, "what": "slack", "synth": sa, "reference": sb,
                            "rel": abs(sa - sb)})
    return out


def run_problem(p: RobustProblem, *, time_limit: float = 60.0, budget: float = 1.0,
                ref_seconds: float = 120.0) -> dict[str, Any]:
    """Design, reference and cross-checks of one problem: a JSON-ready record."""
    import synth

    rec: dict[str, Any] = {**p.to_dict(), "controller": p.spec["controller"]["type"],
                           "requirements": [r["type"] for r in p.spec["requirements"]],
                           "objective": p.spec.get("objective")}
    plants = _plants(p)
    t0, c0 = time.perf_counter(), time.process_time()
    old = signal.signal(signal.SIGPROF, _alarm)
    signal.setitimer(signal.ITIMER_PROF, time_limit, 1.0)
    d = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            d = synth.design(synth.parse_spec(p.spec))
        rec["synth_status"] = d.status
        rec["synth_verdict"] = d.verdict
        dd = d.to_dict()
        rec["synth_objective"] = dd.get("objective")
        rec["synth_optimality"] = dd.get("optimality")
    except _TimeoutError:
        rec["synth_status"] = "timeout"
    except Exception as e:
        rec["synth_status"] = "error"
        rec["synth_error"] = f"{type(e).__name__}: {e}"
        rec["synth_traceback"] = traceback.format_exc()
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, old)
    rec["synth_seconds"] = time.perf_counter() - t0
    rec["synth_cpu_seconds"] = time.process_time() - c0
    c0 = time.process_time()
    r = reference(plants, p.spec, budget=budget, seed=p.index, max_seconds=ref_seconds)
    rec["ref_seconds"], rec["ref_cpu_seconds"] = r.seconds, time.process_time() - c0
    rec["ref_feasible"], rec["ref_method"], rec["ref_evaluations"] = r.feasible, r.method, r.evaluations
    rec["ref_best"] = None if r.best is None else r.best.to_dict()
    if d is not None and d.feasible:
        params = dict(d.controller.parameters)
        rec["synth_params"] = params
        e = check_point(plants, p.spec, params)
        rec["synth_in_reference"] = e.to_dict()
        rec["synth_passes_reference"] = e.feasible(TOL)
        rec["synth_failures"] = e.failures(TOL)
        if not e.stable:
            rec["synth_stable_with_eps_1e-12"] = check_point(plants, p.spec, params, 1e-12).stable
        if p.spec.get("objective") and r.feasible and e.objective is not None and r.best.objective is not None:
            rec["objective_gap"] = objective_gap(p.spec, r.best.objective, e.objective)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                c = synth.check(synth.parse_spec(p.spec), d.controller).to_dict()
            rec["check_feasible"] = c.get("feasible")
            rec["check_differences"] = compare_check(p.spec, c, rec["synth_in_reference"])
        except Exception as exc:
            rec["check_error"] = f"{type(exc).__name__}: {exc}"
            rec["check_traceback"] = traceback.format_exc()
    if r.feasible and rec["synth_status"] != "feasible":
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                c = synth.check(synth.parse_spec(p.spec), synth.Controller(p.spec["controller"]["type"],
                                                                           r.best.params)).to_dict()
            rec["synth_check_of_ref_point"] = bool(c["feasible"])
            rec["synth_check_of_ref_point_failing"] = [
                {"plant": row.get("plant"), "type": row["type"], "value": row.get("value"), "slack": row.get("slack"),
                 "message": row.get("message")} for row in c["requirements"] if not row.get("met")]
        except Exception as exc:
            rec["synth_check_of_ref_point"] = f"{type(exc).__name__}: {exc}"
    rec["outcome"] = classify(rec)
    return rec


def classify(rec: dict[str, Any]) -> str:
    """The outcome of a record (see the module docstring).

    Examples
    --------
    >>> classify({"synth_status": "infeasible", "ref_feasible": True})
    'false infeasible'
    >>> classify({"synth_status": "feasible", "synth_passes_reference": False, "ref_feasible": True})
    'false feasible'
    """
    st = rec["synth_status"]
    if st == "error":
        if rec.get("synth_error", "").split(":")[0] in SYNTH_ERRORS:
            return "declined (ref feasible)" if rec["ref_feasible"] else "declined"
        return "error"
    if st in ("timeout", "undetermined"):
        return "undetermined (ref feasible)" if rec["ref_feasible"] else "undetermined"
    if st == "feasible":
        if not rec["synth_passes_reference"]:
            return "false feasible"
        return "agree feasible" if rec["ref_feasible"] else "ref missed"
    return "false infeasible" if rec["ref_feasible"] else "agree infeasible"


OUTCOMES = ("agree feasible", "agree infeasible", "false infeasible", "false feasible", "ref missed", "error",
            "declined", "declined (ref feasible)", "undetermined", "undetermined (ref feasible)")


def summarize(records: list[dict[str, Any]]) -> list[tuple[str, str]]:
    """Rows ``(measure, value)`` of the summary table.

    Examples
    --------
    >>> summarize([{"outcome": "agree infeasible", "synth_seconds": 1.0, "ref_seconds": 2.0}])[0]
    ('problems', '1')
    """
    n = len(records)
    out = [r["outcome"] for r in records]
    rows = [("problems", str(n))]
    for k in OUTCOMES:
        c = out.count(k)
        rows.append((k, f"{c} ({100 * c / max(n, 1):.1f} %)"))
    gaps = np.array([r["objective_gap"] for r in records if "objective_gap" in r and r["outcome"] == "agree feasible"])
    if gaps.size:
        rows.append(("objective within 1 % of the reference's best", f"{np.mean(gaps <= 0.01) * 100:.1f} % of "
                                                                      f"{gaps.size}"))
        rows.append(("worst objective gap (synth worse)", f"{gaps.max() * 100:.2f} %"))
        rows.append(("synth better than the reference by > 1 %", str(int(np.sum(gaps < -0.01)))))
    diffs = [r for r in records if r.get("check_differences")]
    rows.append(("designs whose synth.check differs from the reference by > 1e-3 on some plant",
                 f"{len(diffs)} of {sum(1 for r in records if 'check_differences' in r)}"))
    for key, label in (("synth_seconds", "synth design"), ("ref_seconds", "reference")):
        t = np.array([r[key] for r in records])
        if t.size:
            rows.append((f"{label} wall time, median / p95 [s]", f"{np.median(t):.2f} / {np.percentile(t, 95):.2f}"))
    return rows


def _yaml(spec: dict[str, Any]) -> str:
    import yaml

    return yaml.safe_dump(spec, sort_keys=False, default_flow_style=None, width=120)


def main() -> None:
    """Command line: run problems or summarize stored records."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--time-limit", type=float, default=60.0, help="per synth.design call [CPU s]")
    ap.add_argument("--budget", type=float, default=1.0, help="scales the reference's search")
    ap.add_argument("--ref-seconds", type=float, default=120.0, help="wall-time cap of the reference search")
    ap.add_argument("--json", type=Path, help="records as JSON lines (streamed)")
    ap.add_argument("--summarize", type=Path, nargs="+", help="only re-read JSON-lines files")
    args = ap.parse_args()
    records: list[dict[str, Any]] = []
    if args.summarize:
        for path in args.summarize:
            records += [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
        for rec in records:
            rec["outcome"] = classify(rec)
        records.sort(key=lambda r: r["index"])
    else:
        fh = args.json.open("w") if args.json else None
        for p in generate(args.n, args.seed, args.start):
            rec = run_problem(p, time_limit=args.time_limit, budget=args.budget, ref_seconds=args.ref_seconds)
            records.append(rec)
            print(f"#{p.index} {rec['outcome']}: {rec['controller']} {rec['requirements']} {rec['objective']} "
                  f"synth {rec['synth_seconds']:.1f} s, reference {rec['ref_seconds']:.1f} s"
                  f"{' gap %.2f %%' % (100 * rec['objective_gap']) if 'objective_gap' in rec else ''}", flush=True)
            if fh:
                fh.write(json.dumps(rec, default=float) + "\n")
                fh.flush()
    print("\n| measure | value |\n|---|---|")
    for k, v in summarize(records):
        print(f"| {k} | {v} |")
    outdir = (args.summarize[0] if args.summarize else args.json or Path("/tmp/robust/x")).parent / "specs"
    for r in records:
        bad = r["outcome"] not in ("agree feasible", "agree infeasible", "undetermined") or \
            r.get("objective_gap", 0) > 0.01 or r.get("check_differences") or r.get("check_error")
        if not bad:
            continue
        outdir.mkdir(parents=True, exist_ok=True)
        (outdir / f"{r['spec']['name']}.yaml").write_text(_yaml(r["spec"]))
        print(f"- #{r['index']} {r['outcome']}: {r['controller']} {r['features']} {r['requirements']}"
              f" synth={r.get('synth_params') or r.get('synth_error') or r['synth_status']}"
              f" ref={None if r['ref_best'] is None else r['ref_best']['params']}"
              f" synth.check(ref point)={r.get('synth_check_of_ref_point')}"
              f" gap={r.get('objective_gap')} failures={r.get('synth_failures')}"
              f" check differences={r.get('check_differences')} {r.get('check_error') or ''}")


if __name__ == "__main__":
    main()
