"""Frequency-sweep identification: composite accuracy and speed.

(a) Accuracy. Two sweep runs (:func:`synth.ident.sweep_design.design_sweep`) through
a known plant, white output noise of a given fraction of the output's standard
deviation. The error against the exact response is the RMS of ``|H_est/H - 1|``
over the composite's coherent band on its log grid. Baselines in the same run:
single-window ``scipy.signal.csd`` / ``scipy.signal.welch`` (Hann, 50 % overlap,
the two runs' segments averaged) with the window ``w_min`` needs (``2 * 2 pi / w_min``
= 31.4 s) and with the composite's middle window, interpolated onto the same grid;
and synth's own single 31.4 s window (segments spread to the run's end, bins
averaged on the grid), which separates the gain from the composite from the gain
from covering the whole run.

(b) Speed. Two 90 s runs at 1 kHz (2 x 90,001 samples) end to end
(``frequency_response``: 5 windows, spectra, composite, coherent band), against
one single-window ``scipy.signal.csd`` + ``welch`` over the same data.

Run: ``python benchmarks/freqresp.py`` (about 20 s).
"""

from __future__ import annotations

import time

import numpy as np
from scipy.signal import csd, welch

from synth.data import record_from_arrays
from synth.ident.simulate import simulate_plant
from synth.ident.spectra import frequency_response
from synth.ident.spectral_windows import required_window
from synth.ident.sweep_design import design_sweep
from synth.plant import Plant

PLANTS = {
    "roll 31.6e^-0.041s/((s+0.49)(s+2.3))": (Plant.from_string("31.6/((s+0.49)*(s+2.30))", delay=0.041), 0.4, 12.0),
    "5e^-0.05s/(s^2+2s+4)": (Plant.from_string("5/(s^2+2*s+4)", delay=0.05), 0.4, 12.0),
}


def runs(plant: Plant, w_min: float, w_max: float, noise: float, seed: int, fs: float = 100.0):
    rng = np.random.default_rng(seed)
    design = design_sweep(w_min, w_max)
    out = []
    for _ in range(2):
        t, u = design.signal(1.0, fs)
        u = u + 0.02 * rng.standard_normal(t.size)      # a pilot is not a signal generator
        y = simulate_plant(plant, t, u, "zero")
        out.append(record_from_arrays(t, u, y + noise * np.std(y) * rng.standard_normal(t.size)))
    return out


def scipy_single(records, window: float, grid: np.ndarray) -> np.ndarray:
    fs = records[0].fs
    n = round(window * fs)
    pxy = sum(csd(r.u, r.y, fs=fs, window="hann", nperseg=n, detrend="linear")[1] for r in records)
    f, pxx = 0, 0
    for r in records:
        f, p = welch(r.u, fs=fs, window="hann", nperseg=n, detrend="linear")
        pxx = pxx + p
    H = pxy / pxx
    w = 2 * np.pi * f
    return np.interp(grid, w, H.real) + 1j * np.interp(grid, w, H.imag)


def accuracy() -> None:
    print("(a) error against the exact response over the composite's coherent band: RMS |H/H0 - 1|")
    print(f"{'plant':38s} {'noise':>5s} {'seed':>4s} {'band [rad/s]':>14s} {'composite':>9s} "
          f"{'csd 31.4 s':>11s} {'csd middle':>10s} {'synth 31.4 s':>13s}")
    wins = 0
    total = 0
    for name, (plant, w_min, w_max) in PLANTS.items():
        for noise in (0.05, 0.2, 0.5):
            for seed in (1, 2, 3):
                recs = runs(plant, w_min, w_max, noise, seed)
                r = frequency_response(recs, w_min, w_max)
                if not r.band.found:
                    print(f"{name:38s} {noise:5.2f} {seed:4d}  no coherent band")
                    continue
                m = r.band.contains(r.w)
                H0 = plant.freqresp(r.w[m])

                def err(H: np.ndarray, H0: np.ndarray = H0) -> float:
                    return float(np.sqrt(np.mean(np.abs(H / H0 - 1) ** 2)))

                e_c = err(r.H[m])
                need = required_window(w_min)      # 2 * 2 pi / w_min: the single window w_min needs
                e_long = err(scipy_single(recs, need, r.w)[m])
                e_mid = err(scipy_single(recs, r.windows[len(r.windows) // 2], r.w)[m])
                r1 = frequency_response(recs, w_min, w_max, windows=[need])
                e_one = err(r1.H[m])
                wins += e_c < min(e_long, e_mid)
                total += 1
                band = f"{r.band.w_min:.2f}-{r.band.w_max:.2f}"
                print(f"{name:38s} {noise:5.2f} {seed:4d} {band:>14s} {e_c:9.4f} {e_long:11.4f} {e_mid:10.4f} {e_one:13.4f}")
    print(f"composite closer than both scipy single windows in {wins} of {total} cases\n")


def speed(repeats: int = 5) -> None:
    fs = 1000.0
    plant, w_min, w_max = PLANTS["roll 31.6e^-0.041s/((s+0.49)(s+2.3))"]
    recs = runs(plant, w_min, w_max, 0.1, 7, fs)

    def best(f) -> float:
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            f()
            times.append(time.perf_counter() - t0)
        return min(times)

    t_comp = best(lambda: frequency_response(recs, w_min, w_max))
    t_one = best(lambda: frequency_response(recs, w_min, w_max, windows=[2 * 2 * np.pi / w_min]))
    t_scipy = best(lambda: scipy_single(recs, 2 * 2 * np.pi / w_min, np.geomspace(w_min, w_max, 100)))
    print(f"(b) two 90 s runs at 1 kHz ({recs[0].n} + {recs[1].n} samples), best of {repeats}; goal < 2 s")
    print(f"{'method':50s} {'time [s]':>9s}")
    print(f"{'synth frequency_response, composite (5 windows)':50s} {t_comp:9.3f}")
    print(f"{'synth frequency_response, one window (31.4 s)':50s} {t_one:9.3f}")
    print(f"{'scipy.signal.csd + welch, one window (baseline)':50s} {t_scipy:9.3f}")


if __name__ == "__main__":
    accuracy()
    speed()
