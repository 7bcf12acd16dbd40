"""Does the deterministic start of the simulation-error fit land in the truth's basin? (issue 16)

Each case draws, from its seed, a lightly damped second-order plant ``k w^2/(s^2 + 2 z w s + w^2)`` (``w``
log-uniform from 5 rad/s to 0.3 times the Nyquist frequency, ``z`` log-uniform 0.02-0.7, ``k`` log-uniform
0.2-5), a sample time (0.5-10 ms), a record length (5,000-130,000 samples, log-uniform), an input (a random-phase
multisine, or white noise low-passed above the mode), an input mean, an output offset, white output noise
(2-50 % of the output's std) and a start: from rest, or cut out of a longer run (the plant's state and the
input's level at the first sample are those of an excitation in progress, as in the multisine part of the real
Silverbox record).

Each record is fitted by :func:`synth.ident.timefit.fit_structure` from its deterministic start, and again from
the truth (``initial=``). ``w`` and ``z`` are compared as the positive equivalent (``(-w, -z)`` is the same
plant). Two rates:

- in the truth's basin: the fit from the deterministic start did not fail and ends where the fit from the truth
  ends (every parameter within 0.5 of its standard error): the start is the one under test;
- within 5 std: the fit did not fail and every parameter lies within 5 of its reported standard errors of the
  truth. A record cut out of a running excitation starts off rest, which the fit's model (from rest, with an
  output offset) leaves out: on a short record with a slowly decaying mode that start-up transient biases even
  the fit from the truth by more than that, whatever the start.

Since session 46 every whole-record fit tests its start state (:mod:`synth.ident.start_state`) and
:func:`synth.ident.identification.identify` (``average="none"``) fits a record whose start state matters again
from where it has died out (:mod:`synth.ident.unknown_start`). Each case is identified that way too:

- after the start test: identify did not fail and every parameter lies within 5 of its reported standard errors;
- start left out: identify left out a start (on a record from rest, a false alarm).

Run:  nice -n 10 python benchmarks/ident_cut_records.py [--cases 60] [--seed 45] [--json out.jsonl]
      (PYTHONPATH=<other checkout> runs another version of synth on the same cases)
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import numpy as np
from scipy.signal import butter, sosfilt

from synth.data import record_from_arrays
from synth.errors import FitError
from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.ident.timefit import fit_structure
from synth.plant import Plant

STRUCTURE = "k*w^2/(s^2+2*z*w*s+w^2)"


def make_case(seed: int, index: int) -> dict[str, Any]:
    """One case's record and truth, drawn from ``(seed, index)``.

    Examples
    --------
    >>> case = make_case(45, 0)
    >>> sorted(case["truth"]), case["u"].size == case["t"].size == case["y"].size
    (['k', 'w', 'z'], True)
    """
    rng = np.random.default_rng([seed, index])
    dt = float(10 ** rng.uniform(np.log10(5e-4), -2.0))
    nyquist = np.pi / dt
    w = float(10 ** rng.uniform(np.log10(5.0), np.log10(0.3 * nyquist)))
    z = float(10 ** rng.uniform(np.log10(0.02), np.log10(0.7)))
    k = float(10 ** rng.uniform(np.log10(0.2), np.log10(5.0)))
    n = int(10 ** rng.uniform(np.log10(5000), np.log10(130000)))
    kind = str(rng.choice(["multisine", "noise"]))
    start = str(rng.choice(["rest", "cut"]))
    settle = int(np.ceil(8.0 / (z * w) / dt))  # the transient decays to e^-8
    pre = settle + int(rng.integers(0, 2000)) if start == "cut" else 0
    total = n + pre
    f_hi = float(rng.uniform(min(1.5 * w, 0.9 * nyquist), 0.9 * nyquist))
    if kind == "multisine":
        period = int(min(total, 2 ** int(rng.integers(12, 15))))
        bins = np.arange(1, int(f_hi * period * dt / (2 * np.pi)) + 1)
        tt = np.arange(period) * dt
        phases = rng.uniform(0, 2 * np.pi, bins.size)
        one = np.sum(np.cos(2 * np.pi * bins[:, None] * tt[None, :] / (period * dt) + phases[:, None]), axis=0)
        x = np.tile(one, total // period + 1)[:total]
    else:
        sos = butter(4, min(f_hi / nyquist, 0.95), output="sos")
        x = sosfilt(sos, rng.normal(size=total + 500))[500:]
    x = x / np.std(x)
    u_mean = float(rng.uniform(-1.0, 1.0))
    u = u_mean + x
    if start == "rest":  # hold the first level a while, then excite
        hold = int(rng.integers(20, 500))
        u = np.r_[np.full(hold, u[0]), u[:total - hold]]
    truth = {"k": k, "w": w, "z": z}
    plant = Plant(np.array([k * w * w]), np.array([1.0, 2 * z * w, w * w]))
    t_all = np.arange(total) * dt
    y_clean = simulate_plant(plant, t_all, u)[pre:]
    u = u[pre:]
    t = np.arange(n) * dt
    noise = float(10 ** rng.uniform(np.log10(0.02), np.log10(0.5))) * float(np.std(y_clean))
    y = y_clean + float(rng.uniform(-2, 2)) * k + noise * rng.normal(size=n)
    return {"seed": seed, "index": index, "dt": dt, "n": n, "kind": kind, "start": start, "noise": noise,
            "truth": truth, "t": t, "u": u, "y": y}


def canonical(params: dict[str, float]) -> dict[str, float]:
    """``(k, w, z)`` with ``w >= 0`` (``(-w, -z)`` is the same plant).

    Examples
    --------
    >>> canonical({"k": 1.0, "w": -3.0, "z": -0.1})
    {'k': 1.0, 'w': 3.0, 'z': 0.1}
    """
    sign = -1.0 if params["w"] < 0 else 1.0
    return {"k": params["k"], "w": sign * params["w"], "z": sign * params["z"]}


def run_case(case: dict[str, Any]) -> dict[str, Any]:
    """Fit one case from the deterministic start; its distance to the truth in standard errors."""
    t0 = time.perf_counter()
    fit = fit_structure(record_from_arrays(case["t"], case["u"], case["y"]), STRUCTURE)
    elapsed = time.perf_counter() - t0
    ref = fit_structure(record_from_arrays(case["t"], case["u"], case["y"]), STRUCTURE, initial=case["truth"])
    got, start, best = canonical(fit.parameters), canonical(fit.initial), canonical(ref.parameters)
    sigmas = {p: abs(got[p] - case["truth"][p]) / max(fit.std[p], 1e-300) for p in ("k", "w", "z")}
    to_ref = max(abs(got[p] - best[p]) / max(ref.std[p], 1e-300) for p in ("k", "w", "z"))
    failure = fit.solver.get("failure", "")
    worst = max(sigmas.values())
    t1 = time.perf_counter()
    try:
        res = identify(record_from_arrays(case["t"], case["u"], case["y"]), STRUCTURE, average="none",
                       compare_directions=False)
        after, left_out, first = canonical(res.fit.parameters), bool(res.whole_record_note), \
            float(res.fit.solver["start_state"]["first"])
        after_sigmas = {p: abs(after[p] - case["truth"][p]) / max(res.fit.std[p], 1e-300) for p in ("k", "w", "z")}
        after_failure = ""
    except FitError as exc:
        after_sigmas = {p: float("inf") for p in ("k", "w", "z")}
        left_out, first, after_failure = False, float("nan"), str(exc)
    after_seconds = time.perf_counter() - t1
    return {"seed": case["seed"], "index": case["index"], "n": case["n"], "dt": case["dt"], "kind": case["kind"],
            "start": case["start"], "truth": case["truth"], "fit": fit.parameters, "std": fit.std,
            "initial": fit.initial, "start_w_ratio": start["w"] / case["truth"]["w"], "start_z": start["z"],
            "sigmas": sigmas, "worst_sigma": worst, "fit_percent": fit.fit_percent, "failure": failure,
            "to_truth_start_fit": to_ref, "truth_start_fit": ref.parameters,
            "in_basin": (not failure) and to_ref <= 0.5, "within_5_std": (not failure) and worst <= 5.0,
            "negative_w": fit.parameters["w"] < 0,
            "seconds": elapsed, "after_sigmas": after_sigmas, "after_worst_sigma": max(after_sigmas.values()),
            "after_within_5_std": (not after_failure) and max(after_sigmas.values()) <= 5.0,
            "start_left_out": left_out, "first_fitted": first, "after_failure": after_failure,
            "after_seconds": after_seconds}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=60)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--seed", type=int, default=45)
    ap.add_argument("--json", default=None, help="append one JSON line per case")
    args = ap.parse_args()
    hits = near = negative = after_near = 0
    left_out = {"rest": [0, 0], "cut": [0, 0]}  # start left out, cases
    done = 0
    for i in range(args.first, args.first + args.cases):
        row = run_case(make_case(args.seed, i))
        done += 1
        hits += row["in_basin"]
        near += row["within_5_std"]
        negative += row["negative_w"]
        after_near += row["after_within_5_std"]
        left_out[row["start"]][0] += row["start_left_out"]
        left_out[row["start"]][1] += 1
        tr, st = row["truth"], row["initial"]
        print(f"{i:3d} n={row['n']:6d} dt={row['dt'] * 1e3:5.2f}ms {row['kind']:9s} {row['start']:4s} "
              f"w={tr['w']:8.2f} z={tr['z']:.3f} | start w={st['w']:10.3g} z={st['z']:8.3g} | "
              f"worst {row['worst_sigma']:9.3g} sd, {row['to_truth_start_fit']:9.3g} sd from the truth's fit, fit "
              f"{row['fit_percent']:6.2f} % {'OK ' if row['in_basin'] else 'OUT'} {row['seconds']:5.1f}s "
              f"{row['failure'][:50]} | after the start test worst {row['after_worst_sigma']:8.3g} sd"
              f"{(', from ' + format(row['first_fitted'], '.4g') + ' s') if row['start_left_out'] else ''} "
              f"{row['after_seconds']:5.1f}s "
              f"{row['after_failure'][:60]}", flush=True)
        if args.json:
            with open(args.json, "a") as fh:
                fh.write(json.dumps(row) + "\n")
    print(f"in the truth's basin: {hits}/{done} ({100.0 * hits / max(done, 1):.1f} %); within 5 std of the truth: "
          f"{near}/{done} ({100.0 * near / max(done, 1):.1f} %); negative w reported: {negative}")
    print(f"after the start test (identify): within 5 std {after_near}/{done}; start left out on "
          f"{left_out['cut'][0]}/{left_out['cut'][1]} cut records and {left_out['rest'][0]}/{left_out['rest'][1]} "
          "records from rest")


if __name__ == "__main__":
    main()
