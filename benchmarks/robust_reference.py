"""An independent multi-plant reference for ``synth.design`` on specs with ``plant.variants``.

Imports nothing from synth. Each plant of a problem of ``benchmarks/robust_problems.py`` is one
:class:`benchmarks.design_reference.LoopModel` (exact delay, closed-loop stability by the argument principle or the
characteristic polynomial's roots, 1600 points per decade, refined peaks and crossings), extended here by the
requirement types that model lacks, each from its definition in docs/spec-format.md:

- ``delay_margin``: the minimum over the gain crossovers of ``PM/wc`` (PM in [0, 360) deg; ``inf`` without a
  crossover), slack ``ln(value/min)``;
- ``disk_margin``: ``alpha = 1/max |S + (skew - 1)/2|`` over the grid (peak refined by Brent search), ``w = 0``
  and ``w -> inf`` (``|S| -> 1`` for the strictly proper plants generated), slack ``ln(alpha/min)``;

and by the objectives ``crossover`` (the highest gain crossover, the lowest one recorded too), ``integral_gain``
(``ki``), ``low_frequency_gain`` (``|C(0)|``), ``peak_complementary`` and ``control_effort`` (peak ``|KS|``, dB).

A controller is feasible when every plant's loop is stable and every requirement holds on every plant (the worst
plant counts, docs/spec-format.md, ``variants``). Each requirement's robust slack is its minimum over the plants.
The objective is evaluated on the nominal plant (the doc does not say which plant; the value on every plant is
recorded beside it). The search of the controller box follows ``benchmarks/design_reference.py``: one free
parameter, a grid of 400 values then bisection to the boundary and golden refinement; two, a 48 x 48 grid
(linear and logarithmic) then Nelder-Mead; more, random points then Nelder-Mead from the best; screened on 160
points per decade, every point called feasible passed the dense check on every plant. A point found is a proof of
feasibility; none found is evidence only.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import minimize, minimize_scalar

from benchmarks.design_reference import LN10_20, Evaluation, LoopModel, _log_crossing, _unseen_crossings

__all__ = ["BASE_TYPES", "PlantModel", "RobustEvaluation", "RobustModel", "RobustResult", "check_point", "reference"]

BASE_TYPES = ("bandwidth", "sensitivity", "sensitivity_static", "peak_sensitivity", "peak_complementary",
              "peak_control_sensitivity", "margins", "slew_rate")
"""Requirement types :class:`benchmarks.design_reference.LoopModel` evaluates itself."""

MAXIMIZED = ("bandwidth", "crossover", "integral_gain", "low_frequency_gain")


class PlantModel(LoopModel):
    """:class:`LoopModel` of one plant with ``delay_margin``, ``disk_margin`` and every objective added.

    Examples
    --------
    >>> spec = {"controller": {"type": "P", "bounds": {"kp": [0, 10]}},
    ...         "requirements": [{"type": "disk_margin", "min": 0.5}]}
    >>> e = PlantModel([1.0], [1.0, 1.0], 0.0, spec).evaluate({"kp": 1.0})
    >>> round(e.values["0:disk_margin"], 6)   # |S - 1/2| peaks at 1/2 (w -> inf): alpha = 2
    2.0
    """

    def __init__(self, num: list[float], den: list[float], delay: float, spec: dict[str, Any],
                 eps_scale: float = 1e-6) -> None:
        reqs = spec["requirements"]
        # the base model reads r["min"] as a frequency when it sizes its grid: give it the delay margin's 1/min
        shown = [{"type": "x", "delay_margin": r["min"]} if r["type"] == "delay_margin" else
                 ({"type": "x"} if r["type"] == "disk_margin" else r) for r in reqs]
        super().__init__(num, den, delay, {**spec, "requirements": shown}, eps_scale)
        self.requirements = reqs

    def _requirements(self, p: dict[str, float], cn: np.ndarray, cd: np.ndarray, g: dict[str, np.ndarray],
                      dense: bool) -> Evaluation:
        reqs, objective = self.requirements, self.objective
        base = [(k, r) for k, r in enumerate(reqs) if r["type"] in BASE_TYPES]
        self.requirements = [r for _, r in base]
        self.objective = objective if objective is not None and objective[1] in ("bandwidth", "peak_sensitivity") \
            else None
        try:
            ev = super()._requirements(p, cn, cd, g, dense)
        finally:
            self.requirements, self.objective = reqs, objective
        # the base model keys by position in its own (filtered) list: back to the spec's positions
        rename = {f"{j}:{r['type']}": f"{k}:{r['type']}" for j, (k, r) in enumerate(base)}

        def key(x: str) -> str:
            head = ":".join(x.split(":")[:2])
            return rename[head] + x[len(head):] if head in rename else x

        ev.slacks = {key(x): v for x, v in ev.slacks.items()}
        ev.values = {key(x): v for x, v in ev.values.items()}
        self._extras(ev, cn, cd, g, dense)
        return ev

    def _extras(self, ev: Evaluation, cn: np.ndarray, cd: np.ndarray, g: dict[str, np.ndarray], dense: bool) -> None:
        w = g["w"]

        def Lf(x: float) -> complex:
            return complex(self.G(np.array([x]))[0] * np.polyval(cn, 1j * x) / np.polyval(cd, 1j * x))

        def closed(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            s = 1j * np.asarray(x, float)
            a = np.polyval(self.den, s) * np.polyval(cd, s)
            b = np.polyval(self.num, s) * np.polyval(cn, s) * np.exp(-self.delay * s)
            return a / (a + b), b / (a + b), np.polyval(cn, s) * np.polyval(self.den, s) / (a + b)

        with np.errstate(all="ignore"):
            S, T, KS = closed(w)
            L = self.G(w) * np.polyval(cn, 1j * w) / np.polyval(cd, 1j * w)

        def peak(y: np.ndarray, f: Any) -> float:
            i = int(np.argmax(y))
            best = float(y[i])
            if dense and 0 < i < len(w) - 1:
                r = minimize_scalar(lambda lx: -f(np.exp(lx)), bounds=(np.log(w[i - 1]), np.log(w[i + 1])),
                                    method="bounded", options={"xatol": 1e-10})
                best = max(best, float(-r.fun))
            return best

        def crossovers() -> list[float]:
            mag = np.log(np.abs(L))
            brackets = [(w[i], w[i + 1]) for i in np.nonzero(np.sign(mag[:-1]) * np.sign(mag[1:]) < 0)[0]]
            brackets += _unseen_crossings(lambda x: np.log(abs(Lf(x))), w, mag)
            return sorted(_log_crossing(lambda x: np.log(abs(Lf(x))), a, b, 1e-13) for a, b in brackets)

        wcs: list[float] | None = None
        for k, r in enumerate(self.requirements):
            t, name = r["type"], f"{k}:{r['type']}"
            if t == "delay_margin":
                wcs = crossovers() if wcs is None else wcs
                dm = np.inf
                for x in wcs:
                    lag = (np.degrees(np.angle(Lf(x))) + 180.0) % 360.0
                    dm = min(dm, np.radians(lag) / x)
                ev.values[name] = float(dm)
                ev.slacks[name] = float(np.log(dm / r["min"])) if dm > 0 else -10.0
            elif t == "disk_margin":
                c = (float(r.get("skew", 0.0)) - 1.0) / 2.0
                y = np.abs(S + c)
                m = peak(y, lambda x, c=c: float(abs(closed(np.array([x]))[0][0] + c)))
                s0 = closed(np.array([0.0]))[0][0]
                if np.isfinite(s0):
                    m = max(m, float(abs(s0 + c)))
                m = max(m, abs(1.0 + c))  # w -> inf: the plants are strictly proper, S -> 1
                alpha = 1.0 / m
                ev.values[name] = alpha
                ev.slacks[name] = float(np.log(alpha / r["min"]))
            elif t not in BASE_TYPES:
                raise ValueError(f"reference: no definition for requirement type {t!r}")
        if self.objective is None:
            return
        name = self.objective[1]
        if name in ("bandwidth", "peak_sensitivity"):
            return  # the base model's
        if name == "crossover":
            wcs = crossovers() if wcs is None else wcs
            ev.objective = float(wcs[-1]) if wcs else 0.0
            ev.values["crossover_lowest"] = float(wcs[0]) if wcs else 0.0
        elif name == "integral_gain":
            ev.objective = float(ev.params.get("ki", cn[-1] if cd[-1] == 0 else 0.0))
        elif name == "low_frequency_gain":
            ev.objective = float(abs(cn[-1] / cd[-1])) if cd[-1] != 0 else np.inf
        elif name in ("peak_complementary", "control_effort"):
            y = np.abs(T if name == "peak_complementary" else KS)
            i = 1 if name == "peak_complementary" else 2
            ev.objective = float(20 * np.log10(peak(y, lambda x, i=i: float(abs(closed(np.array([x]))[i][0])))))
        else:
            raise ValueError(f"reference: no objective {name!r}")


@dataclass
class RobustEvaluation:
    """One controller checked on every plant."""

    params: dict[str, float]
    per_plant: dict[str, Evaluation]
    dense: bool = False
    slacks: dict[str, float] = field(default_factory=dict)
    worst_plant: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for label, e in self.per_plant.items():
            for k, v in e.slacks.items():
                if k not in self.slacks or v < self.slacks[k]:
                    self.slacks[k], self.worst_plant[k] = v, label

    @property
    def stable(self) -> bool:
        return all(e.stable for e in self.per_plant.values())

    @property
    def min_slack(self) -> float:
        return float(min(e.min_slack for e in self.per_plant.values()))

    @property
    def objective(self) -> float | None:
        return self.per_plant["nominal"].objective if "nominal" in self.per_plant else None

    def feasible(self, tol: float = 0.0) -> bool:
        return all(e.feasible(tol) for e in self.per_plant.values())

    def failures(self, tol: float = 0.0) -> list[dict[str, Any]]:
        """Every (plant, requirement) that fails: its value and slack."""
        out = []
        for label, e in self.per_plant.items():
            if not e.stable:
                out.append({"plant": label, "requirement": "closed-loop stability",
                            "value": f"{e.unstable_poles} unstable root(s)", "slack": -float(e.unstable_poles)})
                continue
            for k, v in e.slacks.items():
                if v < -tol:
                    vals = {x: y for x, y in e.values.items() if x == k or x.startswith(k + ":")}
                    out.append({"plant": label, "requirement": k, "value": vals, "slack": v})
        return out

    def to_dict(self) -> dict[str, Any]:
        return {"params": self.params, "stable": self.stable, "slacks": self.slacks, "worst_plant": self.worst_plant,
                "objective": self.objective, "min_slack": self.min_slack,
                "per_plant": {k: e.to_dict() for k, e in self.per_plant.items()}}


class RobustModel:
    """Every plant of a problem as a :class:`PlantModel`; the nominal plant first.

    Examples
    --------
    >>> spec = {"controller": {"type": "P", "bounds": {"kp": [0, 10]}},
    ...         "requirements": [{"type": "bandwidth", "min": 2}], "objective": {"maximize": "bandwidth"}}
    >>> m = RobustModel([("nominal", [1.0], [1.0, 1.0], 0.0), ("v1", [0.5], [1.0, 1.0], 0.0)], spec)
    >>> e = m.evaluate({"kp": 3.0})   # |T| 3 dB below |T(0)| at 0.99763 (kp g + 1): 3.99 and 2.49
    >>> e.feasible(), e.worst_plant["0:bandwidth"], round(e.objective, 4)
    (True, 'v1', 3.9905)
    """

    def __init__(self, plants: list[tuple[str, list[float], list[float], float]], spec: dict[str, Any],
                 eps_scale: float = 1e-6) -> None:
        self.models = {label: PlantModel(num, den, delay, spec, eps_scale) for label, num, den, delay in plants}
        first = next(iter(self.models.values()))
        self.bounds, self.free, self.objective = first.bounds, first.free, first.objective
        self.order = list(self.models)  # evaluation order: the plant that failed last goes first

    def params(self, x: np.ndarray) -> dict[str, float]:
        return next(iter(self.models.values())).params(x)

    def evaluate(self, p: dict[str, float], dense: bool = True, screen: bool = False) -> RobustEvaluation:
        """Check ``p`` on every plant; ``screen`` stops at the first unstable loop (the others are skipped)."""
        per: dict[str, Evaluation] = {}
        for label in list(self.order):
            e = self.models[label].evaluate(dict(p), dense)
            per[label] = e
            if not e.feasible():
                self.order.remove(label)
                self.order.insert(0, label)
                if screen and not e.stable:
                    break
        ordered = {k: per[k] for k in self.models if k in per}
        return RobustEvaluation(dict(p), ordered, dense)


@dataclass
class RobustResult:
    """The best point the reference found, and its effort."""

    feasible: bool
    best: RobustEvaluation | None
    evaluations: int
    seconds: float
    method: str

    def to_dict(self) -> dict[str, Any]:
        return {"feasible": self.feasible, "best": None if self.best is None else self.best.to_dict(),
                "evaluations": self.evaluations, "seconds": self.seconds, "method": self.method}


class _Search:
    def __init__(self, model: RobustModel, tol: float, deadline: float) -> None:
        self.m, self.tol, self.n, self.deadline = model, tol, 0, deadline
        self.best: RobustEvaluation | None = None

    def score(self, ev: RobustEvaluation) -> float:
        """Larger is better: the objective in log units (nepers), or the smallest slack without one."""
        if self.m.objective is None:
            return ev.min_slack
        _sense, name = self.m.objective
        v = ev.objective
        if v is None or not np.isfinite(v):
            return np.inf if (v is not None and name in MAXIMIZED) else -np.inf
        if name in MAXIMIZED:
            return float(np.log(max(v, 1e-300)))
        return float(-v * LN10_20)

    def ev(self, p: dict[str, float], dense: bool) -> RobustEvaluation:
        self.n += 1
        e = self.m.evaluate(p, dense, screen=not dense)
        if dense and e.feasible(-self.tol) and (self.best is None or self.score(e) > self.score(self.best)):
            self.best = e
        return e

    def penalty(self, x: np.ndarray) -> float:
        if time.perf_counter() > self.deadline:
            return 1e5
        e = self.ev(self.m.params(x), dense=False)
        if not e.feasible(-self.tol):
            if not e.stable:
                return 1e4 + sum(x.unstable_poles for x in e.per_plant.values() if not x.stable)
            return 1e3 - e.min_slack
        return -self.score(e)


def reference(plants: list[tuple[str, list[float], list[float], float]], spec: dict[str, Any], *,
              tol: float = 1e-4, budget: float = 1.0, seed: int = 0, max_seconds: float = 600.0) -> RobustResult:
    """Search the controller box of ``spec`` for the best point that passes the dense check on every plant.

    Parameters
    ----------
    plants : list of (label, num, den, delay)
        The nominal plant (label ``nominal``) first.
    spec : dict
        The spec (controller bounds, requirements, objective).
    tol : float
        Slack (nepers, radians) a point must have on every plant to count as feasible.
    budget : float
        Scales the number of grid points and starts.
    seed : int
        Random stream of the starts.
    max_seconds : float
        Wall-time cap of the search (the result says when it was reached).

    Returns
    -------
    RobustResult

    Examples
    --------
    >>> spec = {"controller": {"type": "P", "bounds": {"kp": [0, 10]}},
    ...         "requirements": [{"type": "bandwidth", "max": 6}], "objective": {"maximize": "bandwidth"}}
    >>> r = reference([("nominal", [1.0], [1.0, 1.0], 0.0), ("v1", [2.0], [1.0, 1.0], 0.0)], spec)
    >>> r.feasible, round(r.best.params["kp"], 3)   # v1's bandwidth (2 kp + 1) 0.99763 <= 6
    (True, 2.507)
    """
    with np.errstate(all="ignore"):
        return _reference(plants, spec, tol, budget, seed, max_seconds)


def _reference(plants: list[tuple[str, list[float], list[float], float]], spec: dict[str, Any], tol: float,
               budget: float, seed: int, max_seconds: float) -> RobustResult:
    t0 = time.perf_counter()
    m = RobustModel(plants, spec)
    srch = _Search(m, tol, t0 + max_seconds)
    rng = np.random.default_rng(seed)
    lo = np.array([m.bounds[k][0] for k in m.free])
    hi = np.array([m.bounds[k][1] for k in m.free])
    nfree = len(m.free)
    if nfree == 0:
        srch.ev(m.params(np.array([])), dense=True)
        method = "fixed"
    elif nfree == 1:
        n = max(50, int(200 * budget))
        xs = np.unique(lo[0] + (hi[0] - lo[0]) * np.concatenate([np.linspace(0, 1, n), np.logspace(-5, 0, n)]))
        evs = [srch.ev(m.params(np.array([x])), dense=False) for x in xs]
        # candidates: points within 0.05 of feasible on the coarse grid (design_reference.py asks for a slack of
        # +0.05 here, which stops its refinement short of a boundary optimum: 2.36 for 2.51 on 2/(s+1))
        scores = np.array([srch.score(e) if e.feasible(0.05) else -np.inf for e in evs])
        ok = np.nonzero(scores > -np.inf)[0]
        done = 0
        for i in ok[np.argsort(-scores[ok], kind="stable")][:12]:
            if not srch.ev(evs[i].params, dense=True).feasible(-tol):
                continue
            done += 1
            for j in (i - 1, i + 1):
                if not 0 <= j < len(xs):
                    continue
                a, b = xs[i], xs[j]
                if srch.ev(m.params(np.array([b])), dense=True).feasible(-tol):
                    if m.objective is not None:
                        r = minimize_scalar(lambda x: _dense_pen(srch, x), bounds=(min(a, b), max(a, b)),
                                            method="bounded", options={"xatol": 1e-7 * max(1.0, abs(a))})
                        _dense_pen(srch, r.x)
                else:
                    for _ in range(30):
                        c = 0.5 * (a + b)
                        if srch.ev(m.params(np.array([c])), dense=True).feasible(-tol):
                            a = c
                        else:
                            b = c
            if m.objective is None or done >= 2:
                break
        method = f"grid {len(xs)} + boundary bisection"
    else:
        if nfree == 2:
            k = max(12, int(32 * np.sqrt(budget)))
            axis = np.unique(np.concatenate([np.linspace(0, 1, k), np.logspace(-6, 0, k // 2)]))
            g1, g2 = np.meshgrid(axis, axis)
            U = np.column_stack([g1.ravel(), g2.ravel()])
            method = f"grid {axis.size}x{axis.size} (linear and log) + Nelder-Mead"
        else:
            U = rng.random((max(60, int(300 * budget)), nfree))
            third = len(U) // 3
            U[:third] = U[:third] ** 3
            U[third: 2 * third] = 10.0 ** (-6.0 * U[third: 2 * third])
            method = f"{len(U)} random starts + Nelder-Mead"
        X = lo + (hi - lo) * U
        pen = np.array([srch.penalty(x) for x in X])
        starts = X[np.argsort(pen)[: max(3, int(8 * budget))]]
        if m.objective is None:
            for x0 in starts[:3]:
                if srch.ev(m.params(x0), dense=True).feasible(-tol):
                    starts = starts[:0]
                    break
        scale = hi - lo
        for x0 in starts:
            if time.perf_counter() > srch.deadline:
                method += " (time cap reached)"
                break
            r = minimize(lambda u: srch.penalty(lo + scale * np.clip(u, 0, 1)), (x0 - lo) / scale,
                         method="Nelder-Mead", options={"maxfev": int(300 * budget) + 50, "xatol": 1e-7,
                                                        "fatol": 1e-9})
            xe = lo + scale * np.clip(r.x, 0, 1)
            if not srch.ev(m.params(xe), dense=True).feasible(-tol):
                a, b = x0, xe
                if srch.ev(m.params(a), dense=True).feasible(-tol):
                    for _ in range(30):
                        c = 0.5 * (a + b)
                        if srch.ev(m.params(c), dense=True).feasible(-tol):
                            a = c
                        else:
                            b = c
    best = srch.best
    return RobustResult(best is not None, best, srch.n, time.perf_counter() - t0, method)


def _dense_pen(srch: _Search, x: float) -> float:
    e = srch.ev(srch.m.params(np.array([x])), dense=True)
    return -srch.score(e) if e.feasible(-srch.tol) else 1e3 - e.min_slack


def check_point(plants: list[tuple[str, list[float], list[float], float]], spec: dict[str, Any],
                params: dict[str, float], eps_scale: float = 1e-6) -> RobustEvaluation:
    """Dense check of one controller on every plant (e.g. synth's design).

    Examples
    --------
    >>> spec = {"controller": {"type": "P", "bounds": {"kp": [0, 10]}},
    ...         "requirements": [{"type": "delay_margin", "min": 0.1}]}
    >>> e = check_point([("nominal", [1.0], [1.0, 0.0], 0.0), ("v1", [4.0], [1.0, 0.0], 0.0)], spec, {"kp": 1.0})
    >>> e.worst_plant["0:delay_margin"], round(e.per_plant["v1"].values["0:delay_margin"], 6)   # (pi/2)/4
    ('v1', 0.392699)
    """
    with np.errstate(all="ignore"):
        return RobustModel(plants, spec, eps_scale).evaluate(dict(params), dense=True)

