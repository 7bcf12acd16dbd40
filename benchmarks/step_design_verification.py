"""Designs with step-response limits (``step_response``: overshoot, settling time, rise time) against an
independent reference: a dense grid of controllers whose steps come from the closed loop's poles and residues.

Problems (seeded, reproducible from ``(seed, index)``): plants of order 1-3 without delay (real poles
0.2-10 rad/s, sometimes a lightly damped pair, sometimes a minimum-phase zero; DC gain 0.5-5), a PI or a PID
with a fixed derivative filter, maximize the integral gain, under one to three step limits drawn from the
plant's own time scale, so that some problems are feasible and some are not.

The reference imports nothing from synth: the closed loop ``T = C G / (1 + C G)`` from the polynomials, its
unit step ``y(t) = T(0) + sum_i r_i e^(p_i t) / p_i`` from numpy's roots and the residues (``y(0+) = T(inf)``
checks them), sampled on 4,001 points
over ten times the slowest pole's time constant, the metrics by their definitions (overshoot over the final
value in percent, settling as the last exit from the band, rise from 10 % to 90 %). It calls a grid point
feasible with 1 % to spare on every limit (0.1 points of overshoot), so that its sampling does not decide.

For synth's design it reports: its status; whether the reference's step of the design meets the limits (0.05
points of overshoot and 0.5 % of time to spare for the reference's sampling: "false feasible" otherwise); the
objective against the grid's best ("within 1 %" counts synth's ki >= 0.99 of the best); "false infeasible"
where synth found no design and the grid holds feasible points.

Run:  python benchmarks/step_design_verification.py [--seed 0] [--n 40] [--json FILE]
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


# ------------------------------------------------------------------ problems


def problem(seed: int, index: int) -> dict[str, Any]:
    """One design problem as a spec dict, with the plant's polynomials under ``"_plant"``."""
    rng = np.random.default_rng([seed, index])
    order = int(rng.integers(1, 4))
    poles = list(-(10.0 ** rng.uniform(np.log10(0.2), 1.0, order)))
    den = np.poly(poles)
    if order >= 2 and rng.random() < 0.3:  # a lightly damped pair instead of two real poles
        wn, zeta = float(10.0 ** rng.uniform(-0.5, 1.0)), float(rng.uniform(0.2, 0.7))
        den = np.polymul(np.poly(poles[2:]), [1.0, 2 * zeta * wn, wn**2])
    num = np.array([1.0])
    if rng.random() < 0.3:
        num = np.array([1.0, float(10.0 ** rng.uniform(-0.3, 1.3))])
    dc = float(10.0 ** rng.uniform(np.log10(0.5), np.log10(5.0)))
    num = num * dc * den[-1] / num[-1]
    slow = float(np.min(np.abs(np.roots(den).real)))
    kind = "PI" if rng.random() < 0.7 else "PID"
    bounds: dict[str, list[float]] = {"kp": [0.0, float(10.0 / dc)], "ki": [0.0, float(1000.0 * slow / dc)]}
    if kind == "PID":
        bounds |= {"kd": [0.0, float(2.0 / dc / slow)], "tf": [0.01 / slow, 0.01 / slow]}
    limits: dict[str, float] = {}
    while not limits:
        if rng.random() < 0.8:
            limits["max_overshoot"] = float(rng.choice([2.0, 5.0, 10.0, 20.0]))
        if rng.random() < 0.5:
            limits["max_settling_time"] = float(rng.uniform(0.5, 6.0) * 4.0 / slow)
        if rng.random() < 0.3:
            limits["max_rise_time"] = float(rng.uniform(0.2, 2.0) / slow)
    spec = {"name": f"step_{seed}_{index}", "plant": {"tf": _tf_text(num, den)},
            "controller": {"type": kind, "bounds": bounds},
            "requirements": [{"type": "step_response", **limits}],
            "objective": {"maximize": "integral_gain"}}
    return {"spec": spec, "_plant": (num, den), "limits": limits, "kind": kind}


