"""The NLP polish with its helper variables solved in units of their starts, beside the polish as it is (units
of one), on the same NLPs in one run.

The polish's helper variables (crossover, phase-crossover and peak frequencies, a peak's level) enter IPOPT in
their own units: a crossover of 1,000 rad/s beside controller variables of order one. On the test suite's
second-order rational design (``tests/test_synthesis_rational.py``) the limited-memory BFGS then crawls, about
900 iterations of a constant small step per round. This benchmark asks whether dividing each helper by its start
value helps in general: it runs the designs of stored benchmark problems (seeds 24-28 of
``benchmarks/design_verification.py``, controllers other than P, a random sample), records every NLP the polish
builds, and solves each again both ways from the same start.

Per NLP it compares IPOPT's time, iterations, status and the objective at the answer (both answers feasible to
1e-6). It measures single NLPs, not designs: the rounds and stages after a different answer are not followed.

Run:  python benchmarks/polish_helper_units.py [--problems 30] [--seed 1]
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import synth
from synth.synthesis import nlp_problem

ROWS = Path(__file__).resolve().parents[1] / "reports" / "design_verification" / "seed24-28_s50.jsonl"


def capture(problems: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Every NLP the polish solves while designing ``problems`` (the design follows the polish as it is)."""
    captured: list[dict[str, Any]] = []
    solve = nlp_problem.NLPBuilder.solve

    def recording(self: nlp_problem.NLPBuilder, options: dict[str, Any] | None = None, x0: np.ndarray | None = None,
                  expand: bool = False) -> tuple[np.ndarray, dict[str, Any]]:
        x = ca.vertcat(*self.x)
        g = ca.vertcat(*self.g) if self.g else nlp_problem.SYM(0, 1)
        captured.append({"problem": ca.Function("nlp", [x], [self.f, g]), "n_controller": len(self.ctrl.free),
                         "x0": np.concatenate(self.x0) if x0 is None else np.asarray(x0, float),
                         "lbx": np.concatenate(self.lbx), "ubx": np.concatenate(self.ubx),
                         "lbg": np.array(self.lbg), "ubg": np.array(self.ubg),
                         "options": {**nlp_problem.IPOPT_OPTIONS, **(options or {}), "expand": expand}})
        return solve(self, options, x0, expand)

    nlp_problem.NLPBuilder.solve = recording  # type: ignore[method-assign]
    try:
        for row in problems:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                synth.design(synth.parse_spec(row["spec"]))
            print(f"designed {row['spec']['name']} #{row['index']} ({row['controller']}): {len(captured)} NLPs so far",
                  file=sys.stderr, flush=True)
    finally:
        nlp_problem.NLPBuilder.solve = solve  # type: ignore[method-assign]
    return captured


def solve_in_units(nlp: dict[str, Any], helper_units: bool) -> dict[str, Any]:
    """Solve one captured NLP with its helpers in units of one or of their starts."""
    unit = np.ones(nlp["x0"].size)
    if helper_units:
        start = nlp["x0"][nlp["n_controller"]:]
        unit[nlp["n_controller"]:] = np.where(np.isfinite(start) & (start != 0.0), np.abs(start), 1.0)
    v = ca.MX.sym("v", unit.size)
    f, g = nlp["problem"](v * unit)
    solver = ca.nlpsol("polish", "ipopt", {"x": v, "f": f, "g": g}, nlp["options"])
    t0 = time.perf_counter()
    res = solver(x0=nlp["x0"] / unit, lbx=nlp["lbx"] / unit, ubx=nlp["ubx"] / unit, lbg=nlp["lbg"], ubg=nlp["ubg"])
    stats = solver.stats()
    gv = np.asarray(res["g"]).ravel()
    violation = float(np.max(np.concatenate([[0.0], nlp["lbg"] - gv, gv - nlp["ubg"]])))
    return {"seconds": time.perf_counter() - t0, "iterations": int(stats["iter_count"]),
            "success": bool(stats["success"]), "f": float(res["f"]), "violation": violation}


def sampled_rows(problems: int, seed: int) -> list[dict[str, Any]]:
    """``problems`` stored design problems (controllers other than P, under 15 s of synth's CPU), shuffled by
    ``seed``."""
    rows = [json.loads(line) for line in ROWS.read_text().splitlines() if line.strip()]
    rows = [r for r in rows if r["controller"] != "P" and (r.get("synth_cpu_seconds") or 99.0) < 15.0]
    random.Random(seed).shuffle(rows)
    return rows[:problems]


def objective_counts(pairs: list[tuple[dict[str, Any], dict[str, Any]]]) -> tuple[int, int, int]:
    """Of the pairs whose answers are both feasible (1e-6): how many, and how many the second solve made better
    and worse (beyond a relative 1e-6)."""
    both = [(a, b) for a, b in pairs if a["violation"] < 1e-6 and b["violation"] < 1e-6]
    tol = [1e-6 * max(1.0, abs(a["f"])) for a, _ in both]
    better = sum(b["f"] < a["f"] - t for (a, b), t in zip(both, tol))
    worse = sum(b["f"] > a["f"] + t for (a, b), t in zip(both, tol))
    return len(both), better, worse


def parsed_args() -> argparse.Namespace:
    """``--problems`` and ``--seed``."""
    parser = argparse.ArgumentParser(description=(sys.modules["__main__"].__doc__ or "").splitlines()[0])
    parser.add_argument("--problems", type=int, default=30)
    parser.add_argument("--seed", type=int, default=1, help="the sample's shuffle")
    return parser.parse_args()


def main() -> None:
    args = parsed_args()
    nlps = capture(sampled_rows(args.problems, args.seed))
    pairs = [(solve_in_units(n, False), solve_in_units(n, True)) for n in nlps]
    print(f"\n{len(nlps)} NLPs from {args.problems} designs\n")
    print("| helpers in units of | IPOPT seconds | iterations | converged |")
    print("|---|---|---|---|")
    for k, name in enumerate(("one (as it is)", "their starts")):
        print(f"| {name} | {sum(p[k]['seconds'] for p in pairs):.2f} | {sum(p[k]['iterations'] for p in pairs)} | "
              f"{sum(p[k]['success'] for p in pairs)} of {len(pairs)} |")
    both, better, worse = objective_counts(pairs)
    print(f"\nobjective at the answer, units of the starts against one ({both} NLPs with both answers feasible): "
          f"better {better}, the same {both - better - worse}, worse {worse}")


if __name__ == "__main__":
    main()
