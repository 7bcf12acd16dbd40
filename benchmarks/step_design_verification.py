"""Designs with step-response limits (``step_response``: overshoot, settling time, rise time) against an
independent reference: a dense grid of controllers whose steps come from the closed loop's poles and residues.

Problems (seeded, reproducible from ``(seed, index)``): plants of order 1-3 (real poles 0.2-10 rad/s,
sometimes a lightly damped pair, sometimes a minimum-phase zero; DC gain 0.5-5), a PI or a PID with a fixed
derivative filter, maximize the integral gain, under one to three step limits drawn from the plant's own time
scale. With ``--delay-share S`` a strictly proper plant gets a delay of 0.02-0.5 times its slowest time
constant with probability S (from a random stream of its own: the problems are otherwise the same).

The reference imports nothing from synth: the closed loop ``T = C G / (1 + C G)`` from the polynomials, its
unit step ``y(t) = T(0) + sum_i r_i e^(p_i t) / p_i`` from numpy's roots and the residues (``y(0+) = T(inf)``
checks them), sampled on 4,001 points
over ten times the slowest pole's time constant, the metrics by their definitions (overshoot over the final
value in percent, settling as the last exit from the band, rise from 10 % to 90 %). It calls a grid point
feasible with 1 % to spare on every limit (0.1 points of overshoot), so that its sampling does not decide.

A delayed loop's step comes from ``benchmarks/delayed_step_reference.py`` (written apart from synth and from
this file's other reference): the grid by a fixed-step simulation of all its controllers at once (a point counts
when its last quarter is within 1 % of the final value and it meets the limits with 1 % to spare), the grid's
best confirmed, and synth's design checked, by the method of steps with ``solve_ivp`` over a horizon doubled
until the step has settled, stability by the Nyquist count.

For synth's design it reports: its status; whether the reference's step of the design meets the limits (0.05
points of overshoot and 0.5 % of time to spare for the reference's sampling: "false feasible" otherwise); the
objective against the grid's best ("within 1 %" counts synth's ki >= 0.99 of the best); "false infeasible"
where synth found no design and the grid holds feasible points.

Run:  python benchmarks/step_design_verification.py [--seed 0] [--n 40] [--json FILE] [--delay-share 0.5]
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


def problem(seed: int, index: int, delay_share: float = 0.0) -> dict[str, Any]:
    """One design problem as a spec dict, with the plant's polynomials under ``"_plant"`` and its delay under
    ``"delay"``. ``delay_share``: the probability that a strictly proper plant gets a delay of 0.02-0.5 times its
    slowest time constant (drawn from a stream of its own, so the rest of the problem is the same as without)."""
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
    delay = 0.0
    delay_rng = np.random.default_rng([seed, index, 7])
    if delay_rng.random() < delay_share and num.size < den.size:
        delay = float(10.0 ** delay_rng.uniform(np.log10(0.02), np.log10(0.5)) / slow)
    spec = {"name": f"step_{seed}_{index}", "plant": {"tf": _tf_text(num, den), "delay": delay},
            "controller": {"type": kind, "bounds": bounds},
            "requirements": [{"type": "step_response", **limits}],
            "objective": {"maximize": "integral_gain"}}
    return {"spec": spec, "_plant": (num, den), "delay": delay, "limits": limits, "kind": kind, "slow": slow}


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


def delayed_metrics(num: np.ndarray, den: np.ndarray, delay: float, kind: str, p: dict[str, float],
                    slow: float, band: float = 0.02) -> dict[str, float] | None:
    """The metrics of a delayed loop's step by the method of steps (``delayed_step_reference.dde_step``), over a
    horizon doubled (up to four times from 20 slow time constants plus 20 delays) until the last quarter stays
    within a fifth of the band; None when the loop is not stable or the step never settles there."""
    from benchmarks.delayed_step_reference import dde_step, final_value, stable, step_metrics_from_samples

    if not stable(num, den, delay, kind, p):
        return None
    final = final_value(num, den, kind, p)
    if abs(final) < 1e-12:
        return None
    horizon = 20.0 / slow + 20.0 * delay
    for _ in range(5):
        out = dde_step(num, den, delay, kind, p, horizon, 8001)
        if out is None:
            return None
        t, y = out
        if np.all(np.abs(y[t >= 0.75 * horizon] / final - 1.0) <= band / 5):
            return step_metrics_from_samples(t, y, final, band)
        horizon *= 2.0
    return None


def _delayed_grid_best(prob: dict[str, Any], points: list[dict[str, float]]) -> tuple[dict[str, float] | None, int]:
    """The best ki among ``points`` whose delayed steps (``grid_steps``, one fixed-step simulation of all of
    them) are settled over their last quarter and meet the limits with 1 % to spare, confirmed by the method of
    steps (the next best is tried when it is not: at most ten); and how many met them on the grid."""
    from benchmarks.delayed_step_reference import final_value, grid_steps, step_metrics_from_samples

    num, den = prob["_plant"]
    delay, slow, kind = prob["delay"], prob["slow"], prob["kind"]
    horizon = 40.0 / slow + 40.0 * delay
    passing = []
    # in chunks of similar speed (the fixed step follows the fastest loop of a chunk): by the high-frequency gain
    points = sorted(points, key=lambda p: p["kp"] + p.get("kd", 0.0) / p.get("tf", 1.0))
    for start in range(0, len(points), 500):
        chunk = points[start:start + 500]
        ys = grid_steps(num, den, delay, kind, chunk, horizon, 4001)
        t = np.linspace(0.0, horizon, ys.shape[1])
        for p, y in zip(chunk, ys):
            final = final_value(num, den, kind, p)
            if not np.all(np.isfinite(y)) or abs(final) < 1e-12 \
                    or np.any(np.abs(y[t >= 0.75 * horizon] / final - 1.0) > 0.01):
                continue
            if meets(step_metrics_from_samples(t, y, final), prob["limits"], 0.1, 0.01):
                passing.append(p)
    passing.sort(key=lambda p: -p["ki"])
    for p in passing[:10]:
        if meets(delayed_metrics(num, den, delay, kind, p, slow), prob["limits"], 0.05, 0.005):
            return p, len(passing)
    return None, len(passing)


def reference(prob: dict[str, Any]) -> dict[str, Any]:
    """Best ki over a dense grid (PI: 60 x 60; PID: 24^3, with a delay 15^3), every point feasible with 1 % to
    spare; with a delay by :func:`_delayed_grid_best`."""
    num, den = prob["_plant"]
    spec = prob["spec"]
    bounds = spec["controller"]["bounds"]
    free = [k for k, (lo, hi) in bounds.items() if lo < hi]

    def axis(lo: float, hi: float, n: int) -> np.ndarray:
        return np.unique(np.r_[np.linspace(lo, hi, n), hi * np.geomspace(1e-3, 1.0, n // 2)])

    n = 40 if len(free) == 2 else 16 if prob["delay"] == 0 else 10  # the delayed grid is simulated: 15^3 for a PID
    axes = [axis(*bounds[k], n) for k in free]
    grid = [{k: float(v) for k, v in zip(free, values)} | {k: lo for k, (lo, hi) in bounds.items() if lo >= hi}
            for values in np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(free))]
    if prob["delay"] > 0:
        best, feasible = _delayed_grid_best(prob, grid)
        return {"best": best, "feasible_points": feasible, "grid_points": len(grid)}
    best, feasible = None, 0
    for p in grid:
        if meets(step_metrics(num, den, prob["kind"], p), prob["limits"], 0.1, 0.01):
            feasible += 1
            if best is None or p["ki"] > best["ki"]:
                best = p
    return {"best": best, "feasible_points": feasible, "grid_points": len(grid)}


# ------------------------------------------------------------------ run


def run_one(seed: int, index: int, delay_share: float = 0.0, stored: dict[str, Any] | None = None) -> dict[str, Any]:
    """One problem: the reference's grid (or ``stored``, a row of :func:`reference_row`: its ``reference`` and
    ``reference_time``) and synth's design, judged by the reference's own step."""
    from synth.design import design
    from synth.spec import parse_spec

    prob = problem(seed, index, delay_share)
    if stored is not None:
        assert (stored["seed"], stored["index"], stored["delay_share"]) == (seed, index, delay_share), stored
        ref, ref_time = stored["reference"], stored["reference_time"]
    else:
        t = time.perf_counter()
        ref = reference(prob)
        ref_time = time.perf_counter() - t
    spec = parse_spec(prob["spec"])
    t = time.perf_counter()
    result = design(spec)
    synth_time = time.perf_counter() - t
    row: dict[str, Any] = {"index": index, "kind": prob["kind"], "delay": prob["delay"], "limits": prob["limits"],
                           "status": result.status,
                           "synth_time": synth_time, "reference_time": ref_time, "reference": ref}
    num, den = prob["_plant"]
    if result.feasible:
        p = dict(result.controller.parameters)
        row["synth"] = p
        metrics = step_metrics(num, den, prob["kind"], p) if prob["delay"] == 0 else \
            delayed_metrics(num, den, prob["delay"], prob["kind"], p, prob["slow"])
        row["synth_meets"] = meets(metrics, prob["limits"], -0.05, -0.005)
        if ref["best"] is not None:
            row["gap"] = 1.0 - p["ki"] / ref["best"]["ki"] if ref["best"]["ki"] > 0 else 0.0
    return row


def reference_row(seed: int, index: int, delay_share: float = 0.0) -> dict[str, Any]:
    """The reference's grid result for one problem, to store (``--references-only``) and pass to :func:`run_one`."""
    t = time.perf_counter()
    ref = reference(problem(seed, index, delay_share))
    return {"seed": seed, "index": index, "delay_share": delay_share, "reference": ref,
            "reference_time": time.perf_counter() - t}


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
    parser.add_argument("--delay-share", type=float, default=0.0,
                        help="probability of a delay (strictly proper plants; 0.02-0.5 slow time constants)")
    parser.add_argument("--indices", type=int, nargs="+", help="these problems instead of --start/--n")
    parser.add_argument("--references-only", action="store_true",
                        help="write only the reference's rows (reference_row) to --json, for tests to reuse")
    args = parser.parse_args()
    indices = args.indices or range(args.start, args.start + args.n)
    if args.references_only:
        for index in indices:
            stored = reference_row(args.seed, index, args.delay_share)
            if args.json:
                with open(args.json, "a", encoding="utf-8") as fh:
                    fh.write(json.dumps(stored, default=float) + "\n")
        return
    rows = []
    for index in indices:
        row = run_one(args.seed, index, args.delay_share)
        rows.append(row)
        print(f"#{index} {row['kind']} {outcome(row)} gap {100 * row.get('gap', float('nan')):.2f} % "
              f"synth {row['synth_time']:.1f} s, reference {row['reference_time']:.1f} s", flush=True)
        if args.json:
            with open(args.json, "a", encoding="utf-8") as fh:
                fh.write(json.dumps(row, default=float) + "\n")
    summarize(rows)


if __name__ == "__main__":
    main()
