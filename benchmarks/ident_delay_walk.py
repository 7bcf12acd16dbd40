"""A fitted delay on random plants and records: this checkout beside a baseline checkout, in one run (issue 16).

Each seed draws a plant (odd seeds ``k(s+z)/(s+p)``, biproper; even seeds ``k(s+z)/((s+p1)(s+p2))``; the zero at
least 25 % from the slow pole, since a near cancellation is the pair relocation's subject), a delay of 0-30 samples
of 5 ms, a square wave of five periods over 500-4000 samples and white output noise of 0.01, and fits the truth's
structure with the delay (``synth.ident.timefit.fit_structure``), once by IPOPT and once by the FFT-convolution
solver. The reference is the truth the record was made from: a fit is right when its residual std is below 1.1x
the noise and its delay within two samples of the truth's. Counted: right, wrong but flagged as a failure
(``solver["failure"]``), wrong and not flagged, an exception (a traceback for the user), and CPU time.

Run:  python benchmarks/ident_delay_walk.py [--seeds 200] [--baseline-ref aa3e3f6]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DT = 0.005
NOISE = 0.01


def case(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, str, float]:
    """``(t, u, y, structure, delay)`` of seed ``seed`` (module text)."""
    from synth.ident.simulate import simulate_plant
    from synth.plant import Plant

    rng = np.random.default_rng(seed)
    p = rng.uniform(0.5, 5.0)
    z = rng.uniform(0.2, 3.0)
    while abs(z - p) < 0.25 * p:
        z = rng.uniform(0.2, 3.0)
    if seed % 2:
        truth, structure = f"{rng.uniform(1, 3)}*(s+{z})/(s+{p})", "k*(s+z)/(s+p)"
    else:
        p2 = rng.uniform(6.0, 20.0)
        truth, structure = f"{rng.uniform(5, 30)}*(s+{z})/((s+{p})*(s+{p2}))", "k*(s+z)/((s+p1)*(s+p2))"
    delay = float(rng.uniform(0.0, 30 * DT))
    n = int(rng.choice([500, 1000, 2000, 4000]))
    t = np.arange(n) * DT
    u = ((t // (t[-1] / 5)) % 2).astype(float)
    y = simulate_plant(Plant.from_string(truth, delay=delay), t, u) + NOISE * rng.standard_normal(n)
    return t, u, y, structure, delay


def judge(seed: int, solver: str) -> dict:
    """One fit of seed ``seed`` by ``solver``: its outcome (module text) and CPU seconds."""
    from synth.data import record_from_arrays
    from synth.ident.timefit import fit_structure

    t, u, y, structure, delay = case(seed)
    start = time.process_time()
    try:
        fit = fit_structure(record_from_arrays(t, u, y), structure, delay="fit", solver=solver)
    except Exception as exc:  # a traceback for the user: what is counted
        return {"outcome": "exception", "detail": repr(exc)[:100], "cpu": time.process_time() - start}
    right = fit.residual_std < 1.1 * NOISE and abs(fit.parameters["delay"] - delay) <= 2 * DT
    outcome = "right" if right else ("flagged" if fit.solver["failure"] else "wrong")
    return {"outcome": outcome, "cpu": time.process_time() - start,
            "detail": f"residual {fit.residual_std / NOISE:.2f} noise, delay off "
                      f"{(fit.parameters['delay'] - delay) / DT:.1f} samples {fit.solver['failure'][:60]}"}


def side(root: Path, seeds: int) -> list[dict]:
    """Every fit, run by a child process with ``root``'s synth on its path."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    # this file's judge, loaded by path, and synth from root (PYTHONPATH)
    code = (f"import json, runpy; judge = runpy.run_path({__file__!r})['judge']; import synth; "
            f"assert synth.__file__.startswith({str(root)!r}), synth.__file__; "
            f"print(json.dumps([dict(judge(s, v), seed=s, solver=v) for s in range({seeds}) "
            f"for v in ('ipopt', 'convolution')]))")
    proc = subprocess.run([sys.executable, "-c", code], cwd=root, env=env, capture_output=True, text=True, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    from benchmarks.cli_speed import baseline_tree

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=200)
    parser.add_argument("--baseline-ref", default="main")
    args = parser.parse_args()
    with baseline_tree(args.baseline_ref, "synth-delay-walk-") as base:
        rows = {"this checkout": side(ROOT, args.seeds), f"baseline {args.baseline_ref}": side(base, args.seeds)}
    kinds = ("right", "flagged", "wrong", "exception")
    print(f"{args.seeds} seeds x 2 solvers = {2 * args.seeds} fits")
    print(f"| side | {' | '.join(kinds)} | CPU total [s] | CPU median fit [s] |")
    print("|---|" + "---|" * (len(kinds) + 2))
    for name, fits in rows.items():
        counts = [sum(f["outcome"] == k for f in fits) for k in kinds]
        cpu = [f["cpu"] for f in fits]
        print(f"| {name} | {' | '.join(str(c) for c in counts)} | {sum(cpu):.1f} | {np.median(cpu):.2f} |")
    for name, fits in rows.items():
        for f in fits:
            if f["outcome"] != "right":
                print(f"{name}: seed {f['seed']} {f['solver']}: {f['outcome']}: {f['detail']}")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
