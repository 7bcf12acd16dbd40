"""Identification from records with UNEVEN time stamps, over random problems, against an independent reference.

Real loggers write uneven time stamps; ``synth.ident.identify`` resamples such a record onto a uniform grid (the
input held, the output interpolated; ``docs/identification.md``, "Time stamps") and fits a structure. This
benchmark draws random problems unlike any worked example and asks, per case and parameter, over noise seeds:

(a) bias:     |mean - truth| <= 0.5 empirical std (a t-statistic is printed too; with 20 seeds it is noisy);
(b) std:      0.7 <= empirical std / mean reported std <= 1.4 (does synth's std describe its scatter?);
(c) CRB:      empirical std <= 1.5 x the Cramer-Rao bound computed on the NATIVE stamps.

Cases (case k drawn from ``numpy.random.default_rng(k)``): ``K/(T s+1)``, ``k(s+z)/((s+p1)(s+p2))`` or
``k/((s+p1)(s+p2))``, poles 0.5-20 rad/s (apart by a ratio > 1.3), a zero at least a ratio 1.3 from each pole, a
true delay of 5-50 ms in about a third of the cases (then fitted with ``delay="fit"``), an output offset. Stamps
(nominal interval h = 1-10 ms, 4,000-20,000 stamps): uniform jitter h(1 + U(-a, a)), a = 0.1-0.4; dropouts (1-3 %
of the stamps missing in gaps of 2-4 intervals); slow rate drift (the interval varying +-10-20 % over the record);
bursty (runs of two intervals). Command: a random telegraph between two levels or a random walk over 4-6 levels,
dwell times 0.5-3 slowest time constants, changing only AT stamps and held to the next stamp, at rest at 0 for
2-3 slowest time constants first. White Gaussian output noise of 0.5-3 % of the response's peak. The stamps and
the command are fixed per case (so the bound is per case); every seed draws fresh noise.

The reference is independent of synth: the noise-free output is the exact zero-order-hold response on the native
stamps (``scipy.signal.tf2ss``; each native interval, split where the delayed command changes, i.e. at
t_i + delay, is advanced with ``scipy.linalg.expm`` of the augmented ``[[A, B], [0, 0]] dt`` for its own length).
``--selfcheck`` verifies it against ``scipy.signal.lsim`` on even grids (with whole-sample delays, and uneven stamps
that are multiples of a fine even grid). The bound: ``sigma sqrt(diag((J^T J)^-1))`` with J the central-difference
sensitivities (relative step 1e-6) of that output at the native stamps to the structure's parameters, the delay
when fitted, and a constant output offset (synth estimates one; a nuisance parameter). A second bound leaves out
the stamps synth weights 0 (the start-up it treats as unknown, read from the fit's weights) and is printed beside.

Diagnostics beside the criteria: a seed whose estimate lies more than 5 of its own reported std from the truth is
listed with its fit (a fit far off that reports a small std); per case, what linear interpolation onto synth's grid
(``result.record.t``) does to white native noise (its variance, its low-frequency power per grid sample) and the
reported-std / bound ratio a white-noise fit on that grid would then show (``interpolation_factors``); the JSON
records which synth ran (path, git HEAD, uncommitted files).

Run (from the repository root):

    python benchmarks/uneven_stamps.py --selfcheck
    python benchmarks/uneven_stamps.py --quick                       # 6 cases x 8 seeds
    python benchmarks/uneven_stamps.py --cases 40 --seeds 20 --json out.json
    python benchmarks/uneven_stamps.py --only 3 7 --seeds 20
"""

from __future__ import annotations

import os

# One BLAS thread: the tiny matrices here (and synth's fits) gain nothing from more, and on a shared 2-core machine
# OpenBLAS's spinning threads made the simulator 25-200 times slower. Set before numpy is imported, and only when run
# as a script (an importer, such as the test suite, keeps its own settings and its subprocesses' environment).
if __name__ == "__main__":
    for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import argparse
import json
import math
import subprocess
import sys
import time
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from scipy import linalg, signal

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

STRUCTURES: dict[str, tuple[str, tuple[str, ...]]] = {
    "first": ("K/(T*s+1)", ("K", "T")),
    "second_zero": ("k*(s+z)/((s+p1)*(s+p2))", ("k", "z", "p1", "p2")),
    "second": ("k/((s+p1)*(s+p2))", ("k", "p1", "p2")),
}
STAMP_KINDS = ("jitter", "dropout", "drift", "bursty")
COMMAND_KINDS = ("telegraph", "multilevel")
BIAS_MAX = 0.5  # |bias| <= BIAS_MAX * empirical std
RATIO_RANGE = (0.7, 1.4)  # empirical std / mean reported std
CRB_MAX = 1.5  # empirical std <= CRB_MAX * bound
FAR_SIGMAS = 5.0  # a seed whose error exceeds this many of its own reported std is listed


# ----------------------------------------------------------------------------------------------- plants


