"""Randomized step-train identification against the Cramer-Rao bound (issue 16, item 1).

Each case draws a plant (order 1-3, with zeros, some with a zero within 5-15 % of a pole: a near
pole-zero cancellation), a delay (fitted, or known and given), a known sensor or none, a train
design and a noise level, all from the case's seed:

- ``periodic-settling``: a square wave whose half period is the settling time (cycle averaging);
- ``periodic-unsettled``: a square wave whose half period is a third of it (the slow mode never settles);
- ``aperiodic``: two levels, dwell times drawn from 0.3-1.5 settling times (edge averaging, whole-record refit);
- ``amplitudes``: levels drawn from five amplitudes, dwell times as above (no averaging: the whole record).

Every train starts at rest and holds its first level for 1.5 settling times (``--rest``: another number; a short
rest leaves a periodic train's first averaged periods in the start-up transient). The record is
``--samples`` samples at 200 Hz (default 16,000, 80 s) with white Gaussian output noise of 1, 3 or
10 % of the output's peak, lowered where needed so that every structure parameter's bound stays
below 10 % of its value (50 % for a near cancellation): the bound is a local statement, and
beyond that a fit is dominated by the nonlinearity (which the weak-identifiability report covers).

The Cramer-Rao bound of each case is computed here, independently of synth's fit code: the
model output is simulated with scipy (``tf2ss``, the zero-order hold with a fractional delay
from ``scipy.linalg.expm``, ``scipy.signal.dlsim``), its sensitivities to the parameters (the
output offset included as a nuisance parameter) are central finite differences, and the bound
is ``sqrt(diag(sigma^2 (J^T J)^-1))``.

Each case is identified with ``synth.ident.identify`` on ``--seeds`` noise realizations (without
the up/down-step comparison, which does not change the fit).
Criteria, per (case, parameter): empirical std <= 1.5 CRB, |bias| <= 0.5 empirical std, mean
reported std within 0.7-1.4 of the empirical std. With 20 seeds the bias and std estimates are
themselves noisy (the bias criterion is a 2.2-sigma test of a mean of 20 draws), so the table
also gives, per parameter, the same statistics of the linearized least-squares estimator
``truth + (J^T J)^-1 J^T e`` on the same noise ``e`` ("ideal": efficient and unbiased by
construction), and the pass rate it gets: what chance alone does to the criteria.

Run:  nice -n 10 python benchmarks/ident_crb.py [--cases 50] [--seeds 20] [--samples 16000] [--json out.json]
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import time
from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from synth.ident.identification import identify  # noqa: E402

DT = 0.005
DESIGNS = ("periodic-settling", "periodic-unsettled", "aperiodic", "amplitudes")
KINDS = ("o1", "o2", "o2z", "o3z", "o3zz", "o2z-cancel", "o3z-cancel")


@dataclass
class Case:
    """One randomized case: the truth, the experiment, and how it is identified."""

    index: int
    kind: str
    structure: str
    truth: dict[str, float]
    delay: float
    fit_delay: bool
    sensor: str | None
    design: str
    noise_rel: float
    samples: int
    sigma: float = 0.0
    bound: dict[str, Any] = field(default_factory=dict, repr=False)
    u: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    y0: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]

    def label(self) -> str:
        return (f"{self.kind} {self.design}{' sensor' if self.sensor else ''}"
                f"{' delay-fit' if self.fit_delay else ' delay-known'} noise {100 * self.noise_rel:g}%")


# ------------------------------------------------------------ truth and input


def _poles(rng: np.random.Generator, count: int) -> list[float]:
    """Poles log-uniform in [0.5, 25] rad/s, each pair at least a factor 2.5 apart."""
    while True:
        p = sorted(float(x) for x in np.exp(rng.uniform(np.log(0.5), np.log(25.0), count)))
        if all(b / a >= 2.5 for a, b in pairwise(p)):
            return p


def _zero(rng: np.random.Generator, poles: list[float]) -> float | None:
    """A zero log-uniform in [0.3, 20] rad/s at least a factor 2 from every pole (None if 200 draws find none)."""
    for _ in range(200):
        z = float(np.exp(rng.uniform(np.log(0.3), np.log(20.0))))
        if all(max(z / p, p / z) >= 2.0 for p in poles):
            return z
    return None


def _truth(rng: np.random.Generator, kind: str) -> tuple[str, dict[str, float]]:
    cancel = kind.endswith("-cancel")
    base = kind.removesuffix("-cancel")
    order, zeros = int(base[1]), base.count("z")
    while True:  # two zeros and three poles may leave no room: draw again
        poles = _poles(rng, order)
        zs: list[float] = []
        for _ in range(zeros):
            z = _zero(rng, poles + zs)
            if z is None:
                break
            zs.append(z)
        if len(zs) == zeros:
            break
    if cancel:  # a zero within 5-15 % of a pole
        zs[0] = poles[int(rng.integers(order))] * float(rng.uniform(1.05, 1.15)) ** float(rng.choice([-1, 1]))
    zs = sorted(zs)  # labelled in ascending order, as the poles, and as :func:`matched` orders the fits
    k = float(np.prod(poles) / np.prod(zs) * rng.uniform(0.5, 2.0)) if zs else float(np.prod(poles) * rng.uniform(0.5, 2))
    pn = [f"p{i + 1}" for i in range(order)]
    zn = ["z"] if zeros == 1 else [f"z{i + 1}" for i in range(zeros)]
    num = "k" + "".join(f"*(s+{z})" for z in zn)
    structure = f"{num}/({'*'.join(f'(s+{p})' for p in pn)})"
    return structure, {"k": k, **dict(zip(zn, zs)), **dict(zip(pn, poles))}


def _tf(structure_truth: dict[str, float], sensor: str | None) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of the plant (times the sensor) from the parameter values."""
    num = np.array([structure_truth["k"]])
    den = np.array([1.0])
    for name, v in structure_truth.items():
        if name.startswith("z"):
            num = np.polymul(num, [1.0, v])
        elif name.startswith("p"):
            den = np.polymul(den, [1.0, v])
    if sensor is not None:
        a, b = (float(x) for x in sensor.split("|"))
        num, den = np.polymul(num, [a * b]), np.polymul(den, np.polymul([1.0, a], [1.0, b]))
    return num, den