def _tf_text(num: np.ndarray, den: np.ndarray) -> str:
    def poly(p: np.ndarray) -> str:
        n = len(p) - 1
        return "(" + " + ".join(f"{c:.12g}*s^{n - i}" if n - i else f"{c:.12g}" for i, c in enumerate(p)) + ")"
    return f"{poly(num)}/{poly(den)}"


# ------------------------------------------------------------------ the reference (no synth imports)


def controller_polys(kind: str, p: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    if kind == "PI":
        return np.array([p["kp"], p["ki"]]), np.array([1.0, 0.0])
    kp, ki, kd, tf = p["kp"], p["ki"], p["kd"], p["tf"]
    return np.array([kp * tf + kd, kp + ki * tf, ki]), np.array([tf, 1.0, 0.0])


def step_metrics(num: np.ndarray, den: np.ndarray, kind: str, p: dict[str, float],
                 band: float = 0.02) -> dict[str, float] | None:
    """Overshoot (%), settling and rise time (s) of the closed loop's unit step; None when it is not stable."""
    cn, cd = controller_polys(kind, p)
    while cn.size > 1 and cd.size > 1 and cn[-1] == 0.0 and cd[-1] == 0.0:  # ki = 0: the integrator cancels
        cn, cd = cn[:-1], cd[:-1]
    ln, ld = np.polymul(cn, num), np.polymul(cd, den)
    closed = np.polyadd(ld, ln)
    closed = np.trim_zeros(closed, "f")
    roots = np.roots(closed)
    if roots.size == 0 or np.max(roots.real) >= -1e-9:
        return None
    final = float(np.polyval(ln, 0.0) / np.polyval(closed, 0.0))
    if abs(final) < 1e-12:
        return None  # no controller output at rest (kp = ki = 0): no step to measure
    # Y(s) = T(s)/s: y(t) = T(0) + sum r_i e^{p_i t}, r_i = L_num(p_i) / (p_i closed'(p_i))
    lnp = np.pad(ln, (closed.size - ln.size, 0))
    derivative = np.polyder(closed)
    residues = np.polyval(lnp, roots) / (roots * np.polyval(derivative, roots))
    horizon = 10.0 / float(np.min(-roots.real))
    t = np.linspace(0.0, horizon, 4001)
    y = final + np.real(np.exp(np.outer(t, roots)) @ residues)
    at_infinity = float(lnp[0] / closed[0])  # y(0+) = T(inf): 0 unless the loop is biproper
    if abs(y[0] - at_infinity) > 1e-6 * max(1.0, abs(final)) or not np.all(np.isfinite(y)):
        return None  # near-repeated poles: residues that do not cancel (left out of the grid)
    frac = y / final
    overshoot = max(0.0, 100.0 * (float(np.max(frac)) - 1.0))
    outside = np.flatnonzero(np.abs(frac - 1.0) > band)
    settling = 0.0 if outside.size == 0 else float(t[min(outside[-1] + 1, t.size - 1)])
    i10, i90 = np.argmax(frac >= 0.1), np.argmax(frac >= 0.9)
    rise = float(t[i90] - t[i10]) if frac.max() >= 0.9 else np.inf
    return {"max_overshoot": overshoot, "max_settling_time": settling, "max_rise_time": rise}


def meets(metrics: dict[str, float] | None, limits: dict[str, float], spare_pct: float, spare_rel: float) -> bool:
    if metrics is None:
        return False
    for key, bound in limits.items():
        if key == "max_overshoot":
            if metrics[key] > bound - spare_pct:
                return False
        elif metrics[key] > bound * (1.0 - spare_rel):
            return False
    return True


def reference(prob: dict[str, Any]) -> dict[str, Any]:
    """Best ki over a dense grid (PI: 60 x 60; PID: 24^3), every point feasible with 1 % to spare."""
    num, den = prob["_plant"]
    spec = prob["spec"]
    bounds = spec["controller"]["bounds"]
    free = [k for k, (lo, hi) in bounds.items() if lo < hi]

    def axis(lo: float, hi: float, n: int) -> np.ndarray:
        return np.unique(np.r_[np.linspace(lo, hi, n), hi * np.geomspace(1e-3, 1.0, n // 2)])

    n = 40 if len(free) == 2 else 16
    axes = [axis(*bounds[k], n) for k in free]
    best, feasible = None, 0
    for values in np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(free)):
        p = {k: float(v) for k, v in zip(free, values)} | {k: lo for k, (lo, hi) in bounds.items() if lo >= hi}
        if meets(step_metrics(num, den, prob["kind"], p), prob["limits"], 0.1, 0.01):
            feasible += 1
            if best is None or p["ki"] > best["ki"]:
                best = p
    return {"best": best, "feasible_points": feasible, "grid_points": int(np.prod([a.size for a in axes]))}


# ------------------------------------------------------------------ run


def run_one(seed: int, index: int) -> dict[str, Any]:
    from synth.design import design
    from synth.spec import parse_spec

    prob = problem(seed, index)
    t = time.perf_counter()
    ref = reference(prob)
    ref_time = time.perf_counter() - t
    spec = parse_spec(prob["spec"])
    t = time.perf_counter()
    result = design(spec)
    synth_time = time.perf_counter() - t
    row: dict[str, Any] = {"index": index, "kind": prob["kind"], "limits": prob["limits"], "status": result.status,
                           "synth_time": synth_time, "reference_time": ref_time, "reference": ref}
    num, den = prob["_plant"]
    if result.feasible:
        p = dict(result.controller.parameters)
        row["synth"] = p
        row["synth_meets"] = meets(step_metrics(num, den, prob["kind"], p), prob["limits"], -0.05, -0.005)
        if ref["best"] is not None:
            row["gap"] = 1.0 - p["ki"] / ref["best"]["ki"] if ref["best"]["ki"] > 0 else 0.0
    return row


def outcome(row: dict[str, Any]) -> str:
    if row["status"] == "feasible":
        return "agree feasible" if row["synth_meets"] else "FALSE FEASIBLE"
    if row["reference"]["feasible_points"]:
        return f"false {row['status']} (the grid holds feasible points)"
    return f"agree: no design ({row['status']})"


def summarize(rows: list[dict[str, Any]]) -> None:
    from collections import Counter

    counts = Counter(outcome(r) for r in rows)
    print(f"| measure | value |\n|---|---|\n| problems | {len(rows)} |")
    for name, count in sorted(counts.items()):
        print(f"| {name} | {count} |")
    gaps = [r["gap"] for r in rows if "gap" in r and r["synth_meets"]]
    if gaps:
        within = sum(g <= 0.01 for g in gaps)
        print(f"| objective within 1 % of the grid's best (or better) | {within} of {len(gaps)} |")
        print(f"| synth better than the grid's best by > 1 % | {sum(g < -0.01 for g in gaps)} |")
        print(f"| worst gap (synth worse) | {100 * max(gaps):.2f} % |")
    for key in ("synth_time", "reference_time"):
        ts = sorted(r[key] for r in rows)
        print(f"| {key.replace('_', ' ')} median / p95 [s] | {statistics.median(ts):.2f} / "
              f"{ts[int(0.95 * (len(ts) - 1))]:.2f} |")
    for r in rows:
        if outcome(r) != "agree feasible" or r.get("gap", 0.0) > 0.01:
            if not outcome(r).startswith("agree: no design"):
                print(f"- #{r['index']} {r['kind']} {r['limits']}: {outcome(r)}, gap "
                      f"{100 * r.get('gap', float('nan')):.2f} %, synth {r.get('synth')}, grid best "
                      f"{r['reference']['best']}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--start", type=int, default=0)
    parser.add_argument("--n", type=int, default=40)
    parser.add_argument("--json", metavar="FILE", help="write one JSON row per problem")
    args = parser.parse_args()
    rows = []
    for index in range(args.start, args.start + args.n):
        row = run_one(args.seed, index)
        rows.append(row)
        print(f"#{index} {row['kind']} {outcome(row)} gap {100 * row.get('gap', float('nan')):.2f} % "
              f"synth {row['synth_time']:.1f} s, reference {row['reference_time']:.1f} s", flush=True)
        if args.json:
            with open(args.json, "a", encoding="utf-8") as fh:
                fh.write(json.dumps(row, default=float) + "\n")
    summarize(rows)


if __name__ == "__main__":
    main()