def tf_of(kind: str, p: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator (descending powers of s) of structure ``kind`` at parameters ``p``."""
    if kind == "first":
        return np.array([p["K"]]), np.array([p["T"], 1.0])
    den = np.array([1.0, p["p1"] + p["p2"], p["p1"] * p["p2"]])
    if kind == "second_zero":
        return np.array([p["k"], p["k"] * p["z"]]), den
    return np.array([p["k"]]), den


def slowest_time_constant(kind: str, p: dict[str, float]) -> float:
    """The plant's slowest time constant (s)."""
    return p["T"] if kind == "first" else 1.0 / min(p["p1"], p["p2"])


# ----------------------------------------------------------------------------------------------- reference simulator


def delayed_segments(t: np.ndarray, u: np.ndarray, delay: float) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoints (the native stamps plus t_j + delay where the command changes) and the delayed command on each.

    The command is held from each stamp to the next and was at ``u[0]`` before the record (rest).
    """
    changes = np.flatnonzero(np.diff(u) != 0.0) + 1
    extra = t[changes] + delay
    grid = np.union1d(t, extra[extra < t[-1]])
    mid = 0.5 * (grid[:-1] + grid[1:]) - delay
    idx = np.searchsorted(t, mid, side="right") - 1
    w = np.where(idx >= 0, u[np.clip(idx, 0, None)], u[0])
    return grid, w


def simulate(num: np.ndarray, den: np.ndarray, t: np.ndarray, u: np.ndarray, delay: float = 0.0) -> np.ndarray:
    """Exact noise-free output at the stamps ``t`` of ``num/den e^(-delay s)`` driven by ``u`` held between stamps.

    Starts at rest. Each segment between breakpoints is advanced exactly with the matrix exponential of the
    augmented ``[[A, B], [0, 0]] dt`` for that segment's own length.
    """
    A, B, C, D = signal.tf2ss(num, den)
    n = A.shape[0]
    grid, w = delayed_segments(t, u, delay)
    dts = np.diff(grid)
    M = np.zeros((dts.size, n + 1, n + 1))
    M[:, :n, :n] = A
    M[:, :n, n] = B[:, 0]
    E = linalg.expm(M * dts[:, None, None])
    Phi = E[:, :n, :n]
    Gam = E[:, :n, n]
    x = np.zeros(n)
    xs = np.empty((grid.size, n))
    xs[0] = x
    for k in range(dts.size):
        x = Phi[k] @ x + Gam[k] * w[k]
        xs[k + 1] = x
    at = np.searchsorted(grid, t)
    w_at = np.append(w, w[-1])[at]  # the delayed command at each stamp (for a direct feedthrough)
    return xs[at] @ C[0] + D[0, 0] * w_at


# ----------------------------------------------------------------------------------------------- cases


@dataclass
class Case:
    """One random problem: plant, stamps, command, noise (the arrays are not written to JSON)."""

    index: int
    kind: str
    structure: str
    names: tuple[str, ...]
    truth: dict[str, float]
    delay: float
    fit_delay: bool
    offset: float
    stamp_kind: str
    stamp_info: dict[str, float]
    h: float
    n_stamps: int
    duration: float
    command_kind: str
    levels: list[float]
    n_changes: int
    rest: float
    tau_slow: float
    noise_std: float
    peak: float
    t: np.ndarray = field(repr=False)
    u: np.ndarray = field(repr=False)

    def describe(self) -> dict:
        d = asdict(self)
        d.pop("t")
        d.pop("u")
        d["names"] = list(self.names)
        return d


def loguniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def draw_plant(rng: np.random.Generator, kind: str) -> dict[str, float]:
    """Truth of structure ``kind``: poles 0.5-20 rad/s, static gain 0.5-5 (a quarter negative)."""
    gain = rng.uniform(0.5, 5.0) * (-1.0 if rng.random() < 0.25 else 1.0)
    if kind == "first":
        return {"K": gain, "T": 1.0 / loguniform(rng, 0.5, 20.0)}
    while True:
        p1, p2 = sorted((loguniform(rng, 0.5, 20.0), loguniform(rng, 0.5, 20.0)))
        if p2 / p1 > 1.3:
            break
    if kind == "second":
        return {"k": gain * p1 * p2, "p1": p1, "p2": p2}
    while True:
        z = loguniform(rng, 0.25, 40.0)
        if min(max(z / p, p / z) for p in (p1, p2)) > 1.3:
            break
    return {"k": gain * p1 * p2 / z, "z": z, "p1": p1, "p2": p2}


def draw_intervals(rng: np.random.Generator, kind: str, h: float, n: int) -> tuple[np.ndarray, dict[str, float]]:
    """``n`` sample intervals of stamp kind ``kind`` around ``h`` (dropouts removed afterwards, in draw_stamps)."""
    if kind == "jitter":
        a = rng.uniform(0.1, 0.4)
        return h * (1.0 + rng.uniform(-a, a, n)), {"a": a}
    if kind == "dropout":
        return h * (1.0 + rng.uniform(-0.02, 0.02, n)), {"a": 0.02}
    if kind == "drift":
        amp = rng.uniform(0.1, 0.2)
        cycles = rng.uniform(0.5, 3.0)
        phase = rng.uniform(0.0, 2.0 * math.pi)
        i = np.arange(n)
        slow = 1.0 + amp * np.sin(2.0 * math.pi * cycles * i / n + phase)
        return h * slow * (1.0 + rng.uniform(-0.02, 0.02, n)), {"amp": amp, "cycles": cycles}
    r_short, r_long = rng.uniform(0.4, 0.7), rng.uniform(1.3, 2.0)
    run = rng.uniform(5.0, 50.0)
    state = np.empty(n, dtype=bool)
    cur = bool(rng.random() < 0.5)
    i = 0
    while i < n:
        m = int(rng.geometric(1.0 / run))
        state[i : i + m] = cur
        cur = not cur
        i += m
    ratio = np.where(state, r_short, r_long)
    ratio = ratio / ratio.mean()
    intervals = h * ratio * (1.0 + rng.uniform(-0.01, 0.01, n))
    return intervals, {"short": float(r_short / np.mean(np.where(state, r_short, r_long))), "run": run}


def draw_stamps(rng: np.random.Generator, kind: str, h: float, n: int) -> tuple[np.ndarray, dict[str, float]]:
    """About ``n`` stamps of kind ``kind`` (after dropouts), starting at a random time 0-50 s."""
    frac = rng.uniform(0.01, 0.03) if kind == "dropout" else 0.0
    n_raw = math.ceil(n / (1.0 - frac))
    intervals, info = draw_intervals(rng, kind, h, n_raw - 1)
    t = rng.uniform(0.0, 50.0) + np.concatenate(([0.0], np.cumsum(intervals)))
    if kind == "dropout":
        keep = np.ones(n_raw, dtype=bool)
        while (~keep).mean() < frac:
            gap = int(rng.integers(1, 4))  # 1-3 stamps missing: a gap of 2-4 intervals
            start = int(rng.integers(50, n_raw - 50))
            keep[start : start + gap] = False
        t = t[keep]
        info = {**info, "missing": float(1.0 - keep.mean())}
    return t, info


def draw_command(
    rng: np.random.Generator, kind: str, t: np.ndarray, tau: float, rest: float
) -> tuple[np.ndarray, list[float], int]:
    """Command at the stamps (held to the next stamp): 0 up to ``rest`` after the first stamp, then random levels."""
    amp = rng.uniform(0.5, 5.0)
    if kind == "telegraph":
        lo = amp * rng.uniform(-1.0, 0.5)
        levels = [lo, lo + amp * rng.uniform(0.6, 1.5)]
        if abs(levels[0]) < 0.05 * amp:  # keep the first change away from a non-change
            levels[0] = -0.3 * amp
    else:
        count = int(rng.integers(4, 7))
        while True:
            levels = sorted(amp * rng.uniform(-1.0, 1.0, count))
            if np.min(np.diff(levels)) > 0.15 * amp and min(abs(v) for v in levels) > 0.05 * amp:
                break
    u = np.zeros_like(t)
    tc = t[0] + rest
    cur = -1
    changes = 0
    while True:
        if kind == "telegraph":
            cur = int(rng.integers(0, 2)) if cur < 0 else 1 - cur
        else:
            cur = int(rng.choice([j for j in range(len(levels)) if j != cur]))
        i = int(np.searchsorted(t, tc))  # the change is snapped to the first stamp at or after tc
        if i >= t.size - 1:
            break
        u[i:] = levels[cur]
        changes += 1
        tc = t[i] + rng.uniform(0.5, 3.0) * tau
    return u, [float(v) for v in levels], changes


def make_case(index: int) -> Case:
    """Case ``index``, drawn from ``default_rng(index)``."""
    rng = np.random.default_rng(index)
    kind = ("first", "second_zero", "second")[int(rng.integers(0, 3))]
    truth = draw_plant(rng, kind)
    tau = slowest_time_constant(kind, truth)
    fit_delay = bool(rng.random() < 1.0 / 3.0)
    delay = rng.uniform(0.005, 0.05) if fit_delay else 0.0
    stamp_kind = STAMP_KINDS[int(rng.integers(0, len(STAMP_KINDS)))]
    command_kind = COMMAND_KINDS[int(rng.integers(0, len(COMMAND_KINDS)))]
    rest = rng.uniform(2.0, 3.0) * tau
    target = rest + rng.uniform(15.0, 40.0) * tau
    h = loguniform(rng, 0.001, 0.01)
    n = int(np.clip(round(target / h), 4000, 20000))
    h = float(np.clip(target / n, 0.001, 0.01))
    n = int(np.clip(round(target / h), 4000, 20000))
    t, info = draw_stamps(rng, stamp_kind, h, n)
    u, levels, changes = draw_command(rng, command_kind, t, tau, rest)
    num, den = tf_of(kind, truth)
    y0 = simulate(num, den, t, u, delay)
    peak = float(np.max(np.abs(y0)))
    noise = rng.uniform(0.005, 0.03) * peak
    offset = peak * rng.uniform(-1.0, 1.0)
    structure, names = STRUCTURES[kind]
    return Case(
        index=index, kind=kind, structure=structure, names=names, truth=truth, delay=float(delay),
        fit_delay=fit_delay, offset=offset, stamp_kind=stamp_kind, stamp_info=info, h=h, n_stamps=int(t.size),
        duration=float(t[-1] - t[0]), command_kind=command_kind, levels=levels, n_changes=changes, rest=float(rest),
        tau_slow=tau, noise_std=float(noise), peak=peak, t=t, u=u,
    )


def clean_output(case: Case) -> np.ndarray:
    num, den = tf_of(case.kind, case.truth)
    return simulate(num, den, case.t, case.u, case.delay) + case.offset


# ----------------------------------------------------------------------------------------------- Cramer-Rao bound


def estimated_names(case: Case) -> list[str]:
    return [*case.names, "delay"] if case.fit_delay else list(case.names)


def jacobian(case: Case, rel: float = 1e-6) -> np.ndarray:
    """Central-difference sensitivities of the exact output at the native stamps; last column the offset."""
    names = estimated_names(case)
    base = {**case.truth, "delay": case.delay}
    cols = []
    for name in names:
        step = rel * max(abs(base[name]), 1e-3)
        outs = []
        for sign in (1.0, -1.0):
            p = {**base, name: base[name] + sign * step}
            num, den = tf_of(case.kind, p)
            outs.append(simulate(num, den, case.t, case.u, p["delay"]))
        cols.append((outs[0] - outs[1]) / (2.0 * step))
    cols.append(np.ones_like(case.t))
    return np.column_stack(cols)


def crb(J: np.ndarray, sigma: float) -> np.ndarray:
    """``sigma sqrt(diag((J^T J)^-1))`` with the columns scaled before inverting; inf where singular."""
    scale = np.linalg.norm(J, axis=0)
    scale[scale == 0] = 1.0
    F = (J / scale).T @ (J / scale)
    try:
        cov = np.linalg.inv(F) / np.outer(scale, scale)
    except np.linalg.LinAlgError:
        return np.full(J.shape[1], np.inf)
    return sigma * np.sqrt(np.abs(np.diag(cov)))


# ----------------------------------------------------------------------------------------------- fits


def canonical(case: Case, values: dict[str, float], stds: dict[str, float]) -> tuple[dict, dict]:
    """Estimates in the truth's labelling: p1 < p2 (the two poles are interchangeable in the formula)."""
    v = {k: float(values[k]) for k in estimated_names(case)}
    s = {k: float(stds[k]) for k in estimated_names(case)}
    if "p1" in v and v["p1"] > v["p2"]:
        v["p1"], v["p2"] = v["p2"], v["p1"]
        s["p1"], s["p2"] = s["p2"], s["p1"]
    return v, s


def zero_weight_span(res) -> float:
    """Duration (s) of the fit's zero-weighted start, 0 if none or not known."""
    w = getattr(res.fit, "weights", None)
    tt = getattr(res.fit, "t", None)
    if w is None or tt is None:
        return 0.0
    w, tt = np.asarray(w, dtype=float).ravel(), np.asarray(tt, dtype=float).ravel()
    if w.size != tt.size or w.size == 0 or w[0] != 0.0:
        return 0.0
    first = int(np.argmax(w != 0.0)) if np.any(w != 0.0) else w.size - 1
    return float(tt[first] - tt[0])


def interpolation_factors(t: np.ndarray, grid: np.ndarray) -> dict[str, float]:
    """What linear interpolation of white native noise onto ``grid`` does to it (a diagnostic, not a criterion).

    ``var``: the interpolated noise's variance per grid sample over the native sigma^2 (2/3 for weights uniform in
    [0, 1]); ``lowfreq``: its low-frequency power per grid sample over sigma^2 (each native sample's total weight
    squared, summed, over the grid's count); a white-noise fit on the grid scaling sigma from its residuals then
    reports ``sqrt(var n_native / n_grid)`` times the native bound (``pred_rep_crb``), while its scatter stays near
    ``sqrt(lowfreq n_native / n_grid)`` times it (``pred_emp_crb``).
    """
    grid = grid[(grid >= t[0]) & (grid <= t[-1])]
    j = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 2)
    w = np.clip((grid - t[j]) / (t[j + 1] - t[j]), 0.0, 1.0)
    var = float(np.mean((1.0 - w) ** 2 + w**2))
    c = np.bincount(j, 1.0 - w, minlength=t.size) + np.bincount(j + 1, w, minlength=t.size)
    lowfreq = float(np.sum(c**2) / grid.size)
    share = t.size / grid.size
    return {"n_native": int(t.size), "n_grid": int(grid.size), "var": var, "lowfreq": lowfreq,
            "pred_rep_crb": math.sqrt(var * share), "pred_emp_crb": math.sqrt(lowfreq * share)}


