"""Randomized check of the frequency-response fit's standard errors (issue 16): reported against the scatter.

For each of ``--problems`` random plants (first order; a zero and two real poles; a lightly damped pair; some
behind a fitted delay) a logarithmic sweep of random length and sample rate is simulated (:func:`record`)
with white output noise of a random level, ``--seeds`` times with fresh noise.
Each record goes through :func:`synth.ident.spectra.frequency_response` and
:func:`synth.ident.freqfit.fit_frequency_response` with the truth's own structure over the coherent band. The
reference is the fits' own scatter over the noise seeds (independent of the formula under test) and the truth:

- ratio: the mean reported standard error over the empirical standard deviation, per (problem, parameter);
  the issue's band is 0.7-1.4;
- coverage: the share of fits whose 95 % interval holds the true value.

Usage: ``python benchmarks/freqfit_uncertainty.py --problems 30 --seeds 12 --seed 1 [--json F] [--no-widening]``
(``--no-widening``: the baseline without the residual-correlation factor ``kappa``, in the same code).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from synth.data import record_from_arrays
from synth.ident.freqfit import fit_frequency_response
from synth.ident.spectra import frequency_response


def problem(rng: np.random.Generator, index: int) -> dict:
    """One random plant, its structure formula, true parameters and sweep design."""
    kind = ["first", "zero", "resonant"][index % 3]
    delay = float(rng.uniform(0.005, 0.05)) if rng.random() < 0.4 else 0.0
    if kind == "first":
        p = float(np.exp(rng.uniform(np.log(0.5), np.log(20))))
        k = float(p * np.exp(rng.uniform(np.log(0.3), np.log(5))))
        num, den, formula, truth = [k], [1.0, p], "k/(s+p)", {"k": k, "p": p}
        corners = [p]
    elif kind == "zero":
        p1, p2 = sorted(np.exp(rng.uniform(np.log(0.5), np.log(30), 2)))
        if p2 / p1 < 3:
            p2 = 3 * p1
        z = float(np.exp(rng.uniform(np.log(0.3), np.log(30))))
        while min(abs(np.log(z / p1)), abs(np.log(z / p2))) < 0.4:  # no near cancellation
            z = float(np.exp(rng.uniform(np.log(0.3), np.log(30))))
        k = float(p1 * p2 / z * np.exp(rng.uniform(np.log(0.3), np.log(5))))
        a, b = float(p1 + p2), float(p1 * p2)
        num, den = [k, k * z], [1.0, a, b]
        formula, truth = "k*(s+z)/(s^2+a*s+b)", {"k": k, "z": z, "a": a, "b": b}
        corners = [p1, p2, z]
    else:
        wn = float(np.exp(rng.uniform(np.log(1.0), np.log(20))))
        zeta = float(rng.uniform(0.05, 0.5))
        k = float(wn ** 2 * np.exp(rng.uniform(np.log(0.3), np.log(5))))
        a, b = 2 * zeta * wn, wn ** 2
        num, den, formula, truth = [k], [1.0, a, b], "k/(s^2+a*s+b)", {"k": k, "a": a, "b": b}
        corners = [wn]
    if delay:
        formula = formula.replace("k*", "k*exp(-Td*s)*", 1) if formula.startswith("k*") else \
            formula.replace("k/", "k*exp(-Td*s)/", 1)
        truth["Td"] = delay
    w_lo, w_hi = min(corners) / 5.0, max(corners) * 5.0
    duration = float(rng.uniform(60, 240))
    duration = max(duration, 8 * 2 * np.pi / w_lo)  # a few periods of the lowest frequency
    dt = float(min(np.pi / (20 * w_hi), 0.02))
    dt = max(dt, duration / 40000)  # records of at most 40,000 samples
    return {"index": index, "kind": kind, "num": num, "den": den, "delay": delay, "formula": formula,
            "truth": truth, "w": [w_lo, w_hi], "duration": duration, "dt": dt,
            "noise": float(rng.uniform(0.05, 0.5))}


def record(prob: dict, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sweep (a smooth logarithmic chirp, sampled) through the continuous plant: scipy's ``lsim``, whose
    linear interpolation between samples follows the smooth input closely (a held input would add the hold's
    half-sample lag to what the samples show, a structure's delay to fit), the delay exact (the chirp evaluated
    at ``t - delay``); white output noise of ``noise`` times the output's standard deviation."""
    t = np.arange(0.0, prob["duration"], prob["dt"])
    w_lo, w_hi = prob["w"]

    def sweep(time: np.ndarray) -> np.ndarray:
        return np.where(time >= 0.0, signal.chirp(time, w_lo / (2 * np.pi), t[-1], w_hi / (2 * np.pi),
                                                  method="logarithmic"), 0.0)

    u = sweep(t)
    _, y, _ = signal.lsim((prob["num"], prob["den"]), sweep(t - prob["delay"]), t)
    noise = prob["noise"] * float(np.std(y)) * np.random.default_rng(seed).normal(size=t.size)
    return t, u, y + noise


