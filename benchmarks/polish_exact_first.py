"""Design CPU time with every NLP polish solve on IPOPT's exact Hessian from its first iteration, beside the
limited-memory (BFGS) Hessian the polish starts with (the baseline), in the same run (issues 15 and 18).

The polish goes on with the exact Hessian only after a limited-memory round stopped at its iteration limit.
On a 5-variable PI polish with 667 constraints the limited-memory solves took 100-550 iterations each. This
compares the two starts: each design runs serially in a fresh process (:mod:`benchmarks.design_child`), the
two sides alternating; the table gives CPU seconds, the status and the objective of each.

Problems: :mod:`benchmarks.polish_scalar_form`'s (the test suite's slowest designs) and the first problems of
design-verification seed 9.

Run:  python benchmarks/polish_exact_first.py [--seed9 8]
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.design_child import run_design
from benchmarks.polish_scalar_form import SPECS

EXACT = 'import synth.synthesis.nlp_problem as m; m.IPOPT_OPTIONS["ipopt.hessian_approximation"] = "exact"'


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed9", type=int, default=8, help="how many of seed 9's first problems")
    args = parser.parse_args()
    cases: dict[str, object] = {**SPECS, "seed 5 #20 (PID, 4.3 s delay)": [5, 20],
                                **{f"seed 9 #{i}": [9, i] for i in range(args.seed9)}}
    print("| problem | limited-memory first (baseline) CPU s | exact first CPU s | ratio | status | objective "
          "baseline / exact |")
    print("|---|---|---|---|---|---|")
    ratios = []
    for name, spec in cases.items():
        base, new = (run_design(spec, setup) for setup in ("", EXACT))
        ratio = new["cpu"] / base["cpu"]
        ratios.append(ratio)
        status = base["status"] if base["status"] == new["status"] else f"{base['status']} / {new['status']}"
        objective = (f"{base['objective']:.6g} / {new['objective']:.6g}"
                     if base["objective"] is not None and new["objective"] is not None else "-")
        print(f"| {name} | {base['cpu']:.1f} | {new['cpu']:.1f} | {ratio:.2f} | {status} | {objective} |", flush=True)
    print(f"\nmedian ratio {statistics.median(ratios):.2f} over {len(ratios)} problems")


if __name__ == "__main__":
    main()
