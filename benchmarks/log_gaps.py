"""Step trains whose log drops out over one edge: identification against the truth, over random cases.

Each case (``numpy.random.default_rng(case)``): a first-order ``K/(T s+1)`` or second-order ``K/((T1 s+1)(T2 s+1))``
plant with a whole-sample delay of 0-50 ms, a square-wave train of 20-40 periods (1-3 s between edges) logged every
10 ms, and one dropout of 0.15-0.5 s in the middle of the record that hides an edge (the edge somewhere inside it).
The truth is simulated by ``scipy.signal.cont2discrete`` (zero-order hold, exact for a held command) and
``scipy.signal.lfilter``, independent of synth; white output noise of 1 % of the gain; ``--seeds`` noise seeds per
case. Each record goes through ``synth.ident.identify`` with its default averaging and the truth's structure, the
delay fitted. Per (case, parameter): the largest |estimate - truth| / reported std over the seeds, and the share of
estimates within 3 reported std.

Run (from the repository root; ``PYTHONPATH`` picks the synth to measure):

    python benchmarks/log_gaps.py --cases 40 --seeds 5
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np
from scipy import signal


def case_record(case: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, float], str]:
    """``(t, u, y, truth, structure)`` of one case and noise seed (the dropout cut out of the log)."""
    rng = np.random.default_rng(case)
    dt = 0.01
    second = bool(rng.integers(0, 2))
    half = float(rng.uniform(1.0, 3.0))
    periods = int(rng.integers(20, 41))
    t = np.arange(0.0, 2 * half * periods, dt)
    u = (np.floor(t / half) % 2 == 1) * 1.0
    k, t1 = float(rng.uniform(0.5, 4.0)), float(rng.uniform(0.05, 0.3))
    t2 = float(rng.uniform(0.01, 0.3 * t1)) if second else 0.0
    shift = int(rng.integers(0, 6))
    den = np.polymul([t1, 1.0], [t2, 1.0]) if second else np.array([t1, 1.0])
    num, dd, _ = signal.cont2discrete(([k], den), dt, method="zoh")
    y = signal.lfilter(np.ravel(num), dd, np.r_[np.zeros(shift), u[: u.size - shift]])
    edge = half * int(rng.integers(periods // 2, periods))
    length = float(rng.uniform(0.15, 0.5))
    start = edge - float(rng.uniform(0.05, length - 0.05))
    keep = (t <= start) | (t >= start + length)
    y = y + 0.01 * k * np.random.default_rng(1000 * case + seed).standard_normal(t.size)
    truth = {"K": k, **({"T1": t1, "T2": t2} if second else {"T": t1}), "delay": shift * dt}
    return t[keep], u[keep], y[keep], truth, "K/((T1*s+1)*(T2*s+1))" if second else "K/(T*s+1)"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=40)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--json", help="write the per-fit rows here")
    args = ap.parse_args()
    from synth.ident.identification import identify

    rows, failed, start = [], 0, time.process_time()
    for case in range(args.cases):
        for seed in range(args.seeds):
            t, u, y, truth, structure = case_record(case, seed)
            try:
                fit = identify((t, u, y), structure, delay="fit", compare_directions=False).fit
            except Exception as exc:  # a failure is counted, not hidden
                failed += 1
                rows.append({"case": case, "seed": seed, "error": str(exc)})
                continue
            z = {name: abs(fit.parameters[name] - value) / fit.std[name] for name, value in truth.items()
                 if fit.std.get(name, 0) > 0}
            rows.append({"case": case, "seed": seed, "z": z})
    pairs: dict[tuple[int, str], list[float]] = {}
    for row in rows:
        for name, z in row.get("z", {}).items():
            pairs.setdefault((row["case"], name), []).append(z)
    worst = np.array([max(v) for v in pairs.values()])
    within = np.array([np.mean(np.array(v) <= 3.0) for v in pairs.values()])
    print(f"{args.cases} cases x {args.seeds} seeds, {len(pairs)} (case, parameter) pairs, "
          f"{time.process_time() - start:.0f} s CPU, synth from {sys.modules['synth'].__file__}")
    print("| measure | value |\n|---|---|")
    print(f"| fits failed | {failed} of {args.cases * args.seeds} |")
    print(f"| pairs whose every estimate lies within 3 reported std | {np.mean(within == 1):.1%} |")
    print(f"| estimates within 3 reported std (mean over pairs) | {np.mean(within):.1%} |")
    print(f"| largest \\|error\\| / reported std: median, 95th percentile, max | {np.median(worst):.2f}, "
          f"{np.percentile(worst, 95):.2f}, {worst.max():.2f} |")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(rows, fh)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