def fit_one(case: Case, y: np.ndarray) -> dict:
    """One identification: estimates and reported std in the truth's labelling, or the failure's message."""
    from synth.errors import DataError, FitError
    from synth.ident import identify

    t0 = time.process_time()
    out: dict = {}
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = identify((case.t, case.u, y), case.structure, delay="fit" if case.fit_delay else None,
                           compare_directions=False)
        v, s = canonical(case, res.fit.parameters, res.fit.std)
        out = {"ok": True, "values": v, "std": s, "fit_percent": float(res.fit.fit_percent),
               "residual_std": float(res.fit.residual_std), "weak": [str(x) for x in (res.fit.weak or [])],
               "whole_record_note": res.whole_record_note, "zero_weight_s": zero_weight_span(res),
               "record_notes": list(getattr(res.record, "notes", ()) or ()),
               "warnings": [str(w.message) for w in caught], "fit_samples": len(res.fit.t),
               "fit_t0": float(res.fit.t[0]), "grid_samples": int(res.record.n),
               "grid_dt": float(res.record.dt), "plant": str(res.plant.to_string(4))}
        if getattr(res.record, "t", None) is not None:
            out["interp"] = interpolation_factors(case.t, np.asarray(res.record.t, dtype=float))
    except (FitError, DataError) as exc:
        out = {"ok": False, "error": type(exc).__name__, "message": str(exc)}
    except Exception as exc:  # a crash in synth: counted, reported, never fatal here
        out = {"ok": False, "error": f"crash {type(exc).__name__}", "message": str(exc)}
    out["cpu_s"] = time.process_time() - t0
    return out


