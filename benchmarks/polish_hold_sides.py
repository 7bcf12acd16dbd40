"""Designs with and without the polish's hold of the Nyquist curve's close approaches to -1
(``synth.synthesis.nlp.HOLD_SIDES``: ``"after_unstable"``, the default, against ``"never"``, the baseline),
in the same run.

Each design runs serially in a fresh process, once per setting (:mod:`benchmarks.design_child`); each design
is checked by the benchmark's own dense reference check (:func:`benchmarks.design_reference.check_point`).
The table gives both objectives, both CPU times and whether the designs differ.

Run:  python benchmarks/polish_hold_sides.py --cases 1:192 8:135 5:20      (seed:index of design_problems)
      python benchmarks/polish_hold_sides.py --seed 11 --n 40              (the first 40 of a seed)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.design_child import run_design
from benchmarks.design_problems import Problem, problem
from benchmarks.design_reference import check_point


def _checked(p: Problem, record: dict) -> str:
    if record["objective"] is None:
        return record["status"]
    ok = check_point(p.num, p.den, p.delay, p.spec, record["parameters"]).feasible(1e-3)
    return f"{record['objective']:.6g}" + ("" if ok else " (FAILS the reference check)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="*", default=[], help="seed:index pairs")
    parser.add_argument("--seed", type=int, help="with --n: the first problems of this seed")
    parser.add_argument("--n", type=int, default=0)
    args = parser.parse_args()
    cases = [tuple(int(v) for v in c.split(":")) for c in args.cases]
    if args.seed is not None:
        cases += [(args.seed, i) for i in range(args.n)]
    print("| problem | objective, never (baseline) | objective, after an unstable answer | CPU s, never | CPU s, after "
          "| same design |")
    print("|---|---|---|---|---|---|")
    totals = [0.0, 0.0]
    for seed, index in cases:
        base, new = (run_design([seed, index], f"import synth.synthesis.nlp as m; m.HOLD_SIDES = {mode!r}")
                     for mode in ("never", "after_unstable"))
        totals[0] += base["cpu"]
        totals[1] += new["cpu"]
        same = base["status"] == new["status"] and base["controller"] == new["controller"]
        p = problem(seed, index)
        print(f"| seed {seed} #{index} | {_checked(p, base)} | {_checked(p, new)} | "
              f"{base['cpu']:.1f} | {new['cpu']:.1f} | {'yes' if same else 'no'} |", flush=True)
    print(f"\nCPU over {len(cases)} problems: {totals[0]:.1f} s (never) / {totals[1]:.1f} s (after an unstable answer)")


if __name__ == "__main__":
    main()
