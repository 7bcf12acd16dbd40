"""Whole-record identification of a 420,000-sample step train: before and after, in one run (issue 16, item 1).

Record: the issue's example (15(s+0.8)/((s+12)(s+0.9)) e^(-0.015 s) behind the X-4 sensor
442/((s+45)(s+9.7)), +-25 around 200, a new random level every 2 s so the slow mode never settles,
output noise std 1.5) for 420 s at 1 kHz. ``synth.ident.identify`` averages the edges, finds the
model does not settle within a window and fits the whole record (deterministic start: the
edge fit; no multistart).

- after:  records longer than ``synth.ident.timefit.LONG_RECORD`` samples are fitted by
  :class:`synth.ident.convolution_problem.ConvolutionProblem` (FFT convolution, Levenberg-Marquardt);
- before: the same call with ``LONG_RECORD`` raised above the record length, i.e. casadi's symbolic
  recursion over the whole record and IPOPT (what every record used before).

Goal: under 10 s for the whole identification (the up/down comparison included).

Run:  python benchmarks/ident_whole_record_speed.py [--seconds 420]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import synth.ident.timefit as timefit  # noqa: E402
from synth.ident.identification import identify  # noqa: E402
from synth.ident.simulate import simulate_plant  # noqa: E402
from synth.plant import Plant  # noqa: E402

SENSOR = "442/((s+45)*(s+9.7))"
STRUCTURE = "k*(s+z)/((s+p1)*(s+p2))"
TRUTH = {"k": 15.0, "z": 0.8, "p1": 12.0, "p2": 0.9, "delay": 0.015}


def record(seconds: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.arange(0, seconds, 0.001)
    levels = np.where(np.random.default_rng(100).random(int(seconds // 2) + 1) < 0.5, 175.0, 225.0)
    levels[:2] = (175.0, 225.0)
    u = levels[(t // 2.0).astype(int)]
    f = Plant.from_string("15*(s+0.8)/((s+12)*(s+0.9))").series(Plant.from_string(SENSOR))
    y = 800 + simulate_plant(Plant(f.num, f.den, 0.015), t, u - u[0]) + 1.5 * np.random.default_rng(3).normal(size=t.size)
    return t, u, y


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=420.0)
    args = ap.parse_args()
    t, u, y = record(args.seconds)
    rows = []
    default = timefit.LONG_RECORD
    for label, limit in (("after: FFT convolution + Levenberg-Marquardt", default),
                         ("before: casadi recursion + IPOPT", 10 * t.size)):
        timefit.LONG_RECORD = limit
        t0 = time.perf_counter()
        res = identify((t, u, y), STRUCTURE, delay="fit", sensor=SENSOR)
        rows.append((label, time.perf_counter() - t0, res))
    timefit.LONG_RECORD = default
    print(f"{t.size} samples; {rows[0][2].whole_record_note}")
    print(f"{'':<48}{'seconds':>8}{'iterations':>11}  " + "".join(f"{k:>12}" for k in TRUTH))
    print(f"{'truth':<48}{'':>8}{'':>11}  " + "".join(f"{v:>12.6g}" for v in TRUTH.values()))
    for label, secs, res in rows:
        p = dict(res.fit.parameters)
        if p["p1"] < p["p2"]:
            p["p1"], p["p2"] = p["p2"], p["p1"]
        print(f"{label:<48}{secs:>8.2f}{res.fit.solver['iterations']:>11}  " + "".join(f"{p[k]:>12.6g}" for k in TRUTH))
    print(f"speed-up {rows[1][1] / rows[0][1]:.1f}x; goal < 10 s: {'met' if rows[0][1] < 10 else 'NOT met'}")


if __name__ == "__main__":
    main()
