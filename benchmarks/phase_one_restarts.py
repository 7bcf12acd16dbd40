"""The convex stage with and without the early stop of phase 1's restarts (``ConvexSettings.restart_limit``), on
the design benchmark's random problems (``benchmarks/design_problems.py``), both in the same process: each
structural run's status and objective, the convex solves and the CPU time.

Run: ``python benchmarks/phase_one_restarts.py --seed 5 --n 65`` (rows as JSON lines on stdout, the totals last).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def compare(seed: int, index: int) -> dict:
    """One problem's convex runs with every start converging (``restart_limit`` 0) and with the stop (default).

    Examples
    --------
    >>> row = compare(5, 0)
    >>> row["every"] == row["stopped"], row["solves"]["every"] == row["solves"]["stopped"]
    (True, True)
    """
    import synth
    from benchmarks.design_problems import problem
    from synth.synthesis.convex_settings import ConvexSettings
    from synth.synthesis.multi import convex_runs

    spec = synth.parse_spec(problem(seed, index).spec)
    row: dict = {"index": index, "type": spec.controller.type, "solves": {}, "cpu": {}}
    for name, settings in (("every", ConvexSettings(restart_limit=0.0)), ("stopped", ConvexSettings())):
        t = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                runs = convex_runs(spec, settings)
                row[name] = [(r.status, None if r.objective_value is None else round(float(r.objective_value), 6))
                             for _, r in runs]
                row["solves"][name] = sum(d.solves for d, _ in runs)
            except Exception as e:  # no stabilizing start, say: the same error on both sides is the same verdict
                row[name], row["solves"][name] = repr(e)[:120], 0
        row["cpu"][name] = round(time.process_time() - t, 2)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--n", type=int, default=65)
    args = ap.parse_args()
    rows = []
    for i in range(args.n):
        rows.append(compare(args.seed, i))
        print(json.dumps(rows[-1]), flush=True)
    differ = [r["index"] for r in rows if r["every"] != r["stopped"]]
    infeasible = sum(1 for r in rows if "infeasible" in str(r["every"]))
    where = f"on {differ}" if differ else "on none"
    print(f"{len(rows)} problems ({infeasible} with an infeasible run): verdicts or objectives differ {where}; "
          f"solves {sum(r['solves']['every'] for r in rows)} -> {sum(r['solves']['stopped'] for r in rows)}; "
          f"CPU {sum(r['cpu']['every'] for r in rows):.1f} -> {sum(r['cpu']['stopped'] for r in rows):.1f} s")


if __name__ == "__main__":
    main()
