"""Structures with one pole and one zero more than the plant, fitted with a free delay (issue 16, items 1 and 2).

An engineer who does not know the order fits a structure that is too rich: the record pins down the plant's own
poles and gain, while the extra zero and pole cancel anywhere and trade with the delay. The right answer is a fit
to the noise with the plant's poles where they are and the cancelling pair marked weak, or an honest failure; a
fit far from the data, or a plant pole many standard errors off without a weak mark, is a wrong answer.

Each case draws, from its seed, a plant of order 1 or 2 (real poles log-uniform 0.3-20 rad/s, static gain
0.3-5), a delay (none in half of the cases, else 1-20 samples), a sample time (2-20 ms), a record length
(2,000-20,000 samples, log-uniform), a step train (levels uniform in [-1, 1], each held 0.5-3 times the slowest
time constant, after a rest of 100 samples), and white output noise (0.5-5 % of the output's std). The record is
simulated by scipy (zero-order hold, the delay in whole samples), not by synth. It is identified with
``identify(..., structure, delay="fit", average="none")``, the structure ``k (s + z)/((s + p1)(s + p2))`` for a
first-order plant and ``k (s + z)/((s + p1)(s + p2)(s + p3))`` for a second-order one. Outcomes:

- right: a fit whose residual std is within 10 % of the noise's, every plant pole matched by a fitted pole
  within 5 of its standard errors (or marked weak), and a delay >= 0;
- failed: synth's own FitError (exit 1 on the command line), with its reason;
- wrong: a fit returned that is not right (the case is printed);
- error: any other exception.

Run:  nice -n 10 python benchmarks/ident_overparameterized.py [--cases 100] [--seed 47] [--json out.jsonl]
      (PYTHONPATH=<other checkout> runs another version of synth on the same cases)
      python benchmarks/ident_overparameterized.py --summarize a.jsonl b.jsonl
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import numpy as np
from scipy import signal


def make_case(seed: int, index: int) -> dict[str, Any]:
    """The case's truth and record (see the module docstring)."""
    rng = np.random.default_rng([seed, index])
    order = int(rng.integers(1, 3))
    poles = np.sort(10 ** rng.uniform(np.log10(0.3), np.log10(20.0), order))
    gain = float(10 ** rng.uniform(np.log10(0.3), np.log10(5.0)))
    dt = float(10 ** rng.uniform(np.log10(0.002), np.log10(0.02)))
    n = int(10 ** rng.uniform(np.log10(2000), np.log10(20000)))
    delay_samples = 0 if rng.random() < 0.5 else int(rng.integers(1, 21))
    slowest = 1.0 / poles[0]
    u = np.zeros(n)
    k = 100
    while k < n:
        hold = max(2, int(rng.uniform(0.5, 3.0) * slowest / dt))
        u[k:k + hold] = rng.uniform(-1.0, 1.0)
        k += hold
    den = np.poly(-poles)
    num, dden, _ = signal.cont2discrete(([gain * float(np.prod(poles))], den), dt, method="zoh")
    shifted = np.r_[np.zeros(delay_samples), u[:n - delay_samples]]
    clean = signal.dlsim((np.ravel(num), dden, dt), shifted)[1][:, 0]
    sigma = float(rng.uniform(0.005, 0.05) * np.std(clean))
    y = clean + sigma * rng.normal(size=n)
    structure = "k*(s+z)/((s+p1)*(s+p2))" if order == 1 else "k*(s+z)/((s+p1)*(s+p2)*(s+p3))"
    return {"index": index, "order": order, "poles": poles.tolist(), "gain": gain, "dt": dt, "n": n,
            "delay": delay_samples * dt, "sigma": sigma, "structure": structure,
            "t": np.arange(n) * dt, "u": u, "y": y}


def judge(case: dict[str, Any], fit: Any) -> tuple[str, str]:
    """``("right" | "wrong", why)`` for a returned fit."""
    if not abs(fit.residual_std / case["sigma"] - 1.0) <= 0.10:
        return "wrong", f"residual std {fit.residual_std:.4g} against noise {case['sigma']:.4g}"
    if fit.delay < 0.0:
        return "wrong", f"delay {fit.delay:.4g} s"
    weak = {w.name for w in fit.weak}
    fitted = [p for p in fit.parameters if p.startswith("p")]
    free = list(fitted)
    for pole in case["poles"]:
        best = min(free, key=lambda p: abs(fit.parameters[p] - pole))
        off = abs(fit.parameters[best] - pole) / fit.std[best] if fit.std[best] > 0 else np.inf
        if off > 5.0 and best not in weak:
            return "wrong", f"pole {pole:.4g} fitted {fit.parameters[best]:.4g} ({off:.3g} std, not weak)"
        free.remove(best)
    return "right", ""


def run_case(case: dict[str, Any]) -> dict[str, Any]:
    from synth.errors import FitError
    from synth.ident import identify

    start = time.process_time()
    out = {k: case[k] for k in ("index", "order", "poles", "gain", "dt", "n", "delay", "sigma", "structure")}
    try:
        fit = identify((case["t"], case["u"], case["y"]), case["structure"], delay="fit", average="none").fit
        outcome, why = judge(case, fit)
        out.update(parameters=fit.parameters, method=fit.solver.get("method", ""))
    except FitError as exc:
        outcome, why = "failed", str(exc)[:300]
    except Exception as exc:  # a crash is one of the outcomes counted
        outcome, why = "error", f"{type(exc).__name__}: {exc}"[:300]
    out.update(outcome=outcome, why=why, cpu=time.process_time() - start)
    return out


def summarize(paths: list[str]) -> None:
    print("| record | cases | right | failed | wrong | error | CPU median / p95 / total [s] |")
    print("|---|---|---|---|---|---|---|")
    for path in paths:
        rows = [json.loads(line) for line in open(path, encoding="utf-8") if line.strip()]
        count = {k: sum(r["outcome"] == k for r in rows) for k in ("right", "failed", "wrong", "error")}
        cpu = np.array([r["cpu"] for r in rows])
        print(f"| {path} | {len(rows)} | {count['right']} | {count['failed']} | {count['wrong']} | {count['error']} | "
              f"{np.median(cpu):.2f} / {np.percentile(cpu, 95):.2f} / {cpu.sum():.0f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=100)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--seed", type=int, default=47)
    ap.add_argument("--json", default=None, help="append one JSON line per case")
    ap.add_argument("--summarize", nargs="+", default=None, help="print the table of JSON-lines files")
    args = ap.parse_args()
    if args.summarize:
        summarize(args.summarize)
        return
    import warnings

    warnings.filterwarnings("ignore")  # scipy's BadCoefficients on the discretized numerators
    for index in range(args.first, args.first + args.cases):
        row = run_case(make_case(args.seed, index))
        print(f"#{row['index']:3d} order {row['order']} n {row['n']:6d} delay {row['delay']:.3g} "
              f"{row['outcome']:7s} {row['cpu']:6.1f} s  {row['why'][:110]}", flush=True)
        if args.json:
            with open(args.json, "a", encoding="utf-8") as f:
                f.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
