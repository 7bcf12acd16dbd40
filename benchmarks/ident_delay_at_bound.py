"""`synth identify --delay fit` where the best delay is 0: whole CLI commands, baseline and current in one run.

Random plants fitted with a delay, in three kinds: "bound", a plant without a delay in the structure of the truth (a
first-order lag ``K/(T*s+1)`` or two real poles ``k/((s+p1)*(s+p2))``), whose best delay is 0 plus the noise's share,
below 0 (held at its bound 0) in about half of them; "lead", the same plants with a zero far above their poles, fitted
without it, whose best delay is below 0 (the bound holds); "ctl", the plants of "bound" behind a true delay of 1-5
samples (no bound active: the control). A square wave of random half-period, 1 % output noise, 2,000-60,000 samples at
1 or 5 ms, written as a CSV and identified by ``python -m synth identify ... --structure S --delay fit --average
none`` in a fresh process, once with each checkout (``--baseline-ref``: a ``git worktree``). Each answer is judged by
an independent reference written here from the model's definition (scipy only): the sampled model with the input held
between samples and the delay's fraction of a sample (``scipy.signal.lfilter`` on the partial fractions), fitted by
``scipy.optimize.least_squares`` with the delay bounded at 0, from the truth. Reported: exit code, solver status,
iterations, wall time, the fitted delay and the SSR of the reported model above the reference's optimum.

Run:  python benchmarks/ident_delay_at_bound.py [--cases 12] [--seed 0] [--baseline-ref HEAD~1]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import optimize, signal

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.cli_speed import baseline_checkout, remove_checkout  # noqa: E402
from synth.ident.simulate import simulate_plant  # noqa: E402
from synth.plant import Plant  # noqa: E402

STRUCTURES = {1: "K/(T*s+1)", 2: "k/((s+p1)*(s+p2))"}


KINDS = ("bound", "lead", "ctl")


def case(seed: int, index: int) -> dict:
    """The plant, record and structure of case ``index``: ``order`` 1 or 2 and ``kind`` (:data:`KINDS`) alternate."""
    rng = np.random.default_rng([seed, index])
    order = 1 + index % 2
    kind = KINDS[(index // 2) % 3]
    control = kind == "ctl"
    dt = float(rng.choice([0.001, 0.005]))
    n = int(rng.choice([2000, 12000, 30000, 60000]))
    lead = rng.uniform(0.05, 0.3) if kind == "lead" else 0.0  # the zero's time constant over the fast pole's
    if order == 1:
        T = rng.uniform(0.05, 1.0)
        num, den, slow = np.array([2.0 * lead * T, 2.0]), np.array([T, 1.0]), T
    else:
        p1, p2 = rng.uniform(1.0, 5.0), rng.uniform(10.0, 40.0)
        num, den, slow = 2.0 * p1 * p2 * np.array([lead / p2, 1.0]), np.polymul([1.0, p1], [1.0, p2]), 1.0 / p1
    delay = float(rng.integers(1, 6)) * dt + float(rng.uniform(0.1, 0.9)) * dt if control else 0.0
    hold = max(5, int(rng.uniform(0.5, 2.0) * slow / dt))
    t = np.arange(n) * dt
    u = ((np.arange(n) // hold) % 2).astype(float)
    y = simulate_plant(Plant(num, den, delay), t, u)
    y = y + 0.01 * np.std(y) * rng.normal(size=n)
    return {"order": order, "kind": kind, "control": control, "dt": dt, "n": n, "t": t, "u": u, "y": y, "num": num,
            "den": den, "delay": delay}


# ------------------------------------------------------------------ the independent reference


def _first_order(gain: float, pole: float, w: np.ndarray, dt: float, d: float) -> np.ndarray:
    """``gain/(s + pole) e^(-d s)`` applied to ``w`` held between samples, sampled exactly, from rest."""
    m, f = int(np.floor(d / dt + 1e-12)), d - np.floor(d / dt + 1e-12) * dt
    a = np.exp(-pole * dt)
    late = gain / pole * (1.0 - np.exp(-pole * (dt - f)))
    early = gain / pole * np.exp(-pole * (dt - f)) * (1.0 - np.exp(-pole * f))
    shifted = np.concatenate([np.zeros(m), w])[:w.size]
    v = late * shifted + early * np.concatenate([[0.0], shifted[:-1]])
    return signal.lfilter([0.0, 1.0], [1.0, -a], v)


def model(order: int, x: np.ndarray, w: np.ndarray, dt: float) -> np.ndarray:
    """The structure's output: ``x`` = (K, T, delay, offset) or (k, p1, p2, delay, offset)."""
    if order == 1:
        K, T, d, b = x
        return b + _first_order(K / T, 1.0 / T, w, dt, d)
    k, p1, p2, d, b = x
    if abs(p1 - p2) < 1e-9 * max(p1, p2):
        p2 = p1 * (1 + 1e-9)
    return b + _first_order(k / (p2 - p1), p1, w, dt, d) + _first_order(k / (p1 - p2), p2, w, dt, d)


