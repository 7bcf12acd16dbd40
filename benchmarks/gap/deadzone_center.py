"""Dead zones wherever their band is: named, located and sized, on records simulated without synth.

A generated record: a random stable second-order plant (poles 1-4 and 6-20 rad/s, DC gain 0.5-3), a smooth random
command (white noise low-passed at 0.3 Hz, scaled to 0-10; ``--command steps``: a step train of levels uniform over
0-10, each held 1-3 s), held at its first value for the first 2 s, 3,000
samples at 0.01 s for estimation and as many for validation, noise 1 % of the output's spread (``--noise``). The dead zone
(half-width 0.5-1.2) sits

- ``off``: 1.5-3 units from where the estimation command starts, inside 2.5-7.5 (a log that starts away from the
  band);
- ``rest``: around the estimation command's first sample (a drive that rests in its dead zone).

The records are simulated by scipy alone (exact zero-order hold of the dead-zoned command samples,
``cont2discrete`` and ``dlsim``), not by synth. The nominal model handed to the diagnosis has its gain 3 % high and
its denominator coefficients -3 % and +2 % off. Each record is diagnosed with the candidates ``deadzone``,
``quantization``, ``backlash`` and ``saturation`` (200 bootstrap draws).

Scored: the verdict is ``deadzone`` alone; the center within 0.2 (2 % of the command's span) and the width within
10 % of the truth; and which form the fit kept (the center fitted, or held at the command at rest).

Run:  python benchmarks/gap/deadzone_center.py [--seeds 40] [--kinds off rest] [--command smooth|steps]
      [--noise 0.01] [--jobs 2]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from scipy import signal

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from synth.data import record_from_arrays  # noqa: E402
from synth.data.record import Record  # noqa: E402
from synth.plant import Plant  # noqa: E402

DT, N = 0.01, 3000
CANDIDATES = ["deadzone", "quantization", "backlash", "saturation"]


def dead_zone(x: np.ndarray, width: float, center: float) -> np.ndarray:
    """``center`` inside ``|x - center| <= width``, ``x -+ width`` outside (the block's documented map)."""
    return np.where(x > center + width, x - width, np.where(x < center - width, x + width, center))


def _command(rng: np.random.Generator, command: str) -> np.ndarray:
    """A smooth random command, or a step train (levels uniform over 0-10, each held 1-3 s), over 0-10."""
    if command == "steps":
        levels, holds = rng.uniform(0.0, 10.0, size=N), rng.integers(100, 301, size=N)
        return np.repeat(levels, holds)[:N]
    a = np.exp(-2.0 * np.pi * 0.3 * DT)
    x = signal.lfilter([1.0 - a], [1.0, -a], rng.normal(size=N))
    return 10.0 * (x - x.min()) / np.ptp(x)


def records(seed: int, kind: str = "off", command: str = "smooth",
            noise: float = 0.01) -> tuple[Plant, Record, Record, float, float]:
    """The nominal model, the estimation and validation records, the band's true center and half-width.

    Raises
    ------
    ValueError
        An ``off`` record whose band came out where the command starts (not a record of that kind).
    """
    rng = np.random.default_rng(seed)
    p1, p2, gain = rng.uniform(1.0, 4.0), rng.uniform(6.0, 20.0), rng.uniform(0.5, 3.0)
    num, den = np.array([gain * p1 * p2]), np.polymul([1.0, p1], [1.0, p2])
    disc = signal.cont2discrete(signal.tf2ss(num, den), DT, method="zoh")
    commands = []
    for _ in range(2):  # estimation, validation: commands over 0-10, at rest for 2 s first
        u = _command(rng, command)
        commands.append(np.r_[np.full(200, u[0]), u[:-200]])
    width = float(rng.uniform(0.5, 1.2))
    start = commands[0][0]
    if kind == "rest":
        center = float(start)
    else:  # the band 1.5-3 units to the wider side of where the estimation command starts
        center = float(np.clip(start + (1.0 if start < 5.0 else -1.0) * rng.uniform(1.5, 3.0), 2.5, 7.5))
    out = []
    for u in commands:
        v = dead_zone(u, width, center)
        _, y, _ = signal.dlsim(disc, v - v[0])
        y = np.ravel(y) + gain * float(v[0])  # started in the steady state of the first held command
        y = y + noise * np.std(y) * rng.normal(size=N)
        out.append(record_from_arrays(np.arange(N) * DT, u, y))
    if kind == "off" and abs(commands[0][0] - center) <= 2.0 * width:
        raise ValueError(f"record {seed}: the band is where the command starts")
    nominal = Plant(num * 1.03, np.r_[den[0], den[1:] * np.array([0.97, 1.02])])
    return nominal, out[0], out[1], center, width


def score(job: tuple[int, str, str, float]) -> dict:
    """One record's diagnosis against its truth."""
    from synth.gap.diagnose import diagnose

    seed, kind, command, noise = job
    try:
        nominal, rec, val, center, width = records(seed, kind, command, noise)
    except ValueError:  # not a record of its kind: left out
        return {"seed": seed, "kind": kind, "skipped": True}
    t0 = time.process_time()
    d = diagnose(nominal, rec, val, candidates=CANDIDATES, n_boot=200)
    cpu = time.process_time() - t0
    found = next((e for e in d.attribution.effects if e.effect == "deadzone"), None)
    p = found.parameters if found is not None else {}
    named = d.verdict["effects"] == ["deadzone"]
    located = named and abs(p["center"] - center) < 0.2 and abs(p["width"] - width) < 0.1 * width
    return {"seed": seed, "kind": kind, "named": named, "located": located, "verdict": d.verdict["effects"],
            "center_fitted": bool(p) and p["center"] != float(rec.u[0]), "cpu": cpu}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--kinds", nargs="+", default=["off", "rest"], choices=["off", "rest"])
    ap.add_argument("--command", default="smooth", choices=["smooth", "steps"])
    ap.add_argument("--noise", type=float, default=0.01, help="output noise, a fraction of the output's spread")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    jobs = [(s, k, args.command, args.noise) for k in args.kinds for s in range(args.seeds)]
    with ProcessPoolExecutor(args.jobs) as pool:
        rows = [r for r in pool.map(score, jobs) if not r.get("skipped")]
    print("| band | records | named `deadzone` | center and width within 0.2 / 10 % | center fitted | "
          "CPU per record, median [s] |")
    print("|---|---|---|---|---|---|")
    for kind in args.kinds:
        mine = [r for r in rows if r["kind"] == kind]
        n = len(mine)
        print(f"| {kind} | {n} | {sum(r['named'] for r in mine)} | {sum(r['located'] for r in mine)} | "
              f"{sum(r['center_fitted'] for r in mine)} | {np.median([r['cpu'] for r in mine]):.1f} |")
    for r in rows:
        if not r["located"]:
            print(f"  {r['kind']} seed {r['seed']}: verdict {r['verdict']}")


if __name__ == "__main__":
    main()