# ----------------------------------------------------------------------------------------------- statistics


def param_stats(case: Case, name: str, truth: float, bound: float, bound_w: float, fits: list[dict]) -> dict:
    """Per (case, parameter): mean, std, mean reported std, bound, the three criteria, far seeds."""
    ok = [f for f in fits if f["ok"]]
    est = np.array([f["values"][name] for f in ok])
    rep = np.array([f["std"][name] for f in ok])
    n = est.size
    row: dict = {"param": name, "truth": truth, "n": n, "crb": bound, "crb_weighted": bound_w}
    if n < 3:
        return {**row, "mean": math.nan, "emp_std": math.nan, "rep_std": math.nan}
    mean, emp = float(est.mean()), float(est.std(ddof=1))
    finite = rep[np.isfinite(rep)]
    rep_mean = float(finite.mean()) if finite.size else math.inf
    mad = 1.4826 * float(np.median(np.abs(est - np.median(est))))
    bias = mean - truth
    tstat = bias / (emp / math.sqrt(n)) if emp > 0 else math.inf
    ratio = emp / rep_mean if rep_mean > 0 else math.inf
    ratio_crb = emp / bound if bound > 0 else math.inf
    far = [f["seed"] for f in ok if abs(f["values"][name] - truth) > FAR_SIGMAS * f["std"][name]]
    near = np.array([f["values"][name] for f in ok if f["seed"] not in far])
    return {
        **row, "mean": mean, "bias": bias, "emp_std": emp, "robust_std": mad, "rep_std": rep_mean,
        "rep_inf": int(rep.size - finite.size), "t": tstat, "ratio_rep": ratio, "ratio_crb": ratio_crb,
        "ratio_rep_crb": rep_mean / bound if bound > 0 else math.inf,
        "ratio_repmedian_crb": float(np.median(rep)) / bound if bound > 0 else math.inf,
        "ratio_rep_without_far": float(near.std(ddof=1)) / rep_mean if near.size >= 3 and rep_mean > 0 else math.nan,
        "pass_bias": bool(abs(bias) <= BIAS_MAX * emp),
        "pass_ratio": bool(RATIO_RANGE[0] <= ratio <= RATIO_RANGE[1]),
        "pass_crb": bool(emp <= CRB_MAX * bound),
        "far_seeds": far,
    }