def reference(c: dict, first: int = 0) -> tuple[np.ndarray, float]:
    """The bounded least-squares optimum over the samples from ``first`` on (simulated from rest at the record's
    start; from the truth's poles and gain) and its SSR."""
    w, dt = c["u"] - c["u"][0], c["dt"]
    if c["order"] == 1:
        T = c["den"][0]
        x0, lb, scale = [c["num"][-1], T, c["delay"] + 0.5 * dt, 0.0], [-np.inf, 1e-9, 0.0, -np.inf], [1, T, dt, 1]
    else:
        p = np.sort(-np.roots(c["den"]).real)
        x0 = [c["num"][-1], p[0], p[1], c["delay"] + 0.5 * dt, 0.0]
        lb, scale = [-np.inf, 1e-9, 1e-9, 0.0, -np.inf], [x0[0], p[0], p[1], dt, 1]
    y = c["y"]
    best = None
    for start in (x0, [*x0[:-2], 0.0, x0[-1]]):
        r = optimize.least_squares(lambda x: (y - model(c["order"], x, w, dt))[first:], x0=start, bounds=(lb, np.inf),
                                   x_scale=scale, xtol=1e-13, ftol=1e-14, gtol=1e-13)
        if best is None or r.cost < best.cost:
            best = r
    return best.x, 2.0 * float(best.cost)


# ------------------------------------------------------------------ the CLI runs


def run_identify(checkout: Path, csv: Path, structure: str, out: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(checkout), "SYNTH_IDENTIFY_CACHE": "off"}
    cmd = [sys.executable, "-m", "synth", "identify", "--data", str(csv), "--time", "t", "--input", "u", "--output",
           "y", "--structure", structure, "--delay", "fit", "--average", "none", "--no-figures", "--quiet",
           "--out", str(out), "--json", str(out / "fit.json"), "--force"]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=str(checkout), capture_output=True, text=True)
    wall = time.perf_counter() - t0
    data = json.loads((out / "fit.json").read_text()) if proc.returncode == 0 else {}
    return {"code": proc.returncode, "wall": wall, "data": data, "err": proc.stderr.strip().splitlines()[-1:]}


def first_fitted(c: dict, data: dict) -> int:
    """The first sample the fit weighed (a start it judged not at rest is left out: ``start_state.first``)."""
    first = float(data.get("solver", {}).get("start_state", {}).get("first", 0.0))
    return round(first / c["dt"])


def excess(c: dict, data: dict, ssr_ref: float) -> float:
    """SSR of the reported model over the reference's optimum on the samples the fit weighed, minus 1."""
    p, w = data["parameters"], c["u"] - float(data["input_reference"])
    x = [p["K"], p["T"]] if c["order"] == 1 else [p["k"], p["p1"], p["p2"]]
    x += [float(data["delay"]), 0.0]
    yhat = model(c["order"], np.array(x), w, c["dt"])
    e = (c["y"] - yhat)[first_fitted(c, data):]
    ssr = float(np.sum((e - np.mean(e)) ** 2))  # the offset at its least-squares value
    return ssr / ssr_ref - 1.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", type=int, default=12)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--baseline-ref", default="HEAD~1")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="delay_bound_"))
    base = baseline_checkout(args.baseline_ref, tmp)
    sides = {"baseline": base, "current": ROOT}
    rows = []
    try:
        print(f"{'#':>3} {'kind':<9}{'n':>7}{'dt':>7}  " + "  ".join(
            f"{s + ': exit status iterations wall SSR-excess delay':<72}" for s in sides))
        for i in range(args.cases):
            c = case(args.seed, i)
            csv = tmp / f"case{i}.csv"
            np.savetxt(csv, np.c_[c["t"], c["u"], c["y"]], delimiter=",", header="t,u,y", comments="", fmt="%.10g")
            refs: dict[int, float] = {}
            row = {"case": i, "order": c["order"], "kind": c["kind"], "n": c["n"], "dt": c["dt"]}
            cells = []
            for side, checkout in sides.items():
                r = run_identify(checkout, csv, STRUCTURES[c["order"]], tmp / f"{side}{i}")
                solver = r["data"].get("solver", {})
                ex = float("nan")
                if r["code"] == 0:
                    first = first_fitted(c, r["data"])
                    if first not in refs:
                        refs[first] = reference(c, first)[1]
                    ex = excess(c, r["data"], refs[first])
                d = float(r["data"].get("delay", np.nan))
                row[side] = {"code": r["code"], "wall": r["wall"], "status": solver.get("status", r["err"]),
                             "iterations": solver.get("iterations"), "excess": ex, "delay": d}
                cells.append(f"{r['code']} {str(solver.get('status', '-'))[:27]:<27} {solver.get('iterations')!s:>5}"
                             f" {r['wall']:6.1f} s {ex:+9.1e} d={d / c['dt']:.2f} dt")
            rows.append(row)
            kind = f"{c['kind']} o{c['order']}"
            print(f"{i:>3} {kind:<9}{c['n']:>7}{c['dt']:>7}  " + "  ".join(f"{x:<72}" for x in cells), flush=True)
        for side in sides:
            for label in KINDS:
                rs = [r[side] for r in rows if r["kind"] == label]
                ok = sum(r["code"] == 0 and r["excess"] <= 1e-6 for r in rs)
                walls = sorted(r["wall"] for r in rs)
                print(f"{side:<9} {label:<6} at the optimum (SSR within 1e-6) {ok}/{len(rs)}; exit 0 "
                      f"{sum(r['code'] == 0 for r in rs)}/{len(rs)}; wall median {np.median(walls):.1f} s, "
                      f"max {walls[-1]:.1f} s" if rs else "")
    finally:
        remove_checkout(base)


if __name__ == "__main__":
    main()
