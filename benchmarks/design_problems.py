"""Seeded random design problems for the randomized-truth verification of ``synth.design`` (issue 15, item 1).

Each problem is a spec dict for :func:`synth.parse_spec` plus the plant as plain polynomials, so that an
independent reference (``benchmarks/design_reference.py``) can evaluate it without synth.

Plants: order 1-5, strictly proper (biproper on request: ``biproper=share``), built from a random choice of
features: right-half-plane zeros (written ``(1 - s/z)`` so the DC gain stays positive), open-loop unstable real
poles ``(s - p)``, integrators, lightly damped pairs (damping 0.02 ... 0.7), stable real poles; a gain chosen so that
the loop crosses over near a target frequency ``wt``; a delay up to half the crossover period ``pi/wt`` (drawn
skewed towards small delays). Controllers: P, PI, PID, leadlag, rational up to order (2, 3), with explicit
bounds scaled to the plant. Requirements: a random non-empty subset of every registered type, with bounds
drawn around values that are reachable for some problems and out of reach for others.

Run ``python benchmarks/design_problems.py --n 3`` to print a few.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["CONTROLLERS", "Problem", "generate", "problem"]

CONTROLLERS = ("P", "PI", "PID", "leadlag", "rational")


@dataclass
class Problem:
    """One design problem.

    Attributes
    ----------
    index : int
        Position in the seeded sequence.
    spec : dict
        The spec, as ``synth.parse_spec`` takes it.
    num, den : list of float
        Plant polynomials (highest power first), the same plant as ``spec["plant"]["tf"]``.
    delay : float
        Plant delay (s).
    features : list of str
        What the plant has (``rhp_zero``, ``unstable``, ``integrator``, ``light``, ``delay``, ``biproper``).
    """

    index: int
    spec: dict[str, Any]
    num: list[float]
    den: list[float]
    delay: float
    features: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return dict(self.__dict__)


def _g(x: float) -> str:
    return f"{x:.6g}"


def _type3_plant(rng: np.random.Generator, wt: float) -> tuple[list[str], np.ndarray, np.ndarray, list[str]]:
    """``k (s + z) / (s^2 (s + p1) [(s + p2)])``: a double integrator with a zero (the loop is type 3 under integral
    action), the class where session 41 found a converged polish called a local optimum with a way up left."""
    z = float(_g(wt * 10 ** rng.uniform(-1.0, 0.0)))
    poles = [float(_g(wt * 10 ** rng.uniform(-1.5, -0.3)))]
    if rng.random() < 0.5:
        poles.append(float(_g(wt * 10 ** rng.uniform(0.2, 1.0))))
    num = np.array([1.0, z])
    den = np.array([1.0, 0.0, 0.0])
    for p in poles:
        den = np.polymul(den, [1.0, p])
    s = 1j * wt
    k = float(_g(1.0 / abs(np.polyval(num, s) / np.polyval(den, s))))
    tf = f"{_g(k)}*(s+{_g(z)})/(s^2*" + "*".join(f"(s+{_g(p)})" for p in poles) + ")"
    return [tf], k * num, den, ["integrator", "double_integrator"]


def _plant(rng: np.random.Generator, wt: float, simple: bool,
           biproper: np.random.Generator | None = None) -> tuple[list[str], np.ndarray, np.ndarray, list[str]]:
    order = int(rng.integers(1, 3 if simple else 6))
    factors_den: list[str] = []
    factors_num: list[str] = []
    den = np.array([1.0])
    num = np.array([1.0])
    feats: list[str] = []
    left = order
    if not simple and left >= 1 and rng.random() < 0.25:
        p = wt * 10 ** rng.uniform(-1.0, -0.2)
        factors_den.append(f"(s-{_g(p)})")
        den = np.polymul(den, [1.0, -float(_g(p))])
        feats.append("unstable")
        left -= 1
    if left >= 1 and rng.random() < 0.25:
        factors_den.append("s")
        den = np.polymul(den, [1.0, 0.0])
        feats.append("integrator")
        left -= 1
    if not simple and left >= 2 and rng.random() < 0.4:
        wn = wt * 10 ** rng.uniform(-0.7, 0.7)
        zeta = 10 ** rng.uniform(np.log10(0.02), np.log10(0.7))
        a1, a0 = float(_g(2 * zeta * wn)), float(_g(wn * wn))
        factors_den.append(f"(s^2+{_g(a1)}*s+{_g(a0)})")
        den = np.polymul(den, [1.0, a1, a0])
        feats.append(f"light(zeta={zeta:.3f})")
        left -= 2
    while left > 0:
        p = float(_g(wt * 10 ** rng.uniform(-1.3, 1.0)))
        factors_den.append(f"(s+{_g(p)})")
        den = np.polymul(den, [1.0, p])
        left -= 1
    n_zeros = int(rng.integers(0, min(order - 1, 2) + 1)) if order > 1 else 0
    for i in range(n_zeros):
        z = float(_g(wt * 10 ** rng.uniform(-0.5, 1.2)))
        if not simple and i == 0 and rng.random() < 0.4:
            factors_num.append(f"(1-s/{_g(z)})")
            num = np.polymul(num, [-1.0 / z, 1.0])
            feats.append("rhp_zero")
        else:
            factors_num.append(f"(s+{_g(z)})")
            num = np.polymul(num, [1.0, z])
    if biproper is not None:  # as many zeros as poles: |G(j inf)| is finite and nonzero (a direct feedthrough)
        for _ in range(order - n_zeros):
            z = float(_g(wt * 10 ** biproper.uniform(-0.5, 1.5)))
            factors_num.append(f"(s+{_g(z)})")
            num = np.polymul(num, [1.0, z])
        feats.append("biproper")
    # gain: |G(j wt)| = 1 so that controller gains of order 1 cross over near wt
    s = 1j * wt
    k = float(_g(1.0 / abs(np.polyval(num, s) / np.polyval(den, s))))
    num = k * num
    tf = f"{_g(k)}*" + ("*".join(factors_num) if factors_num else "1") + "/(" + "*".join(factors_den) + ")"
    return [tf], num, den, feats


def _controller(rng: np.random.Generator, kind: str, wt: float) -> dict[str, Any]:
    kmax = float(_g(10 ** rng.uniform(0.3, 1.5)))
    if kind == "P":
        return {"type": "P", "bounds": {"kp": [0.0, kmax]}}
    if kind == "PI":
        return {"type": "PI", "bounds": {"kp": [0.0, kmax], "ki": [0.0, float(_g(kmax * wt))]}}
    if kind == "PID":
        tf = float(_g(0.1 / wt))
        return {"type": "PID", "bounds": {"kp": [0.0, kmax], "ki": [0.0, float(_g(kmax * wt))],
                                          "kd": [0.0, float(_g(kmax / wt))], "tf": [tf, tf]}}
    if kind == "leadlag":
        return {"type": "leadlag", "bounds": {"k": [0.0, kmax], "z": [float(_g(0.05 * wt)), float(_g(20 * wt))],
                                              "p": [float(_g(0.05 * wt)), float(_g(50 * wt))]}}
    n = int(rng.integers(1, 4))
    m = int(rng.integers(0, min(n, 2) + 1))
    bounds: dict[str, list[float]] = {}
    for i in range(m + 1):
        b = float(_g(kmax * wt ** (n - i) * 10))
        bounds[f"b{i}"] = [-b, b]
    for i in range(n):
        bounds[f"a{i}"] = [0.0, float(_g(50 * wt ** (n - i) * 3 ** n))]
    return {"type": "rational", "order": [m, n], "bounds": bounds}


def _requirements(rng: np.random.Generator, wt: float, kind: str, num: np.ndarray, den: np.ndarray,
                  simple: bool) -> list[dict[str, Any]]:
    pool = ["bandwidth", "sensitivity", "sensitivity_static", "peak_sensitivity", "peak_complementary",
            "peak_control_sensitivity", "margins", "slew_rate"]
    if simple:
        pool = ["bandwidth", "peak_sensitivity", "margins", "sensitivity_static"]
    n = int(rng.integers(1, 4))
    chosen = list(rng.choice(pool, size=n, replace=False))
    reqs: list[dict[str, Any]] = []
    for t in map(str, chosen):
        if t == "bandwidth":
            r: dict[str, Any] = {"type": t, "min": float(_g(wt * 10 ** rng.uniform(-0.8, 0.6)))}
            if rng.random() < 0.2:
                r["max"] = float(_g(r["min"] * 10 ** rng.uniform(0.2, 1.0)))
        elif t == "sensitivity":
            hi = float(_g(wt * 10 ** rng.uniform(-1.5, -0.3)))
            lo = 0.0 if rng.random() < 0.5 else float(_g(hi * 0.01))
            r = {"type": t, "max_db": float(_g(rng.uniform(-25, -3))), "band": [lo, hi]}
        elif t == "sensitivity_static":
            r = {"type": t, "max_db": float(_g(rng.uniform(-30, -6)))}
            if den[-1] == 0.0 or rng.random() < 0.5:
                r["plant_gain"] = float(_g(10 ** rng.uniform(-0.5, 1.0)))
        elif t in ("peak_sensitivity", "peak_complementary"):
            r = {"type": t, "max_db": float(_g(rng.uniform(1.0, 9.0)))}
        elif t == "peak_control_sensitivity":
            r = {"type": t, "max_db": float(_g(rng.uniform(5.0, 35.0)))}
        elif t == "margins":
            r = {"type": t}
            which = rng.choice(3, size=int(rng.integers(1, 3)), replace=False)
            if 0 in which:
                r["gain_margin_db"] = float(_g(rng.uniform(2.0, 12.0)))
            if 1 in which:
                r["phase_margin_deg"] = float(_g(rng.uniform(20.0, 70.0)))
            if 2 in which:
                r["delay_margin"] = float(_g(rng.uniform(0.05, 0.6) / wt))
        else:  # slew_rate
            de = float(_g(10 ** rng.uniform(-1, 0.5)))
            r = {"type": t, "rate_limit": float(_g(de * wt * 10 ** rng.uniform(0.3, 2.0))), "max_error": de,
                 "band": [float(_g(0.01 * wt)), float(_g(wt * 10 ** rng.uniform(0.0, 1.0)))]}
        reqs.append(r)
    return reqs


def problem(seed: int, index: int, *, controllers: tuple[str, ...] = CONTROLLERS, simple: bool = False,
            biproper: float = 0.0, type3: float = 0.0) -> Problem:
    """The ``index``-th problem of the sequence ``seed`` (independent of the other indices).

    Parameters
    ----------
    seed, index : int
        The problem is a pure function of both.
    controllers : tuple of str
        Structures to draw from.
    simple : bool
        Order 1-2 stable plants and cheap requirement types only (for the test suite).
    biproper : float
        Share of biproper plants (zeros added up to the plant's order). They are decided and drawn from a stream
        of their own, so every other draw, and every problem of a sequence with ``biproper=0`` (all results
        before session 21), stays as it was.
    type3 : float
        Share of plants that are a double integrator with a zero (``k (s + z) / (s^2 (s + p1) [(s + p2)])``),
        drawn from a stream of their own in place of the plant ``rng`` would draw (the draws after the plant
        stay those of the sequence with ``type3=0``, except that the plant's own draws are skipped).

    Examples
    --------
    >>> p = problem(1, 0)
    >>> [r["type"] for r in problem(1, 0).spec["requirements"]] != []
    True
    """
    rng = np.random.default_rng([seed, index])
    wt = float(_g(10 ** rng.uniform(-1, 2)))
    extra = np.random.default_rng([seed, index, 1])
    third = np.random.default_rng([seed, index, 3])
    if not simple and third.random() < type3:
        (tf,), num, den, feats = _type3_plant(third, wt)
    else:
        (tf,), num, den, feats = _plant(rng, wt, simple, extra if extra.random() < biproper else None)
    delay = 0.0
    if rng.random() < 0.6:
        delay = float(_g(rng.uniform(0, 1) ** 2 * 0.5 * 2 * np.pi / wt * (0.2 if simple else 1.0)))
        feats.append("delay")
    kind = str(rng.choice(controllers))
    spec: dict[str, Any] = {
        "name": f"rand_{seed}_{index}",
        "plant": {"tf": tf, "delay": delay},
        "controller": _controller(rng, kind, wt),
        "requirements": _requirements(rng, wt, kind, num, den, simple),
    }
    u = rng.random()
    spec["objective"] = {"maximize": "bandwidth"} if u < 0.6 else ({"minimize": "peak_sensitivity"} if u < 0.8 else None)
    if spec["objective"] is None:
        del spec["objective"]
    elif "minimize" in spec["objective"] and not any(r["type"] == "bandwidth" for r in spec["requirements"]):
        # without a bandwidth floor, min peak |S| tends to 0 dB at a vanishing gain (no best point)
        spec["requirements"].append({"type": "bandwidth", "min": float(_g(wt * 10 ** rng.uniform(-0.8, 0.3)))})
    return Problem(index, spec, [float(x) for x in num], [float(x) for x in den], delay, feats)


def generate(n: int, seed: int = 0, **kwargs: Any) -> list[Problem]:
    """Problems ``0 .. n-1`` of the sequence ``seed``.

    Examples
    --------
    >>> len(generate(3, seed=2))
    3
    """
    return [problem(seed, i, **kwargs) for i in range(n)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--biproper", type=float, default=0.0, help="share of biproper plants")
    ap.add_argument("--type3", type=float, default=0.0, help="share of double integrators with a zero")
    args = ap.parse_args()
    for p in generate(args.n, args.seed, biproper=args.biproper, type3=args.type3):
        print(json.dumps(p.to_dict()))


if __name__ == "__main__":
    main()