def run_case(case: Case, seeds: int) -> dict:
    """All seeds of one case, the bound and the per-parameter statistics."""
    y0 = clean_output(case)
    J = jacobian(case)
    bound = crb(J, case.noise_std)
    fits = []
    for s in range(seeds):
        rng = np.random.default_rng([case.index, 7919, s])
        f = fit_one(case, y0 + rng.normal(0.0, case.noise_std, y0.size))
        f["seed"] = s
        fits.append(f)
    spans = [f["zero_weight_s"] for f in fits if f["ok"]]
    span = float(np.median(spans)) if spans else 0.0
    rows_w = case.t >= case.t[0] + span
    bound_w = crb(J[rows_w], case.noise_std) if span > 0 else bound
    names = estimated_names(case)
    truth = {**case.truth, "delay": case.delay}
    stats = [param_stats(case, nm, truth[nm], float(bound[i]), float(bound_w[i]), fits) for i, nm in enumerate(names)]
    ok = [f for f in fits if f["ok"]]
    interp = next((f["interp"] for f in ok if "interp" in f), None)
    on_average = sum(f["fit_samples"] < 0.5 * f["grid_samples"] for f in ok)
    observed = float(np.median([r["ratio_repmedian_crb"] for r in stats if "t" in r])) if ok else math.nan
    return {"case": case.describe(), "crb": dict(zip(names, bound[:-1].tolist())), "offset_crb": float(bound[-1]),
            "zero_weight_s": span, "interp": interp, "fits_on_average": on_average, "median_rep_crb": observed,
            "stats": stats, "fits": fits}


# ----------------------------------------------------------------------------------------------- printing


