"""Step-train identification: speed against a baseline in the same run, and Monte Carlo against the Cramer-Rao bound.

Case: the SYNTHETIC X-4 step train (synth.ident.x4_record: eq. 5 plant, eq. 4 sensor, 20 ms delay,
white Gaussian noise of std 1.25 rad/s, 70 periods of 6 s at 1 kHz = 420,000 samples), structure
k*(s+z)/((s+p1)*(s+p2)) with the sensor known and the delay fitted.

(a) Speed. synth: load the CSV, find/align/average the steps, SRIVC initialization, casadi/IPOPT fit
    (fit_structure). Baseline: scipy.optimize.least_squares on the same averaged period and the same
    cost, from the same initial values, the model simulated with synth.ident.simulate.simulate_plant
    (exact fractional delay) over the period repeated until the transient has decayed (periodic state),
    Jacobian by finite differences. Goal (issue 4): the 420,000-sample train in under 10 s.
(b) Monte Carlo over noise seeds: empirical std of each parameter against the Cramer-Rao bound
    sqrt(diag(sigma^2 / N_periods (J^T J)^-1)), J the Jacobian of the averaged-period model at the
    truth (casadi, exact). Goal: ratio within 1.5.

Run:  python benchmarks/ident_steptrain.py [--seeds 50] [--skip-speed]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from synth.data import load_record  # noqa: E402
from synth.ident import x4_record as x4  # noqa: E402
from synth.ident.identification import identify  # noqa: E402
from synth.ident.sim_error_problem import SimulationErrorProblem  # noqa: E402
from synth.ident.simulate import simulate_plant  # noqa: E402
from synth.ident.steps import average_steps  # noqa: E402
from synth.ident.structure import parse_structure  # noqa: E402
from synth.ident.timefit import fit_structure  # noqa: E402
from synth.plant import Plant  # noqa: E402

NAMES = ("k", "z", "p1", "p2", "delay")


def _ordered(p: dict[str, float], by: dict[str, float] | None = None) -> dict[str, float]:
    """Name the faster pole p1 (the order of two symmetric poles is arbitrary); ``by`` decides for a std."""
    out = dict(p)
    ref = by or p
    if ref["p1"] < ref["p2"]:
        out["p1"], out["p2"] = p["p2"], p["p1"]
    return out


def _baseline(avg, init: dict[str, float]) -> tuple[dict[str, float], float]:
    """scipy least_squares on the same averaged period (periodic state by repetition)."""
    from scipy.optimize import least_squares

    st = parse_structure(x4.STRUCTURE)
    sensor = Plant.from_string(x4.SENSOR)
    r = avg.record()
    n, reps = r.n, 4  # 4 periods: the slowest pole (0.54 rad/s) decays to e^-9.7 of its amplitude
    t = np.arange(n * reps) * r.dt
    w = np.tile(r.u - r.u[0], reps)

    def resid(x: np.ndarray) -> np.ndarray:
        plant = st.plant(x[:4], delay=max(x[4], 0.0)).series(sensor)
        y = simulate_plant(plant, t, w, initial="zero")[-n:] + x[5]
        return y - r.y

    x0 = np.r_[[init[k] for k in ("k", "z", "p1", "p2")], init["delay"], np.mean(r.y) - 1.908 * 1.0126 * 25]
    t0 = time.perf_counter()
    sol = least_squares(resid, x0, x_scale=np.abs(x0) + 1e-3, xtol=1e-12, ftol=1e-12)
    return dict(zip(NAMES, sol.x[:5])), time.perf_counter() - t0


def speed() -> None:
    path = x4.x4_step_train_path()
    t0 = time.perf_counter()
    record = load_record(path, *x4.COLUMNS, input_unit="PWM", output_unit="rad/s")
    t_load = time.perf_counter() - t0
    t1 = time.perf_counter()
    avg = average_steps(record)
    t_avg = time.perf_counter() - t1
    t2 = time.perf_counter()
    fit = fit_structure(avg.record(), x4.STRUCTURE, "fit", x4.SENSOR, periodic=True)
    t_fit = time.perf_counter() - t2
    total = time.perf_counter() - t0
    t3 = time.perf_counter()
    fit_structure(avg.record(), x4.STRUCTURE, "fit", x4.SENSOR, periodic=True, initial=fit.initial)
    t_ipopt = time.perf_counter() - t3
    base, t_base = _baseline(avg, fit.initial)
    ours = _ordered(fit.parameters)
    base = _ordered(base)
    print(f"(a) speed, {record.n} samples ({record.source})")
    print(f"{'step':<42}{'time [s]':>10}")
    for label, value in [("load CSV", t_load), ("find, align, average steps", t_avg),
                         ("fit (SRIVC init + casadi/IPOPT)", t_fit), ("total, end to end", total),
                         ("casadi/IPOPT alone, from the same start", t_ipopt),
                         ("baseline: scipy least_squares, same start", t_base)]:
        print(f"{label:<42}{value:>10.2f}")
    print(f"baseline time / casadi time (same start): {t_base / t_ipopt:.1f}x; goal total < 10 s: "
          f"{'met' if total < 10 else 'NOT met'}")
    print(f"{'parameter':<10}{'truth':>10}{'synth':>12}{'baseline':>12}")
    for name in NAMES:
        print(f"{name:<10}{x4.TRUTH[name]:>10.4g}{ours[name]:>12.6g}{base[name]:>12.6g}")
    print()


def crb(periods: int) -> dict[str, float]:
    clean = average_steps(x4.x4_step_train(noise_std=0.0, periods=periods))
    r = clean.record()
    st = parse_structure(x4.STRUCTURE)
    theta = np.array([x4.TRUTH[k] for k in ("k", "z", "p1", "p2")])
    prob = SimulationErrorProblem(st, Plant.from_string(x4.SENSOR), r.n, r.dt, True, theta, True, r.y, False)
    m = int(np.floor(x4.DELAY / r.dt + 1e-9))
    f = x4.DELAY - m * r.dt
    x = np.r_[np.ones(4), f, 820.0]
    J = np.asarray(prob.jac_fn(x, prob.inputs(r.u - r.u[0], m))) / np.r_[prob.scale, 1.0, 1.0][None, :]
    cov = x4.NOISE_STD**2 / clean.count * np.linalg.inv(J.T @ J)
    return dict(zip(NAMES, np.sqrt(np.diag(cov))[:5]))


def monte_carlo(seeds: int) -> None:
    bound = crb(x4.PERIODS)
    rows = []
    t0 = time.perf_counter()
    for seed in range(seeds):
        res = identify(x4.x4_step_train(seed=1000 + seed), x4.STRUCTURE, "fit", x4.SENSOR)
        fit = res.fit
        rows.append([_ordered(fit.parameters)[k] for k in NAMES] + [_ordered(fit.std, fit.parameters)[k] for k in NAMES])
    arr = np.array(rows)
    elapsed = time.perf_counter() - t0
    print(f"(b) Monte Carlo, {seeds} noise seeds ({elapsed:.0f} s): empirical std against the Cramer-Rao bound")
    print(f"{'parameter':<10}{'truth':>9}{'mean':>11}{'bias/std':>10}{'emp. std':>11}{'CRB':>11}{'ratio':>8}"
          f"{'mean reported std':>19}")
    worst = 0.0
    for i, name in enumerate(NAMES):
        emp = float(np.std(arr[:, i], ddof=1))
        ratio = emp / bound[name]
        worst = max(worst, ratio)
        bias = (float(np.mean(arr[:, i])) - x4.TRUTH[name]) / emp
        print(f"{name:<10}{x4.TRUTH[name]:>9.4g}{np.mean(arr[:, i]):>11.5g}{bias:>10.2f}{emp:>11.3g}"
              f"{bound[name]:>11.3g}{ratio:>8.2f}{np.mean(arr[:, 5 + i]):>19.3g}")
    print(f"largest ratio {worst:.2f} (goal <= 1.5: {'met' if worst <= 1.5 else 'NOT met'}); "
          f"ratio std error about {1 / np.sqrt(2 * (seeds - 1)):.2f} from {seeds} seeds")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=50)
    ap.add_argument("--skip-speed", action="store_true")
    args = ap.parse_args()
    if not args.skip_speed:
        speed()
    monte_carlo(args.seeds)


if __name__ == "__main__":
    main()
