"""A biproper structure with a fitted delay: estimates and reported standard deviations over noise seeds.

The record: steps of 1 every 4 s through ``2(s+0.5)/(s+2) e^(-tau s)`` (40 s at 5 ms), white output noise of
0.01, fitted with ``k*(s+z)/(s+p)`` and ``--delay fit`` (``synth.ident.identification.identify``). Printed per
seed: the estimates; then the mean, the empirical standard deviation, the median reported one and their ratio
(the issue asks 0.7-1.4). The delay's whole samples should be the truth's (the fit walks to the best sample
interval, ``synth.ident.delay_samples``); its reported spread is a sample's uniform one (``synth.ident.covariance``).

Run:  python benchmarks/ident_biproper_delay.py [--seeds 20] [--delay 0.1025]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def main() -> None:
    from synth.ident.identification import identify
    from synth.ident.simulate import simulate_plant
    from synth.plant import Plant

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--delay", type=float, default=0.1025)
    args = parser.parse_args()
    t = np.arange(0, 40, 0.005)
    u = np.where((t % 8) >= 4, 1.0, 0.0)
    clean = simulate_plant(Plant.from_string("2*(s+0.5)/(s+2)", delay=args.delay), t, u)
    names = ("k", "z", "p", "delay")
    estimates, reported = [], []
    for seed in range(args.seeds):
        y = clean + 0.01 * np.random.default_rng(seed).standard_normal(t.size)
        fit = identify((t, u, y), "k*(s+z)/(s+p)", delay="fit").fit
        estimates.append([fit.parameters[k] for k in names])
        reported.append([fit.std[k] for k in names])
        print(f"seed {seed:2d}: " + ", ".join(f"{k} {v:.5g}" for k, v in zip(names, estimates[-1])), flush=True)
    est, rep = np.array(estimates), np.array(reported)
    empirical = est.std(axis=0, ddof=1)
    print("\n| parameter | truth | mean | empirical std | reported std (median) | reported / empirical |")
    print("|---|---|---|---|---|---|")
    for i, (k, truth) in enumerate(zip(names, (2.0, 0.5, 2.0, args.delay))):
        median = float(np.median(rep[:, i]))
        print(f"| {k} | {truth:g} | {est[:, i].mean():.5g} | {empirical[i]:.3g} | {median:.3g} | "
              f"{median / empirical[i]:.2f} |")


if __name__ == "__main__":
    main()