def fmt(x: float, spec: str = ".3g") -> str:
    return "nan" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def case_header(c: dict) -> str:
    truth = ", ".join(f"{k}={v:.4g}" for k, v in c["truth"].items())
    dl = f", delay={c['delay'] * 1e3:.1f} ms (fitted)" if c["fit_delay"] else ""
    info = ", ".join(f"{k}={v:.3g}" for k, v in c["stamp_info"].items())
    return (f"case {c['index']}: {c['structure']} [{truth}{dl}]; stamps {c['stamp_kind']} ({info}), h={c['h'] * 1e3:.2f} ms,"
            f" {c['n_stamps']} stamps, {c['duration']:.1f} s; {c['command_kind']} {len(c['levels'])} levels,"
            f" {c['n_changes']} changes, tau={c['tau_slow']:.3g} s;"
            f" noise {c['noise_std']:.3g} ({c['noise_std'] / c['peak']:.1%})")


def print_case(result: dict) -> None:
    print(case_header(result["case"]))
    fails = [f for f in result["fits"] if not f["ok"]]
    ok = len(result["fits"]) - len(fails)
    print(f"  fits ok {ok}/{len(result['fits'])} ({result['fits_on_average']} of them on an edge/periodic average, the"
          f" rest on the whole record); zero-weighted start {result['zero_weight_s']:.3g} s (median)")
    ip = result["interp"]
    if ip:
        print(f"  synth's grid: {ip['n_native']} stamps -> {ip['n_grid']} samples; interpolated white noise: variance"
              f" x{ip['var']:.3f}, low-frequency power x{ip['lowfreq']:.3f} per grid sample; predicted rep/CRB"
              f" {ip['pred_rep_crb']:.2f}, emp/CRB {ip['pred_emp_crb']:.2f} (observed: median seed's rep/CRB,"
              f" median over parameters, {result['median_rep_crb']:.2f})")
    print(f"  {'param':6} {'truth':>10} {'mean':>10} {'emp std':>9} {'rep std':>9} {'CRB':>9} {'CRBw':>9}"
          f" {'t':>6} {'emp/rep':>7} {'emp/CRB':>7} {'rep/CRB':>7}  bias ratio crb")
    for r in result["stats"]:
        if math.isnan(r.get("emp_std", math.nan)):
            print(f"  {r['param']:6} {fmt(r['truth'], '10.4g')}  too few fits")
            continue
        marks = " ".join("ok  " if r[k] else "FAIL" for k in ("pass_bias", "pass_ratio", "pass_crb"))
        far = ""
        if r["far_seeds"]:
            far = f"  far seeds {r['far_seeds']} (emp/rep without them {r['ratio_rep_without_far']:.2f})"
        print(f"  {r['param']:6} {r['truth']:10.4g} {r['mean']:10.4g} {r['emp_std']:9.3g} {r['rep_std']:9.3g}"
              f" {r['crb']:9.3g} {r['crb_weighted']:9.3g} {r['t']:6.2f} {r['ratio_rep']:7.2f} {r['ratio_crb']:7.2f}"
              f" {r['ratio_rep_crb']:7.2f}  {marks}{far}")
    for f in fails:
        print(f"  seed {f['seed']}: {f['error']}: {f['message']}")


def summarize(results: list[dict]) -> dict:
    """Pass rates per criterion, failures, medians and the worst (case, parameter) pairs."""
    rows = [(res["case"], r) for res in results for r in res["stats"] if "pass_bias" in r]
    fails = [(res["case"]["index"], f["seed"], f["error"], f["message"]) for res in results for f in res["fits"]
             if not f["ok"]]
    n_fits = sum(len(res["fits"]) for res in results)

    def rate(key: str) -> float:
        return float(np.mean([r[key] for _, r in rows])) if rows else math.nan

    def worst(key: str, score) -> list[dict]:
        ranked = sorted(rows, key=lambda cr: -score(cr[1][key]))[:5]
        return [{"case": c["index"], "param": r["param"], key: r[key], "kind": c["kind"], "stamps": c["stamp_kind"],
                 "command": c["command_kind"], "fit_delay": c["fit_delay"], "truth": r["truth"], "mean": r["mean"],
                 "emp_std": r["emp_std"], "rep_std": r["rep_std"], "crb": r["crb"]} for c, r in ranked]

    ratio = np.array([r["ratio_rep"] for _, r in rows])
    rcrb = np.array([r["ratio_crb"] for _, r in rows])
    tst = np.array([abs(r["t"]) for _, r in rows])
    far = [(c["index"], r["param"], r["far_seeds"]) for c, r in rows if r["far_seeds"]]
    far_fits = [{"case": res["case"]["index"], "seed": f["seed"], "values": f["values"], "std": f["std"],
                 "truth": {**res["case"]["truth"], "delay": res["case"]["delay"]}, "plant": f["plant"],
                 "fit_percent": f["fit_percent"], "fit_samples": f["fit_samples"], "grid_samples": f["grid_samples"],
                 "note": f["whole_record_note"], "weak": f["weak"]}
                for res in results for f in res["fits"]
                if f["ok"] and any(f["seed"] in r["far_seeds"] for r in res["stats"] if "far_seeds" in r)]
    pred = [(res["case"]["index"], res["interp"]["pred_rep_crb"], res["median_rep_crb"]) for res in results
            if res["interp"] and not math.isnan(res["median_rep_crb"])]
    by_stamp = {k: [float(np.mean([r["pass_bias"] and r["pass_ratio"] and r["pass_crb"] for c, r in rows
                                   if c["stamp_kind"] == k])), sum(c["stamp_kind"] == k for c, _ in rows)]
                for k in STAMP_KINDS if any(c["stamp_kind"] == k for c, _ in rows)}
    return {
        "pairs": len(rows), "fits": n_fits, "failed_fits": len(fails),
        "pass_bias": rate("pass_bias"), "pass_ratio": rate("pass_ratio"), "pass_crb": rate("pass_crb"),
        "pass_all": float(np.mean([r["pass_bias"] and r["pass_ratio"] and r["pass_crb"] for _, r in rows]))
        if rows else math.nan,
        "all_by_stamp_kind": by_stamp,
        "median_ratio_rep": float(np.median(ratio)) if rows else math.nan,
        "min_ratio_rep": float(ratio.min()) if rows else math.nan,
        "max_ratio_rep": float(ratio.max()) if rows else math.nan,
        "median_ratio_crb": float(np.median(rcrb)) if rows else math.nan,
        "max_ratio_crb": float(rcrb.max()) if rows else math.nan,
        "median_abs_t": float(np.median(tst)) if rows else math.nan,
        "max_abs_t": float(tst.max()) if rows else math.nan,
        "worst_ratio_rep": worst("ratio_rep", lambda x: abs(math.log(x)) if 0 < x < math.inf else math.inf),
        "worst_ratio_crb": worst("ratio_crb", lambda x: x),
        "worst_t": worst("t", abs),
        "far_seeds": far,
        "far_fits": far_fits,
        "rep_crb_predicted_observed": pred,
        "failures": fails,
    }