def run(prob: dict, seeds: int) -> dict:
    names = list(prob["truth"])
    values, stds, covered, failures, weak, misfit = [], [], [], 0, 0, 0
    for seed in range(seeds):
        t, u, y = record(prob, 1000 * prob["index"] + seed)
        resp = frequency_response(record_from_arrays(t, u, y), w_min=prob["w"][0], w_max=prob["w"][1])
        try:
            fit = fit_frequency_response(resp, prob["formula"])
        except Exception as exc:  # a FrequencyFitError or any other: every failure is counted, none hidden
            failures += 1
            last_error = f"{type(exc).__name__}: {exc}"
            continue
        unc = fit.uncertainty
        if any(n not in unc.std for n in names):  # a delay held at its bound: no interval of its own
            failures += 1
            last_error = "a parameter at its bound"
            continue
        values.append([fit.parameters[n] for n in names])
        stds.append([unc.std[n] for n in names])
        covered.append([unc.intervals[n][0] <= prob["truth"][n] <= unc.intervals[n][1] for n in names])
        weak += bool(unc.weak)
        misfit += unc.misfit
    out = {**{k: prob[k] for k in ("index", "kind", "formula", "truth", "duration", "dt", "noise")},
           "fits": len(values), "failures": failures}
    if failures:
        out["last_failure"] = last_error
    if len(values) >= 5:
        v, s = np.array(values), np.array(stds)
        emp = v.std(axis=0, ddof=1)
        out["ratio"] = dict(zip(names, (s.mean(axis=0) / emp).tolist()))
        out["coverage"] = dict(zip(names, np.mean(covered, axis=0).tolist()))
        out["bias_over_std"] = dict(zip(names, ((v.mean(axis=0) - np.array([prob["truth"][n] for n in names]))
                                                / emp).tolist()))
        out["weak_share"] = weak / len(values)
        out["misfit_share"] = misfit / len(values)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", type=int, default=30)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", help="write one JSON line per problem")
    ap.add_argument("--no-widening", action="store_true", help="kappa = 1 (the residuals' correlation ignored)")
    args = ap.parse_args()
    if args.no_widening:
        import synth.ident.freqfit_uncertainty as widening

        widening.MAX_RESIDUAL_CORRELATION = 0.0
    rng = np.random.default_rng(args.seed)
    rows, t0 = [], time.process_time()
    sink = open(args.json, "w", encoding="utf-8") if args.json else None
    for i in range(args.problems):
        row = run(problem(rng, i), args.seeds)
        rows.append(row)
        if sink:
            sink.write(json.dumps(row) + "\n")
            sink.flush()
        ratios = " ".join(f"{k} {v:.2f}" for k, v in row.get("ratio", {}).items())
        print(f"{i:3d} {row['kind']:8s} fits {row['fits']:2d} fail {row['failures']:2d}  ratio {ratios}", flush=True)
    pairs = [(r, k) for r in rows if "ratio" in r for k in r["ratio"]]
    within = [0.7 <= r["ratio"][k] <= 1.4 for r, k in pairs]
    cover = [r["coverage"][k] for r, k in pairs]
    ratios = np.array([r["ratio"][k] for r, k in pairs])
    print(f"\n{len(rows)} problems x {args.seeds} seeds, CPU {time.process_time() - t0:.0f} s")
    print(f"(problem, parameter) pairs with reported/empirical std in 0.7-1.4: {sum(within)}/{len(pairs)} "
          f"= {100 * np.mean(within):.1f} %; ratio median {np.median(ratios):.2f}, 5-95 % "
          f"{np.percentile(ratios, 5):.2f}-{np.percentile(ratios, 95):.2f}")
    print(f"95 % interval coverage of the truth: mean {100 * np.mean(cover):.1f} %, pairs below 80 %: "
          f"{sum(c < 0.8 for c in cover)}/{len(cover)}")
    fitted = [r for r in rows if "misfit_share" in r]
    print(f"the right structure said to miss the response: {np.mean([r['misfit_share'] for r in fitted]) * 100:.1f} % "
          f"of fits; a weakly identifiable parameter named: {np.mean([r['weak_share'] for r in fitted]) * 100:.1f} %")
    print(f"fits failed (an error, or a delay held at its bound): {sum(r['failures'] for r in rows)} of "
          f"{len(rows) * args.seeds}")


if __name__ == "__main__":
    main()
