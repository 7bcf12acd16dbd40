"""Does moving the output back by the response's delay before windowing help on sweeps nobody tuned it on?

Random plants (first or second order, lightly to well damped, gains and time constants over decades), pure delays
from none to several seconds, logarithmic sweeps of random range and length with rest before and after, 50 or 100 Hz,
1 % output noise; simulated with scipy (``lsim``, the input held, the delay in whole samples). Each record is
estimated twice in one run: the windows on the runs as they are (the estimate before session 63, ``align=False``)
and :func:`synth.ident.spectra.frequency_response` (realigned where its rule says so). Against the
truth ``G`` times the hold's response over each coherent band: the share of points within 3 random errors in
magnitude and phase, and the largest magnitude error.

    python benchmarks/freqresp_alignment.py --cases 60 --seed 1
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from synth.data import record_from_arrays
from synth.ident import spectra


def case(rng: np.random.Generator) -> dict:
    """One random plant, delay and sweep."""
    order = int(rng.integers(1, 3))
    gain = float(10 ** rng.uniform(-1, 1))
    if order == 1:
        tau = float(10 ** rng.uniform(-1.5, 0.5))
        num, den = [gain], [tau, 1.0]
    else:
        wn, zeta = float(10 ** rng.uniform(-0.5, 1)), float(rng.uniform(0.1, 1.0))
        num, den = [gain * wn**2], [1.0, 2 * zeta * wn, wn**2]
    delay = float(rng.choice([0.0, 0.0, rng.uniform(0.05, 0.5), rng.uniform(0.5, 3.0)]))
    w_lo = float(10 ** rng.uniform(-1.3, -0.3))
    w_hi = float(w_lo * 10 ** rng.uniform(1.2, 2.0))
    dt = float(rng.choice([0.01, 0.02]))
    delay = round(delay / dt) * dt  # whole samples, as simulated
    w_hi = min(w_hi, 0.15 * np.pi / dt)
    length = float(rng.uniform(120.0, 400.0))
    return {"num": num, "den": den, "delay": delay, "w_lo": w_lo, "w_hi": w_hi, "dt": dt, "length": length,
            "seed": int(rng.integers(1 << 30))}


def record(c: dict):
    dt, rest = c["dt"], 5.0
    t = np.arange(0.0, c["length"] + 2 * rest, dt)
    inside = (t >= rest) & (t <= rest + c["length"])
    u = np.where(inside, signal.chirp(t - rest, c["w_lo"] / (2 * np.pi), c["length"], c["w_hi"] / (2 * np.pi),
                                      method="logarithmic"), 0.0)
    y = signal.lsim((c["num"], c["den"]), u, t, interp=False)[1]
    k = round(c["delay"] / dt)
    if k:
        y = np.r_[np.zeros(k), y[:-k]]
    y = y + 0.01 * np.std(y) * np.random.default_rng(c["seed"]).normal(size=t.size)
    return record_from_arrays(t, u, y)


def score(resp, c: dict) -> tuple[float, float]:
    """Share of band points within 3 random errors (magnitude and phase) and the largest |dB| error."""
    inside = resp.band.contains(resp.w)
    if not inside.any():
        return float("nan"), float("nan")
    w = resp.w[inside]
    s = 1j * w
    truth = np.polyval(c["num"], s) / np.polyval(c["den"], s) * np.exp(-s * c["delay"]) \
        * (1 - np.exp(-s * c["dt"])) / (s * c["dt"])
    ratio = resp.H[inside] / truth
    err = resp.random_error[inside]
    ok = (np.abs(np.abs(ratio) - 1) <= 3 * err) & (np.abs(np.angle(ratio)) <= 3 * err)
    return float(np.mean(ok)), float(np.max(np.abs(20 * np.log10(np.abs(ratio)))))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=60)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    rows = []
    for i in range(args.cases):
        c = case(rng)
        r = record(c)
        before = spectra.frequency_response(r, align=False)
        after = spectra.frequency_response(r)
        aligned = any("output was moved" in n for n in after.notes)
        rows.append((c["delay"], aligned, *score(before, c), *score(after, c)))
        print(f"{i:3d} delay {c['delay']:5.2f} s aligned {aligned!s:5} within-3: {rows[-1][2]:.2f} -> "
              f"{rows[-1][4]:.2f}  max dB {rows[-1][3]:.2f} -> {rows[-1][5]:.2f}", flush=True)
    a = np.array([row[2:] for row in rows], float)
    aligned = np.array([row[1] for row in rows])
    long_delay = np.array([row[0] >= 0.5 for row in rows])
    print(f"\n| {args.cases} sweeps | points within 3 random errors, before | after | max dB error (median), before "
          "| after |")
    print("|---|---|---|---|---|")
    for name, sel in (("all", np.ones(len(rows), bool)), ("realigned", aligned), ("delay >= 0.5 s", long_delay)):
        if sel.any():
            print(f"| {name} ({sel.sum()}) | {np.nanmean(a[sel, 0]):.3f} | {np.nanmean(a[sel, 2]):.3f} | "
                  f"{np.nanmedian(a[sel, 1]):.2f} | {np.nanmedian(a[sel, 3]):.2f} |")
    worse = aligned & (a[:, 2] < a[:, 0] - 0.05)
    print(f"\nrealigned and 5 points of share worse: {int(worse.sum())} of {int(aligned.sum())}")


if __name__ == "__main__":
    main()
