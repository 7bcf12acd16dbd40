"""The disturbance shape fit with and without the first Welch bin, over seeds of the X-4 synthetic disturbance
(session 44): each segment's detrend reads the first bin low (0.8 dB with the mean removed, 1.4 dB with a line).

Run: ``python benchmarks/disturbance_first_bin.py [--seeds 20]``
"""

from __future__ import annotations

import argparse

import numpy as np

from synth.ident.disturbance_requirements import fit_disturbance_shape
from synth.ident.disturbance_synthetic import X4_SYNTHETIC_SHAPE, synthetic_disturbance_record, synthetic_noise_record
from synth.ident.psd import analyze_records
from synth.ident.spectrum_features import find_spikes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    args = ap.parse_args()
    shape = X4_SYNTHETIC_SHAPE
    fits: dict[str, list[tuple[float, float]]] = {"with the first bin": [], "without it": []}
    for seed in range(args.seeds):
        a = analyze_records([synthetic_disturbance_record(shape, seed=100 + seed)],
                            [synthetic_noise_record(shape, seed=200 + seed)])
        _, spikes = find_spikes(a.w, a.psd)
        first = a.w < 1.5 * (a.w[1] - a.w[0])
        for label, mask in (("with the first bin", spikes), ("without it", spikes | first)):
            f = fit_disturbance_shape(a.w, a.psd, a.floor, mask)
            fits[label].append((f.plateau_db, f.corner))
    print(f"X-4 synthetic shape: plateau {shape.plateau_db} dB, corner {shape.corner} rad/s; {args.seeds} seeds\n")
    print("| fit | plateau error mean / std / rms [dB] | corner error mean / rms [%] |\n|---|---|---|")
    for label, rows in fits.items():
        x = np.array(rows)
        e, c = x[:, 0] - shape.plateau_db, 100 * (x[:, 1] / shape.corner - 1)
        print(f"| {label} | {e.mean():+.3f} / {e.std():.3f} / {np.sqrt(np.mean(e**2)):.3f} | "
              f"{c.mean():+.2f} / {np.sqrt(np.mean(c**2)):.2f} |")


if __name__ == "__main__":
    main()