def print_summary(s: dict) -> None:
    print("\nSUMMARY")
    print(f"  (case, parameter) pairs: {s['pairs']}; fits {s['fits']}, failed {s['failed_fits']}")
    print(f"  pass |bias| <= {BIAS_MAX} emp std:            {s['pass_bias']:.1%}   (median |t| {s['median_abs_t']:.2f},"
          f" max {s['max_abs_t']:.2f})")
    print(f"  pass {RATIO_RANGE[0]} <= emp/reported <= {RATIO_RANGE[1]}:   {s['pass_ratio']:.1%}   (median"
          f" {s['median_ratio_rep']:.2f}, range {s['min_ratio_rep']:.2f}-{s['max_ratio_rep']:.2f})")
    print(f"  pass emp <= {CRB_MAX} CRB:                 {s['pass_crb']:.1%}   (median {s['median_ratio_crb']:.2f},"
          f" max {s['max_ratio_crb']:.2f})")
    print(f"  all three:                          {s['pass_all']:.1%}")
    print("  all three by stamp kind: " + ", ".join(f"{k} {v[0]:.0%} of {v[1]}" for k, v in s["all_by_stamp_kind"].items()))
    for key in ("worst_ratio_rep", "worst_ratio_crb", "worst_t"):
        print(f"  worst {key[6:]}:")
        for w in s[key]:
            print(f"    case {w['case']} {w['param']}: {w[key[6:]]:.3g}  ({w['kind']}, {w['stamps']}, {w['command']},"
                  f" delay fitted {w['fit_delay']}; truth {w['truth']:.4g} mean {w['mean']:.4g} emp {w['emp_std']:.3g}"
                  f" rep {w['rep_std']:.3g} CRB {w['crb']:.3g})")
    if s["far_seeds"]:
        print(f"  seeds more than {FAR_SIGMAS:g} reported std from the truth: "
              + "; ".join(f"case {c} {p} seeds {v}" for c, p, v in s["far_seeds"]))
    for f in s["far_fits"]:
        vals = ", ".join(f"{k}={v:.4g}+-{f['std'][k]:.2g} (truth {f['truth'][k]:.4g})" for k, v in f["values"].items())
        print(f"    case {f['case']} seed {f['seed']}: {vals}; fit {f['fit_percent']:.1f} % on {f['fit_samples']} of"
              f" {f['grid_samples']} samples; weak {f['weak']}; note: {f['note'] or '-'}")
    if s["rep_crb_predicted_observed"]:
        pr = np.array([[p, o] for _, p, o in s["rep_crb_predicted_observed"]])
        dev = np.abs(np.log(pr[:, 1] / pr[:, 0]))
        print(f"  median seed's reported std / CRB per case (median over parameters) against the interpolation prediction"
              f" sqrt(var n_native/n_grid): observed median {np.median(pr[:, 1]):.2f} (range {pr[:, 1].min():.2f}-"
              f"{pr[:, 1].max():.2f}), predicted median {np.median(pr[:, 0]):.2f}; observed/predicted within"
              f" {np.exp(np.median(dev)):.2f}x (median), {np.exp(np.max(dev)):.2f}x (worst); correlation"
              f" {np.corrcoef(pr[:, 0], pr[:, 1])[0, 1]:.2f}")
    for c, seed, err, msg in s["failures"]:
        print(f"  failed fit: case {c} seed {seed}: {err}: {msg}")


# ----------------------------------------------------------------------------------------------- self-check


