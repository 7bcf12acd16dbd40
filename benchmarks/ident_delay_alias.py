"""``synth identify --delay fit`` on step trains whose delay is longer than half their period (issue 16; session 62).

The averaged period of a train fits a delay ``d`` as well as ``d + j P`` (and a train holding its two levels alike,
``d + P/2 + j P`` with the gain reversed); only what is not periodic tells them apart. Random problems: a plant of
order 1 or 2 (real poles 0.5-10 rad/s, sometimes a zero, a gain of either sign), a period of 1-4 s (at least
twice the slowest pole's settling time), a delay of 0.55-3.5 periods, a two-level train (half of them holding
both levels alike, the others a duty of 0.3-0.7), a rest of 1.2-2 times the settling time plus the delay before
it, 12-20 periods, noise 0.5-3 % of the step; or, with ``--kind edges``, steps at random intervals of 0.5-1.5
delays plus half a settling time. The record is simulated by scipy (``cont2discrete`` at a tenth of the sample time, the
delay a whole number of those steps), not by synth. A case is right when the fitted delay is within 4 of its
reported standard errors (or 2 samples) of the truth and the static gain within 5 %; it found the right alias when
the delay is within a quarter period of the truth (with ``--kind edges``, 10 % of the delay).

Run:  python benchmarks/ident_delay_alias.py [--cases 40] [--seed 0] [--kind trains|edges]
      (with ``PYTHONPATH`` and the script of another checkout for a baseline)
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from synth.data import record_from_arrays
from synth.errors import SynthError
from synth.ident.identification import identify

DT = 0.01
FINE = 10


def simulate(num: np.ndarray, den: np.ndarray, u: np.ndarray, delay: float) -> np.ndarray:
    """The output at the samples of the held input, the delay a whole number of tenth-samples."""
    a, b, c, d, _ = signal.cont2discrete(signal.tf2ss(num, den), DT / FINE, method="zoh")
    fine = np.repeat(u, FINE)
    k = round(delay / (DT / FINE))
    fine = np.r_[np.zeros(k), fine[: fine.size - k]]
    _, y, _ = signal.dlsim((a, b, c, d, DT / FINE), fine)
    return y.ravel()[::FINE]


def case(seed: int, index: int, kind: str) -> dict:
    """One random problem: the record, the structure to fit and the truth."""
    rng = np.random.default_rng([seed, index])
    order = int(rng.integers(1, 3))
    poles = np.sort(rng.uniform(0.5, 10.0, order))
    zero = order == 2 and rng.random() < 0.4
    z = float(rng.uniform(0.3, 3.0)) * float(poles[0]) if zero else None
    gain = float(rng.uniform(0.5, 5.0)) * (1 if rng.random() < 0.7 else -1)
    den = np.poly(-poles)
    num = gain * np.prod(poles) * (np.array([1.0 / z, 1.0]) if zero else np.array([1.0]))
    settle = 5.0 / poles[0]
    if kind == "trains":
        period = max(float(rng.uniform(1.0, 4.0)), 2 * settle)
        delay = round(float(rng.uniform(0.55, 3.5)) * period, 3)
        duty = 0.5 if rng.random() < 0.5 else float(rng.uniform(0.3, 0.7))
        rest = float(rng.uniform(1.2, 2.0)) * (settle + delay)
        n = round((rest + int(rng.integers(12, 21)) * period) / DT)
        t = np.arange(n) * DT
        u = np.where(t < rest, 0.0, (np.mod(t - rest, period) < duty * period - 1e-9).astype(float))
    else:
        period = 0.0
        delay = round(float(rng.uniform(0.5, 3.0)), 3)
        rest = 1.5 * (settle + delay)
        edges = rest + np.cumsum(rng.uniform(0.5, 1.5, 200) * delay + 0.5 * settle)
        n = round((edges[40] if edges.size > 40 else edges[-1]) / DT)
        t = np.arange(n) * DT
        u = np.zeros(n)
        for i, e in enumerate(edges[edges < t[-1]]):
            u[t >= e] = (i + 1) % 2
    y = simulate(num, den, u, delay)
    y = y + float(rng.uniform(0.005, 0.03)) * abs(gain) * rng.normal(size=n)
    structure = ("K/(T*s+1)" if order == 1 else
                 "k*(s+z)/((s+p1)*(s+p2))" if zero else "k/((s+p1)*(s+p2))")
    return {"record": record_from_arrays(t, u, y), "structure": structure, "delay": delay, "gain": gain,
            "period": period}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=40)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--kind", choices=("trains", "edges"), default="trains")
    args = parser.parse_args()
    right, alias, failed, times = 0, 0, 0, []
    for i in range(args.cases):
        c = case(args.seed, i, args.kind)
        t0 = time.process_time()
        try:
            res = identify(c["record"], c["structure"], delay="fit")
        except SynthError as exc:
            failed += 1
            print(f"{i:3d} {c['structure']:26s} delay {c['delay']:7.3f}: failed ({str(exc)[:80]})", flush=True)
            continue
        times.append(time.process_time() - t0)
        d, sd = res.fit.delay, res.fit.std.get("delay", np.nan)
        gain = res.fit.plant.dc_gain()
        ok = abs(d - c["delay"]) <= max(4 * sd, 2 * DT) and abs(gain / c["gain"] - 1) <= 0.05
        right += ok
        near = abs(d - c["delay"]) < 0.25 * c["period"] if c["period"] else abs(d - c["delay"]) < 0.1 * c["delay"]
        alias += near
        print(f"{i:3d} {c['structure']:26s} delay {c['delay']:7.3f} (period {c['period']:.3g}): fitted {d:8.4f} +- "
              f"{sd:.2g}, gain {gain:8.4g} ({c['gain']:.4g}) {'right' if ok else 'WRONG'}"
              f"{'' if near else ', another alias'} ({times[-1]:.1f} s)", flush=True)
    print(f"\n{args.kind}, seed {args.seed}: right {right} of {args.cases}, the delay within a quarter period (edges: "
          f"10 %) of the truth {alias}, failed (exit 1) {failed}, "
          f"CPU median {np.median(times):.2f} s, p95 {np.percentile(times, 95):.2f} s")


if __name__ == "__main__":
    main()
