"""Random two-parameter stability-map problems for :mod:`benchmarks.plane_stability_reference`.

Each case is a strictly proper plant of order 1-4 (relative degree 1-3) with, independently, one or two unstable
real poles (about 40 % of cases, 0.1-5 rad/s), a right-half-plane zero (about 30 %), an integrator (about 15 %), a
lightly damped pair (about 20 %, damping 0.05-0.5), the other poles and zeros stable at 0.1-20 rad/s, a DC gain
(of the plant without its integrator) of magnitude 0.1-20, negative in 20 % of cases, and a delay in about half of
the cases (0.01-1 times the slowest time constant, at most 2 s). The controller is a PI over (kp, ki) in 75 % of
cases, else a PID with two of kp, ki, kd free and the third fixed (tf = 1/(10..100 rad/s) fixed). Half of the
boxes are non-negative, ``[0, hi]`` with ``hi`` log-uniform over 0.1-100 (ki up to 10 times that, kd over
0.01-10); the others allow negative gains (``[-hi, hi]`` or ``[-hi, 0]`` per axis), so that many boxes hold no
stabilizing point at all.

Run:  python benchmarks/plane_stability_cases.py [--seed 0] [--cases 30] [-n 81] [--check 0]
prints per case the plant, the box, the share of stable points and the count of marginal ones, and the total
time; ``--check K`` also recounts K random points of each delayed case by the sampled argument principle.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["describe", "random_case"]


def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def _plant(rng: np.random.Generator) -> tuple[list[float], list[float], float]:
    """num, den and the delay of one random plant."""
    integrator = rng.random() < 0.15
    n_unstable = int(rng.integers(1, 3)) if rng.random() < 0.4 else 0
    pair = rng.random() < 0.2
    rhp_zero = rng.random() < 0.3
    need = integrator + n_unstable + 2 * pair
    while need > 4:  # at most order 4: drop the second unstable pole first, then the pair
        if n_unstable == 2:
            n_unstable = 1
        else:
            pair = False
        need = integrator + n_unstable + 2 * pair
    order = int(rng.integers(max(1, need, 1 + rhp_zero), 5))
    rel_deg = int(rng.integers(1, min(3, order - rhp_zero) + 1))
    poles: list[complex] = [0.0] * integrator + [_log_uniform(rng, 0.1, 5.0) for _ in range(n_unstable)]
    if pair:
        wn, zeta = _log_uniform(rng, 0.1, 20.0), rng.uniform(0.05, 0.5)
        poles += [complex(-zeta * wn, wn * np.sqrt(1 - zeta * zeta)), complex(-zeta * wn, -wn * np.sqrt(1 - zeta * zeta))]
    poles += [-_log_uniform(rng, 0.1, 20.0) for _ in range(order - len(poles))]
    zeros = [_log_uniform(rng, 0.1, 20.0)] * rhp_zero
    zeros += [-_log_uniform(rng, 0.1, 20.0) for _ in range(order - rel_deg - len(zeros))]
    den = np.real(np.poly(poles)) if poles else np.ones(1)
    num = np.real(np.poly(zeros)) if zeros else np.ones(1)
    dc = _log_uniform(rng, 0.1, 20.0) * (-1.0 if rng.random() < 0.2 else 1.0)
    nonzero = [p for p in poles if p != 0]
    gain = dc * np.real(np.prod([-p for p in nonzero])) / np.real(np.prod([-z for z in zeros]) if zeros else 1.0)
    delay = 0.0
    if rng.random() < 0.5:
        slowest = 1.0 / min(abs(p) for p in nonzero) if nonzero else 1.0
        delay = min(2.0, _log_uniform(rng, 0.01, 1.0) * slowest)
    return [float(c) for c in gain * num], [float(c) for c in den], float(delay)


def _box(rng: np.random.Generator, name: str, signed: bool) -> tuple[float, float]:
    hi = _log_uniform(rng, 0.01, 10.0) if name == "kd" else _log_uniform(rng, 0.1, 100.0)
    if name == "ki":
        hi *= _log_uniform(rng, 1.0, 10.0)
    if not signed:
        return (0.0, hi)
    return (-hi, hi) if rng.random() < 0.6 else (-hi, 0.0)


def random_case(seed: int, index: int) -> dict:
    """A random problem, reproducible from (seed, index).

    Parameters
    ----------
    seed, index : int
        The case is drawn from ``np.random.default_rng([seed, index])``.

    Returns
    -------
    dict
        ``{"num", "den", "delay", "ctype", "fixed", "x_name", "x_box", "y_name", "y_box"}``: plant polynomials
        (lists, highest power first), delay in s, "PI" or "PID", the fixed parameters and the two varied ones with
        their (lo, hi) boxes.

    Examples
    --------
    >>> case = random_case(0, 3)
    >>> case == random_case(0, 3), case["ctype"] in ("PI", "PID"), len(case["num"]) < len(case["den"])
    (True, True, True)
    """
    rng = np.random.default_rng([seed, index])
    num, den, delay = _plant(rng)
    fixed: dict[str, float] = {}
    if rng.random() < 0.75:
        ctype, x_name, y_name = "PI", "kp", "ki"
    else:
        ctype = "PID"
        x_name, y_name = [("kp", "kd"), ("ki", "kd"), ("kp", "ki")][int(rng.integers(3))]
        fixed["tf"] = 1.0 / _log_uniform(rng, 10.0, 100.0)
        third = ({"kp", "ki", "kd"} - {x_name, y_name}).pop()
        if third == "kp":
            fixed["kp"] = _log_uniform(rng, 0.01, 10.0)
        elif third == "ki":
            fixed["ki"] = 0.0 if rng.random() < 0.3 else _log_uniform(rng, 0.01, 10.0)
        else:
            fixed["kd"] = 0.0 if rng.random() < 0.3 else _log_uniform(rng, 0.001, 1.0)
    signed = rng.random() < 0.5
    return {"num": num, "den": den, "delay": delay, "ctype": ctype, "fixed": fixed,
            "x_name": x_name, "x_box": _box(rng, x_name, signed), "y_name": y_name, "y_box": _box(rng, y_name, signed)}


def describe(case: dict) -> str:
    """One line: the plant's poles and zeros, gain, delay, controller and box.

    Parameters
    ----------
    case : dict
        As returned by :func:`random_case`.

    Returns
    -------
    str

    Examples
    --------
    >>> describe({"num": [2.0], "den": [1.0, 1.0], "delay": 0.5, "ctype": "PI", "fixed": {},
    ...           "x_name": "kp", "x_box": (0.0, 1.0), "y_name": "ki", "y_box": (-1.0, 1.0)})
    'k=2 p=[-1] z=[] e^-0.5s | PI kp[0, 1] ki[-1, 1]'
    """
    def roots(p: list[float]) -> str:
        r = np.roots(p)
        return "[" + " ".join(f"{x.real:.3g}" + (f"{x.imag:+.3g}j" if x.imag else "") for x in r) + "]"

    gain = case["num"][0] / case["den"][0]
    fixed = " ".join(f"{k}={v:.3g}" for k, v in case["fixed"].items())
    delay = f" e^-{case['delay']:.3g}s" if case["delay"] > 0 else ""
    return (f"k={gain:.3g} p={roots(case['den'])} z={roots(case['num'])}{delay} | {case['ctype']}"
            f"{' ' + fixed if fixed else ''} {case['x_name']}[{case['x_box'][0]:.3g}, {case['x_box'][1]:.3g}]"
            f" {case['y_name']}[{case['y_box'][0]:.3g}, {case['y_box'][1]:.3g}]")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--cases", type=int, default=30)
    parser.add_argument("-n", type=int, default=81)
    parser.add_argument("--check", type=int, default=0, help="points per delayed case recounted by sampling")
    args = parser.parse_args()
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from benchmarks.plane_stability_reference import controller_polynomials, stable_grid, winding_count_sampled

    rng = np.random.default_rng(12345)
    t_all, none_stable, small, checked, differ = time.perf_counter(), 0, 0, 0, 0
    for index in range(args.cases):
        case = random_case(args.seed, index)
        t0 = time.perf_counter()
        xs, ys, stable, marginal = stable_grid(**case, n=args.n)
        dt = time.perf_counter() - t0
        share = stable.mean()
        none_stable += not stable.any()
        small += 0 < share < 0.05
        print(f"{index:3d} {describe(case)}\n    stable {100 * share:6.2f} %  marginal {int(marginal.sum()):5d}"
              f"  ({dt:.2f} s)")
        if args.check and case["delay"] > 0:
            from benchmarks.plane_stability_reference import MARGIN, frequency_scale

            sigma = MARGIN * frequency_scale(case["num"], case["den"])
            for _ in range(args.check):
                j, i = rng.integers(args.n, size=2)
                if marginal[j, i]:
                    continue
                params = {**case["fixed"], case["x_name"]: xs[i], case["y_name"]: ys[j]}
                num_c, den_c = controller_polynomials(case["ctype"], params)
                z = winding_count_sampled(num_c[0], den_c[0], case["num"], case["den"], case["delay"], -sigma)
                checked += 1
                if (z == 0) != stable[j, i]:
                    differ += 1
                    print(f"    SAMPLED COUNT DIFFERS at {case['x_name']}={xs[i]:.6g} {case['y_name']}={ys[j]:.6g}: {z}")
    print(f"\n{args.cases} cases, {none_stable} with no stable point, {small} with 0-5 % stable; "
          f"total {time.perf_counter() - t_all:.1f} s")
    if args.check:
        print(f"sampled recount: {checked} points, {differ} differ")


if __name__ == "__main__":
    main()