def selfcheck() -> bool:
    """The simulator against scipy.signal.lsim (zero-order hold) on even grids; the gain column against y/K."""
    rng = np.random.default_rng(12345)
    worst = 0.0
    plants = [("first", {"K": 2.0, "T": 0.3}), ("second_zero", {"k": 30.0, "z": 2.0, "p1": 1.5, "p2": 12.0}),
              ("second", {"k": -40.0, "p1": 0.7, "p2": 9.0})]
    h = 0.002
    t = np.arange(4000) * h
    u = np.repeat(rng.uniform(-2, 2, 40), 100)
    u[:300] = 0.0
    for kind, p in plants:
        num, den = tf_of(kind, p)
        ref = signal.lsim((num, den), u, t, interp=False)[1]
        err = np.max(np.abs(simulate(num, den, t, u) - ref)) / np.max(np.abs(ref))
        print(f"  even grid, no delay, {kind}: max rel error {err:.2e}")
        worst = max(worst, err)
        m = 13  # a whole-sample delay
        ref_d = signal.lsim((num, den), np.concatenate((np.zeros(m), u[:-m])), t, interp=False)[1]
        err = np.max(np.abs(simulate(num, den, t, u, m * h) - ref_d)) / np.max(np.abs(ref_d))
        print(f"  even grid, delay {m} samples, {kind}: max rel error {err:.2e}")
        worst = max(worst, err)
    hf = 1e-4  # uneven stamps on a fine even grid, a delay between stamps
    steps = rng.integers(5, 60, 800)
    idx = np.concatenate(([0], np.cumsum(steps)))
    tf_ = np.arange(idx[-1] + 1) * hf
    ts = tf_[idx]
    us = np.zeros(ts.size)
    for j in range(40, ts.size, 60):
        us[j:] = rng.uniform(-2, 2)
    uf = us[np.searchsorted(idx, np.arange(tf_.size), side="right") - 1]
    md = 237
    for kind, p in plants:
        num, den = tf_of(kind, p)
        ref = signal.lsim((num, den), np.concatenate((np.zeros(md), uf[:-md])), tf_, interp=False)[1][idx]
        err = np.max(np.abs(simulate(num, den, ts, us, md * hf) - ref)) / np.max(np.abs(ref))
        print(f"  uneven stamps (5-60 fine steps), delay {md * hf * 1e3:.1f} ms, {kind}: max rel error {err:.2e}")
        worst = max(worst, err)
    case = make_case(0)
    J = jacobian(case)
    gain = case.names[0]
    y = clean_output(case) - case.offset
    err = np.max(np.abs(J[:, 0] - y / case.truth[gain])) / np.max(np.abs(y / case.truth[gain]))
    print(f"  case 0 ({case.kind}): d y / d {gain} by central differences against y/{gain}: max rel error {err:.2e}")
    ok = worst < 1e-8 and err < 1e-6
    print(f"selfcheck {'passed' if ok else 'FAILED'} (worst simulator error {worst:.2e})")
    return ok


# ----------------------------------------------------------------------------------------------- main


def synth_state() -> dict:
    """Which synth ran: its path, and the git HEAD and uncommitted files of its checkout when there is one."""
    import synth

    root = Path(synth.__file__).resolve().parents[1]
    state: dict = {"path": str(root)}
    try:
        def git(*args: str) -> str:
            return subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, check=True).stdout

        state["head"] = git("rev-parse", "HEAD").strip()
        state["uncommitted"] = git("status", "--porcelain", "synth").splitlines()
    except (OSError, subprocess.CalledProcessError):
        state["head"] = None
    return state


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=40)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--only", type=int, nargs="+", help="run only these case indices")
    ap.add_argument("--quick", action="store_true", help="smoke run: 6 cases x 8 seeds")
    ap.add_argument("--json", type=Path, help="write cases, per-seed fits, statistics and the summary here")
    ap.add_argument("--selfcheck", action="store_true", help="check the reference simulator and exit")
    args = ap.parse_args(argv)
    if args.selfcheck:
        return 0 if selfcheck() else 1
    cases, seeds = (6, 8) if args.quick else (args.cases, args.seeds)
    indices = args.only if args.only else list(range(cases))
    results = []
    start = time.time()
    state = synth_state()
    print(f"synth from {state['path']} (git HEAD {state.get('head')}, uncommitted {state.get('uncommitted', [])})")
    for i in indices:
        t0 = time.time()
        case = make_case(i)
        result = run_case(case, seeds)
        results.append(result)
        nfail = sum(not f["ok"] for f in result["fits"])
        print(f"[{len(results)}/{len(indices)}] case {i} {case.kind} {case.stamp_kind} {case.command_kind}"
              f" delay={case.fit_delay}: {time.time() - t0:.1f} s, {nfail} failed", file=sys.stderr, flush=True)
        print_case(result)
        print(flush=True)
    summary = summarize(results)
    print_summary(summary)
    print(f"\n{len(indices)} cases x {seeds} seeds in {time.time() - start:.0f} s")
    if args.json:
        payload = {"args": {"cases": indices, "seeds": seeds}, "synth": state, "criteria": {"bias_max": BIAS_MAX,
                   "ratio_range": RATIO_RANGE, "crb_max": CRB_MAX}, "summary": summary, "results": results}
        args.json.write_text(json.dumps(payload, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