def sensor_text(sensor: str | None) -> str | None:
    """The sensor ``a|b`` as the transfer function ``ab/((s+a)(s+b))`` (unit DC gain)."""
    if sensor is None:
        return None
    a, b = (float(x) for x in sensor.split("|"))
    return f"{a * b}/((s+{a})*(s+{b}))"


def _input(rng: np.random.Generator, design: str, n: int, settle: float, rest_settles: float = 1.5) -> np.ndarray:
    t = np.arange(n) * DT
    rest = rest_settles * settle
    if design.startswith("periodic"):
        half = settle if design == "periodic-settling" else settle / 3.0
        half = round(half / DT) * DT
        u = np.where(((t - rest) // half) % 2 == 0, 1.0, 0.0)
    else:
        edges, levels, now = [], [], rest
        amps = np.array([-1.0, -0.5, 0.5, 1.0, 2.0])
        level = 0.0
        while now < t[-1]:
            if design == "aperiodic":
                level = 1.0 if level == 0.0 else 0.0
            else:
                level = float(rng.choice(amps[amps != level]))
            edges.append(now)
            levels.append(level)
            now += float(rng.uniform(0.3, 1.5)) * settle
        u = np.zeros(n)
        for e, lv in zip(edges, levels):
            u[t >= e] = lv
    u[t < rest] = 0.0
    return u


# --------------------------------------------- independent simulation and CRB


def simulate(num: np.ndarray, den: np.ndarray, delay: float, w: np.ndarray) -> np.ndarray:
    """Output of ``num/den e^(-delay s)`` to the held samples ``w`` from rest (scipy only)."""
    from scipy.linalg import expm
    from scipy.signal import dlsim, tf2ss

    A, B, C, D = tf2ss(num, den)
    n = A.shape[0]

    def zoh(h: float) -> tuple[np.ndarray, np.ndarray]:
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n:] = A * h, B * h
        E = expm(M)
        return E[:n, :n], E[:n, n:]

    m = int(np.floor(delay / DT + 1e-12))
    f = delay - m * DT
    Ad, _ = zoh(DT)
    A_rest, G_late = zoh(DT - f)
    _, G_f = zoh(f)
    late = np.r_[np.zeros(m), w[:w.size - m]]
    early = np.r_[np.zeros(m + 1), w[:w.size - m - 1]]
    _, y, _ = dlsim((Ad, np.hstack([G_late, A_rest @ G_f]), C, np.zeros((1, 2)), DT),
                    np.column_stack([late, early]))
    return np.asarray(y).ravel() + float(D[0, 0]) * late


def crb(case: Case) -> dict[str, float]:
    """Cramer-Rao bound of the case's fitted parameters (finite-difference sensitivities, offset a nuisance)."""
    names = list(case.truth) + (["delay"] if case.fit_delay else [])
    theta = np.array([*case.truth.values(), *([case.delay] if case.fit_delay else [])])
    cols = []
    for i, name in enumerate(names):
        h = 1e-4 * DT if name == "delay" else 1e-6 * abs(theta[i])
        out = []
        for sign in (1.0, -1.0):
            th = theta.copy()
            th[i] += sign * h
            values = dict(zip(names, th))
            d = values.pop("delay", case.delay)
            out.append(simulate(*_tf(values, case.sensor), d, case.u))
        cols.append((out[0] - out[1]) / (2 * h))
    J = np.column_stack([*cols, np.ones(case.u.size)])
    cov = case.sigma**2 * np.linalg.inv(J.T @ J)
    # the linearized least-squares estimator (efficient by construction): its deviation is P @ noise
    P = np.linalg.solve(J.T @ J, J.T)[:-1]
    return {"names": names, "std": np.sqrt(np.diag(cov))[:-1], "cov": cov[:-1, :-1], "P": P}  # type: ignore[dict-item]


def make_case(index: int, samples: int, rest: float = 1.5) -> Case:
    """The case drawn from seed ``index``; the train starts after ``rest`` settling times of constant input."""
    rng = np.random.default_rng(7000 + index)
    kind = KINDS[index % len(KINDS)]
    design = DESIGNS[(index // len(KINDS) + index) % len(DESIGNS)]
    structure, truth = _truth(rng, kind)
    sensor = f"{rng.uniform(15, 30):.4g}|{rng.uniform(40, 80):.4g}" if rng.random() < 0.4 else None
    fit_delay = bool(rng.random() < 0.75)
    delay = float(rng.uniform(0.003, 0.04))
    noise_rel = float(rng.choice([0.01, 0.03, 0.1]))
    slow = min(v for k, v in truth.items() if k.startswith("p"))
    settle = 5.0 / slow + delay
    case = Case(index, kind, structure, truth, delay, fit_delay, sensor, design, noise_rel, samples)
    case.u = _input(rng, design, samples, min(settle, 0.15 * samples * DT), rest)
    case.y0 = simulate(*_tf(truth, sensor), delay, case.u)
    case.sigma = noise_rel * float(np.max(np.abs(case.y0)))
    # the bound is a local (asymptotic) statement: keep the noise where it is one, i.e. every structure parameter's
    # bound below 10 % of its value (50 % for a near cancellation, which is meant to be weakly identifiable)
    case.bound = bound = crb(case)
    rel = max(s / abs(case.truth[n]) for n, s in zip(bound["names"], bound["std"]) if n != "delay")
    cap = 0.5 if kind.endswith("-cancel") else 0.1
    if rel > cap:
        case.sigma *= cap / rel
        case.noise_rel *= cap / rel
        case.bound = {**bound, "std": bound["std"] * cap / rel, "cov": bound["cov"] * (cap / rel) ** 2}
    return case


def matched(names: list[str], params: dict[str, float], std: dict[str, float],
            truth: dict[str, float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Values and stds in ``names`` order; the poles' and the zeros' labels are interchangeable, so each group is
    matched to ``truth``'s by the assignment with the least sum of squared relative differences (without
    ``truth``: both sorted). Sorting is that assignment while the estimates keep the truth's order; a weakly
    identified pole of a near cancellation can pass another pole, and sorting then charged its error to the
    well-identified pole it passed (case 20: p1, whose bound is 0.02 % of its value, at 1473 bounds of spread).

    Examples
    --------
    Truth p1 = 1 (well identified), p2 = 10 (weakly), estimated 1.01 and 0.5:

    >>> est, std, truth = {"p1": 0.5, "p2": 1.01}, {"p1": 4.0, "p2": 0.01}, {"p1": 1.0, "p2": 10.0}
    >>> matched(["p1", "p2"], est, std, truth)[0].tolist(), matched(["p1", "p2"], est, std)[0].tolist()
    ([1.01, 0.5], [0.5, 1.01])
    """
    vals, sds = dict(params), dict(std)
    for prefix in ("p", "z"):
        group = [n for n in names if n.startswith(prefix) and n[1:].isdigit()]
        if truth is None:
            order = sorted(group, key=lambda n: params[n])
        else:
            order = list(min(itertools.permutations(group), key=lambda perm: sum(
                ((params[old] - truth[new]) / truth[new]) ** 2 for new, old in zip(group, perm))))
        for new, old in zip(group, order):
            vals[new], sds[new] = params[old], std[old]
    return np.array([vals[n] for n in names]), np.array([sds[n] for n in names])


def run_case(case: Case, seeds: int) -> dict[str, Any]:
    """Identify the case on ``seeds`` noise realizations; empirical statistics against the bound."""
    bound = case.bound or crb(case)
    names = bound["names"]
    truth = np.array([case.truth.get(n, case.delay) for n in names])
    est, rep, weak, failed, lin = [], [], 0, [], []
    t = np.arange(case.samples) * DT
    t0 = time.perf_counter()
    for seed in range(seeds):
        noise = case.sigma * np.random.default_rng(seed).normal(size=case.samples)
        y = 3.0 + case.y0 + noise
        lin.append(truth + bound["P"] @ noise)
        try:
            res = identify((t, case.u, y), case.structure, "fit" if case.fit_delay else case.delay,
                           sensor_text(case.sensor), compare_directions=False)
        except Exception as exc:  # a failed fit counts against the case
            failed.append(f"seed {seed}: {type(exc).__name__}: {exc}"[:200])
            continue
        v, s = matched(names, res.fit.parameters, res.fit.std, dict(zip(names, truth)))
        est.append(v)
        rep.append(s)
        weak += bool(res.fit.weak)
    elapsed = time.perf_counter() - t0
    est_a, rep_a = np.array(est), np.array(rep)
    out: dict[str, Any] = {"case": case.index, "label": case.label(), "structure": case.structure,
                           "truth": dict(zip(names, truth.tolist())), "crb": dict(zip(names, bound["std"].tolist())),
                           "fits": len(est), "failed": failed, "weak_share": weak / max(1, len(est)),
                           "seconds_per_fit": elapsed / seeds}
    if len(est) < 3:
        out["params"] = {}
        return out
    emp = est_a.std(axis=0, ddof=1)
    bias = est_a.mean(axis=0) - truth
    out["params"] = {n: {"emp_std": float(emp[i]), "bias": float(bias[i]), "reported_std": float(rep_a[:, i].mean()),
                         "std_over_crb": float(emp[i] / bound["std"][i]), "bias_over_std": float(bias[i] / emp[i]),
                         "reported_over_emp": float(rep_a[:, i].mean() / emp[i])} for i, n in enumerate(names)}
    lin_a = np.array(lin)  # the efficient estimator on the same noise: how far chance alone moves the statistics
    lin_emp = lin_a.std(axis=0, ddof=1)
    lin_bias = lin_a.mean(axis=0) - truth
    for i, n in enumerate(names):
        out["params"][n] |= {"ideal_std_over_crb": float(lin_emp[i] / bound["std"][i]),
                             "ideal_bias_over_std": float(lin_bias[i] / lin_emp[i])}
    return out


def verdicts(p: dict[str, float], failed: bool) -> dict[str, bool]:
    """The three criteria for one (case, parameter)."""
    return {"efficient": not failed and p["std_over_crb"] <= 1.5, "unbiased": not failed and abs(p["bias_over_std"]) <= 0.5,
            "reported": not failed and 0.7 <= p["reported_over_emp"] <= 1.4}


def paired(p: dict[str, float]) -> bool:
    """One (case, parameter) judged beside the efficient estimator on the same noise realizations (the "ideal"
    columns): empirical std at most 1.5 times that estimator's, and mean within 0.5 empirical std of its mean. What
    20 seeds' shared noise does to both cancels, so a failure here is the fit's own, not chance's.

    Examples
    --------
    >>> paired({"std_over_crb": 1.6, "bias_over_std": 0.6, "ideal_std_over_crb": 1.4, "ideal_bias_over_std": 0.6})
    True
    >>> paired({"std_over_crb": 2.2, "bias_over_std": 0.1, "ideal_std_over_crb": 1.0, "ideal_bias_over_std": 0.1})
    False
    """
    std, ideal_std = p["std_over_crb"], p["ideal_std_over_crb"]  # both in units of the bound
    bias, ideal_bias = p["bias_over_std"] * std, p["ideal_bias_over_std"] * ideal_std
    return std <= 1.5 * ideal_std and abs(bias - ideal_bias) <= 0.5 * std


def summary(results: list[dict[str, Any]]) -> str:
    lines = [f"{'case':<5}{'plant, design, sensor, delay, noise':<58}{'param':<7}{'std/CRB':>8}{'bias/std':>9}"
             f"{'rep/emp':>8}{'ideal':>14}{'weak':>6}{'s/fit':>7}"]
    pairs, passed, ideal, case_ok, paired_ok = 0, {"efficient": 0, "unbiased": 0, "reported": 0, "all": 0}, [], 0, 0
    ideal_reported: list[bool] = []
    ideal_ratio: list[float] = []
    for r in results:
        failed = bool(r["failed"]) or not r["params"]
        ok_case = True
        ok_paired = not failed
        for i, name in enumerate(r["crb"]):
            p = r["params"].get(name)
            v = verdicts(p, failed) if p else {"efficient": False, "unbiased": False, "reported": False}
            pairs += 1
            for key, val in v.items():
                passed[key] += val
            passed["all"] += all(v.values())
            ok_case &= v["efficient"] and v["unbiased"]
            ok_paired = ok_paired and bool(p) and paired(p)
            if p:
                ideal.append(p["ideal_std_over_crb"] <= 1.5 and abs(p["ideal_bias_over_std"]) <= 0.5)
                ratio = p["reported_std"] / (p["ideal_std_over_crb"] * r["crb"][name])
                ideal_reported.append(0.7 <= ratio <= 1.4)
                ideal_ratio.append(p["reported_std"] / r["crb"][name])
            weak, secs = f"{100 * r['weak_share']:.0f}%", f"{r['seconds_per_fit']:.1f}"
            mark = "" if all(v.values()) else "  <- " + ", ".join(k for k, x in v.items() if not x)
            if p:
                lines.append(f"{r['case'] if i == 0 else '':<5}{r['label'] if i == 0 else '':<58}{name:<7}"
                             f"{p['std_over_crb']:>8.2f}{p['bias_over_std']:>9.2f}{p['reported_over_emp']:>8.3g}"
                             f"{p['ideal_std_over_crb']:>8.2f}{p['ideal_bias_over_std']:>6.2f}"
                             f"{weak if i == 0 else '':>6}{secs if i == 0 else '':>7}{mark}")
            else:
                lines.append(f"{r['case']:<5}{r['label']:<58}{name:<7} no result ({len(r['failed'])} failed fits)")
        case_ok += ok_case
        paired_ok += ok_paired
    lines.append("")
    lines.append(f"(case, parameter) pairs: {pairs}; std <= 1.5 CRB: {100 * passed['efficient'] / pairs:.1f} %, "
                 f"|bias| <= 0.5 std: {100 * passed['unbiased'] / pairs:.1f} %, reported std within 0.7-1.4 of the "
                 f"empirical: {100 * passed['reported'] / pairs:.1f} %, all three: {100 * passed['all'] / pairs:.1f} %")
    lines.append(f"the efficient estimator on the same noise (ideal: std/CRB, bias/std) passes std and bias in "
                 f"{100 * np.mean(ideal):.1f} % of the pairs (the rest fail by chance: 20 seeds' statistics are noisy)")
    lines.append(f"the reported std is within 0.7-1.4 of that estimator's empirical std in "
                 f"{100 * np.mean(ideal_reported):.1f} % of the pairs; reported std / CRB: median "
                 f"{np.median(ideal_ratio):.2f}, "
                 f"5-95 % {np.percentile(ideal_ratio, 5):.2f}-{np.percentile(ideal_ratio, 95):.2f}")
    lines.append(f"cases with every parameter efficient and unbiased: {case_ok} of {len(results)}")
    lines.append(f"cases with every parameter efficient and unbiased beside the efficient estimator on the same noise "
                 f"(std <= 1.5 times its std, |mean - its mean| <= 0.5 std: the noise the two share cancels): "
                 f"{paired_ok} of {len(results)}")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", type=int, default=50)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--samples", type=int, default=16000, help="samples per record (200 Hz)")
    ap.add_argument("--first", type=int, default=0, help="first case (to split the run over processes)")
    ap.add_argument("--only", type=int, nargs="+", metavar="CASE", help="only these cases (instead of --first/--cases)")
    ap.add_argument("--rest", type=float, default=1.5,
                    help="settling times of constant input before the train (default 1.5; below 1 the plant has "
                         "not settled when a periodic train's averaged periods begin)")
    ap.add_argument("--json", help="write the per-case results here")
    ap.add_argument("--merge", nargs="+", metavar="JSON", help="only print the table of these result files")
    args = ap.parse_args()
    if args.merge:
        merged = {r["case"]: r for path in args.merge for r in json.loads(Path(path).read_text())}
        print(summary([merged[k] for k in sorted(merged)]))
        return
    results = []
    t0 = time.perf_counter()
    chosen = args.only if args.only else range(args.first, args.first + args.cases)
    for i in chosen:
        case = make_case(i, args.samples, args.rest)
        results.append(run_case(case, args.seeds))
        print(f"case {i}: {case.label()} done ({time.perf_counter() - t0:.0f} s)", file=sys.stderr, flush=True)
        if args.json:
            Path(args.json).write_text(json.dumps(results, indent=1))
    print(summary(results))
    print(f"\n{len(results)} cases x {args.seeds} seeds, {args.samples} samples each: {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
