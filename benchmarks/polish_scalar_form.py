"""Design CPU time with the NLP polish's exact-Hessian solves in scalar form (casadi ``expand``), beside the
matrix form (the baseline, ``SCALAR_FORM = False``), in the same run.

Each design runs serially (no forked job) in a fresh process, once per form, the two forms alternating so that
the machine's load falls on both alike; the table gives each problem's CPU seconds and whether the two designs
are the same controller (to 6 significant digits) with the same status.

Problems: the test suite's slowest designs (a second-order rational controller on the X-4 plant; seed 5 #20, a
PID behind a 4.3 s delay; an infeasible PI) and the first problems of design-verification seed 9.

Run:  python benchmarks/polish_scalar_form.py [--seed9 8]
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.design_child import run_design

X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"

SPECS = {
    "rational (2, 2), X-4 plant": {
        "name": "r2", "plant": {"tf": X4, "delay": 0.02},
        "controller": {"type": "rational", "order": [2, 2], "bounds": {"a0": [0, 0]}},
        "requirements": [{"type": "peak_sensitivity", "max_db": 6},
                         {"type": "margins", "phase_margin_deg": 45, "gain_margin_db": 6}],
        "objective": {"maximize": "crossover"}},
    "PI, infeasible, X-4 plant": {
        "name": "alone", "plant": {"tf": X4, "delay": 0.02},
        "controller": {"type": "PI", "bounds": {"kp": [0, 20], "ki": [0, 500]}},
        "requirements": [{"type": "sensitivity", "max_db": -15, "band": [0, 30]},
                         {"type": "peak_sensitivity", "max_db": 6}]},
}

def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed9", type=int, default=8, help="how many of seed 9's first problems")
    args = parser.parse_args()
    cases: dict[str, object] = {**SPECS, "seed 5 #20 (PID, 4.3 s delay)": [5, 20],
                                **{f"seed 9 #{i}": [9, i] for i in range(args.seed9)}}
    print("| problem | matrix form (baseline) CPU s | scalar form CPU s | ratio | same design |")
    print("|---|---|---|---|---|")
    ratios = []
    for name, spec in cases.items():
        base, new = (run_design(spec, f"import synth.synthesis.nlp_problem as m; m.SCALAR_FORM = {scalar}")
                     for scalar in (False, True))
        same = base["status"] == new["status"] and base["controller"] == new["controller"]
        ratio = new["cpu"] / base["cpu"]
        ratios.append(ratio)
        print(f"| {name} | {base['cpu']:.1f} | {new['cpu']:.1f} | {ratio:.2f} | "
              f"{'yes' if same else 'no: ' + base['controller'] + ' / ' + new['controller']} |", flush=True)
    print(f"\nmedian ratio {statistics.median(ratios):.2f} over {len(ratios)} problems")


if __name__ == "__main__":
    main()
