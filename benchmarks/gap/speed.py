"""Speed of one effect diagnosis on a 20,000-sample record with every candidate, against a baseline in the same run.

Case: the X-4 rotor drive (eq. 5 plant, 2-5 % mismatch in every coefficient of the nominal handed to
the diagnosis), a hidden rate limit of 300 PWM/s, a 16-level step train of several amplitudes sampled
at 500 Hz for 40 s (20,000 samples; the first half trains), noise 1 rad/s. Every candidate of
:data:`synth.gap.effects.registry.DEFAULT_CANDIDATES` (12).

Rows:
  * synth: ``diagnose_effects`` with its defaults (every candidate screened with the denominator fixed,
    the best 3 re-fitted jointly by casadi; calibration by the linearized re-fit, 199 replicates);
  * baseline: the same diagnosis without screening (``confirm=None``: every candidate's full
    grid + golden search, each point a casadi re-fit of the nominal with the effect) and with the
    casadi re-fit repeated on each of 19 calibration replicates (``calibration="refit"``), i.e. the
    procedure before screening.

Goal (issue 6): one diagnosis of a 20,000-sample record with every candidate under 60 s on 2 cores.

Run:  python benchmarks/gap/speed.py [--no-baseline]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from synth.data import record_from_arrays  # noqa: E402
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects  # noqa: E402
from synth.gap.effects import make_effect  # noqa: E402
from synth.plant import Plant  # noqa: E402

TRUE = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
NOMINAL = Plant.from_string("22*(s+0.45)/((s+9.3)*(s+0.56))")
LEVELS = np.array([175, 225, 185, 235, 170, 205, 240, 180, 220, 195, 230, 175, 215, 185, 245, 190], float)


def record(n: int = 20000, seed: int = 0):
    """The benchmark record (``n`` samples over 40 s) and its noise-free output."""
    t = np.linspace(0.0, 40.0, n, endpoint=False)
    u = LEVELS[np.minimum((t // 2.5).astype(int), LEVELS.size - 1)]
    clean = make_effect("rate_limit").apply(TRUE, t, u, {"rate": 300.0})
    y = clean + np.random.default_rng(seed).normal(size=n)
    return record_from_arrays(t, u, y), clean


def _quiet(fn):  # casadi warnings go to file descriptor 2
    fd = os.dup(2)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
            return fn()
    finally:
        os.dup2(fd, 2)
        os.close(fd)


def main(argv: list[str] | None = None) -> None:
    """CLI."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-baseline", action="store_true")
    ap.add_argument("--samples", type=int, default=20000)
    args = ap.parse_args(argv)
    rec, clean = record(args.samples)
    rows = []
    runs = [("synth defaults (screen all 12, joint re-fit of the best 3 on 2 processes, linearized calibration)",
             {"workers": 2})]
    if not args.no_baseline:
        runs.append(("baseline: joint re-fit of all 12 (grid + golden), casadi calibration x 19",
                     {"confirm": None, "calibration": "refit", "n_null": 19}))
    for label, kw in runs:
        t0 = time.perf_counter()
        dg = _quiet(lambda kw=kw: diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(**kw)))
        dt = time.perf_counter() - t0
        best = next((e for e in dg.effects if e.accepted), None)
        true_shrink = 1.0 - float(np.mean((rec.y - clean)[dg.heldout] ** 2)) / dg.j_refit
        rows.append((label, dt, dg.verdict["effects"], best.parameters if best else {},
                     best.shrinkage if best else float("nan"), true_shrink))
    print(f"record: {rec.n} samples, {len(dg.effects)} candidates, hidden rate limit 300 PWM/s\n")
    print("| run | time [s] | verdict | fitted | shrinkage (true) |")
    print("|---|---|---|---|---|")
    for label, dt, verdict, params, shrink, true_shrink in rows:
        fitted = ", ".join(f"{k} = {v:.4g}" for k, v in params.items())
        print(f"| {label} | {dt:.1f} | {verdict} | {fitted} | {shrink:.3f} ({true_shrink:.3f}) |")
    print(f"\nGoal: under 60 s. {'Met' if rows[0][1] < 60 else 'NOT met'} ({rows[0][1]:.1f} s).")


if __name__ == "__main__":
    main()
