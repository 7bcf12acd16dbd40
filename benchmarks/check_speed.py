"""Whole-process time of `synth check` on the X-4 spec, against baselines measured in the same run.

Baselines: the bare interpreter start (the floor), and the same three numbers (static
sensitivity, bandwidth, slew-rate peak) computed with python-control in a fresh process.
Goal: synth check under 2 s.

Run:  python benchmarks/check_speed.py [--repeat 10]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PYTHON_CONTROL_EQUIVALENT = """
import control, numpy as np
s = control.tf('s'); G = 23*(s+0.43)/((s+9.6)*(s+0.54)); K = 3
S0 = 20*np.log10(1/(1+K*1.8)); bw = control.bandwidth(control.feedback(K*G, 1))
w = np.geomspace(0.1, 100, 2000); slew = (5*K*w).max()
print(S0, bw, slew)
"""

CASES = {
    "python -c pass (interpreter floor)": [sys.executable, "-c", "pass"],
    "python-control equivalent (3 numbers)": [sys.executable, "-c", PYTHON_CONTROL_EQUIVALENT],
    "synth check specs/x4_rotor.yaml -c 'P(3)'": [sys.executable, "-m", "synth", "check",
                                                   "specs/x4_rotor.yaml", "--controller", "P(3)"],
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=10)
    args = parser.parse_args()
    rows = []
    for name, cmd in CASES.items():
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True)
            times.append(time.perf_counter() - t0)
        rows.append((name, statistics.median(times), min(times), max(times)))
    print(f"{'case':44s} {'median [s]':>10s} {'min [s]':>8s} {'max [s]':>8s}")
    for name, med, lo, hi in rows:
        print(f"{name:44s} {med:10.3f} {lo:8.3f} {hi:8.3f}")
    synth_median = rows[-1][1]
    print(f"\ngoal: synth check under 2 s -> {'MET' if synth_median < 2.0 else 'NOT MET'} "
          f"({synth_median:.2f} s median over {args.repeat} runs)")


if __name__ == "__main__":
    main()
