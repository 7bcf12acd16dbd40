"""Outputs that do not respond to their input, and outputs that do: this checkout beside a baseline, in one run.

Each walk seed draws a two-level PRBS (holds of 5, 20 or 50 samples of 10 ms, 2,000 or 4,000 samples) and an output
that is a random walk unrelated to it (steps of 0.02); ``synth.identify`` with ``k/(s+p)`` and a fitted delay must
refuse it (a FitError naming no response). Each control seed draws a square train (period 2-10 s) through a
second-order plant ``2 p1 p2 / ((s+p1)(s+p2))`` (poles 0.3-10 and 0.3-30 rad/s) with white noise of 2-30 % of the
response's spread, fitted by the same first-order structure: a wrong structure, smooth residuals and a weak
prewhitened cross-correlation, which must still be identified. Counted per side: walks identified (false
responses), controls refused (false refusals), and CPU time.

Run:  python benchmarks/ident_no_response.py [--walks 100] [--controls 40] [--baseline-ref f3e665d]
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
DT = 0.01


def walk(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(10_000 + seed)
    n, hold = int(rng.choice([2000, 4000])), int(rng.choice([5, 20, 50]))
    u = np.repeat(rng.choice([0.0, 1.0], n // hold + 1), hold)[:n]
    return np.arange(n) * DT, u, np.cumsum(0.02 * rng.normal(size=n))


def control(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from scipy import signal

    rng = np.random.default_rng(20_000 + seed)
    n = int(rng.choice([2000, 4000, 10000]))
    t = np.arange(n) * DT
    p1, p2 = 10 ** rng.uniform(-0.5, 1), 10 ** rng.uniform(-0.5, 1.5)
    u = np.floor(t / 10 ** rng.uniform(0.3, 1)) % 2
    den = np.poly([-p1, -p2])
    b, a, _ = signal.cont2discrete(([2 * den[-1]], den), DT, method="zoh")
    y0 = signal.lfilter(np.squeeze(b), a, u)
    return t, u, y0 + rng.uniform(0.02, 0.3) * np.std(y0) * rng.normal(size=n)


def judge(kind: str, seed: int) -> dict:
    """One identification: ``identified`` or ``refused`` (a FitError), or ``exception``; CPU seconds."""
    from synth.data import record_from_arrays
    from synth.errors import FitError
    from synth.ident.identification import identify

    t, u, y = (walk if kind == "walk" else control)(seed)
    start = time.process_time()
    try:
        fit = identify(record_from_arrays(t, u, y), "k/(s+p)", "fit").fit
        outcome, detail = "identified", f"fit {fit.fit_percent:.1f} %, {fit.plant.to_string()}"
    except FitError as exc:
        outcome, detail = "refused", str(exc)[:110]
    except Exception as exc:  # a traceback for the user: what is counted
        outcome, detail = "exception", repr(exc)[:110]
    return {"kind": kind, "seed": seed, "outcome": outcome, "detail": detail, "cpu": time.process_time() - start}


def side(root: Path, walks: int, controls: int) -> subprocess.Popen:
    """A child process that runs every case with ``root``'s synth on its path (the sides run side by side)."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    code = (f"import json, runpy; judge = runpy.run_path({__file__!r})['judge']; import synth; "
            f"assert synth.__file__.startswith({str(root)!r}), synth.__file__; "
            f"print(json.dumps([judge('walk', s) for s in range({walks})] + "
            f"[judge('control', s) for s in range({controls})]))")
    return subprocess.Popen([sys.executable, "-c", code], cwd=root, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)


def collect(proc: subprocess.Popen) -> list[dict]:
    out, _ = proc.communicate()
    if proc.returncode:
        raise RuntimeError(f"a side's child process exited {proc.returncode}")
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    from benchmarks.cli_speed import baseline_tree

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--walks", type=int, default=100)
    parser.add_argument("--controls", type=int, default=40)
    parser.add_argument("--baseline-ref", default="main")
    args = parser.parse_args()
    with baseline_tree(args.baseline_ref, "synth-no-response-") as base:
        procs = {"this checkout": side(ROOT, args.walks, args.controls),
                 f"baseline {args.baseline_ref}": side(base, args.walks, args.controls)}
        rows = {name: collect(proc) for name, proc in procs.items()}
    print(f"{args.walks} random walks (must be refused), {args.controls} square trains through second-order plants "
          "(must be identified)")
    print("| side | walks identified | walks refused | controls identified | controls refused | exceptions "
          "| CPU total [s] | CPU median [s] |")
    print("|---|---|---|---|---|---|---|---|")
    for name, cases in rows.items():
        counts = {(k, o): sum(c["kind"] == k and c["outcome"] == o for c in cases)
                  for k in ("walk", "control") for o in ("identified", "refused")}
        cpu = [c["cpu"] for c in cases]
        print(f"| {name} | {counts['walk', 'identified']} | {counts['walk', 'refused']} | "
              f"{counts['control', 'identified']} | {counts['control', 'refused']} | "
              f"{sum(c['outcome'] == 'exception' for c in cases)} | {sum(cpu):.1f} | {np.median(cpu):.2f} |")
    for name, cases in rows.items():
        for c in cases:
            wrong = {"walk": "identified", "control": "refused"}[c["kind"]]
            if c["outcome"] in (wrong, "exception"):
                print(f"{name}: {c['kind']} {c['seed']}: {c['outcome']}: {c['detail']}")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
