"""The NLP polish's limited-memory solves with the SR1 update beside BFGS (as it is), on the same NLPs in one run.

IPOPT's limited-memory Hessian approximates the Hessian of the Lagrangian. BFGS keeps that approximation positive
definite; the polish's Lagrangian is not (its constraints bend both ways: crossover conditions, peaks held at
their frequencies). On the test suite's second-order rational design (``tests/test_synthesis_rational.py``) the
BFGS rounds crawled about 900 iterations of a constant small step each. This benchmark asks whether the
symmetric rank-one update (``limited_memory_update_type sr1``), which may be indefinite, helps in general: it
runs the designs of stored benchmark problems (seeds 24-28 of ``benchmarks/design_verification.py``, controllers
other than P, a random sample), records every NLP the polish builds (``polish_helper_units.capture``), and solves
each limited-memory one again with either update from the same start. The exact-Hessian solves are left out:
the update does not apply to them.

Per NLP it compares IPOPT's time, iterations, status and the objective at the answer (both answers feasible to
1e-6). It measures single NLPs, not designs: the rounds and stages after a different answer are not followed.

Run:  python benchmarks/polish_sr1.py [--problems 30] [--seed 1]
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.polish_helper_units import capture, objective_counts, parsed_args, sampled_rows, solve_in_units

UPDATES = ("bfgs", "sr1")


def solve_with(nlp: dict[str, Any], update: str) -> dict[str, Any]:
    """Solve one captured NLP with the limited-memory ``update`` (its variables as the polish has them)."""
    return solve_in_units({**nlp, "options": {**nlp["options"], "ipopt.limited_memory_update_type": update}}, False)


def main() -> None:
    args = parsed_args()
    nlps = [n for n in capture(sampled_rows(args.problems, args.seed))
            if n["options"].get("ipopt.hessian_approximation") == "limited-memory"]
    pairs = [tuple(solve_with(n, u) for u in UPDATES) for n in nlps]
    print(f"\n{len(nlps)} limited-memory NLPs from {args.problems} designs\n")
    print("| update | IPOPT seconds | iterations | converged | over 300 iterations |")
    print("|---|---|---|---|---|")
    for k, name in enumerate(UPDATES):
        print(f"| {name} | {sum(p[k]['seconds'] for p in pairs):.2f} | {sum(p[k]['iterations'] for p in pairs)} | "
              f"{sum(p[k]['success'] for p in pairs)} of {len(pairs)} | "
              f"{sum(p[k]['iterations'] > 300 for p in pairs)} |")
    both, better, worse = objective_counts(pairs)
    print(f"\nobjective at the answer, sr1 against bfgs ({both} NLPs with both answers feasible): "
          f"better {better}, the same {both - better - worse}, worse {worse}")
    for i, (a, b) in enumerate(pairs):
        if a["violation"] < 1e-6 and b["violation"] < 1e-6 and abs(b["f"] - a["f"]) > 1e-6 * max(1.0, abs(a["f"])):
            print(f"  NLP {i}: bfgs f={a['f']:.6g} ({a['iterations']} it), sr1 f={b['f']:.6g} ({b['iterations']} it)")


if __name__ == "__main__":
    main()
