"""NLP polish with casadi + IPOPT: exact requirements and non-convex objectives.

Starting from a design (usually the convex answer), every controller
parameter of the structure is free within its bounds (including the PID
filter ``tf`` and the lead-lag pole ``p`` that the convex stage holds fixed)
and the requirements are imposed exactly on a frequency grid, written as
smooth functions of the parameters:

=====================  ==========================================================
requirement            NLP constraint (per frequency, per plant)
=====================  ==========================================================
|S| <= m               m^2 |1 + L|^2 - 1 >= 0
|T| <= M               |1 + L|^2 - |L|^2 / M^2 >= 0
|KS| <= M              |1 + L|^2 - |C|^2 / M^2 >= 0
slew rate              1 - (De w / B)^2 |C|^2 >= 0
static sensitivity     m^2 (1 + g C(0))^2 - 1 >= 0
bandwidth >= wb        |L|^2 - l^2 T0^2 |1 + L|^2 >= 0 for w <= wb
phase margin           at each gain crossover w_c (a variable with |L(j w_c)| = 1):
                       |1 + L(j w_c)|^2 >= 4 sin^2(PM/2)
delay margin           |1 + L(j w_c)|^2 >= 4 sin^2(w_c DM / 2)
gain margin            at each phase crossover w_p (a variable with Im L = 0):
                       Re L(j w_p) >= -1/g
=====================  ==========================================================

The delay enters exactly as ``cos(w tau) - j sin(w tau)``. Objectives that are
not convex are exact here: the bandwidth is a variable ``wb`` with
``|T(j r wb)| >= l T0`` for ratios ``r`` in (0, 1]; peak |S| is ``1/gamma`` with
``|1 + L| >= gamma``. Crossovers are re-detected after each solve (at most a few
rounds), and the result is only accepted by the caller after the dense
certificate.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from synth.controllers import RATIONAL, Controller, rational_order
from synth.freqgrid import band_grid
from synth.loop import BANDWIDTH_LEVEL, Loop
from synth.plant import Plant
from synth.requirements import (
    Bandwidth,
    MarginsRequirement,
    PeakComplementary,
    PeakSensitivity,
    Sensitivity,
    SlewRate,
    StaticSensitivity,
)
from synth.requirements.base import Requirement, magnitude
from synth.requirements.control_sensitivity import PeakControlSensitivity
from synth.synthesis.cxcomplex import Cx, delay_jw, polyval_jw
from synth.synthesis.form_registry import FormRegistry

__all__ = [
    "BACKOFF",
    "IPOPT_OPTIONS",
    "NLP_FORMS",
    "SYM",
    "TIGHT",
    "NLPContext",
    "NLPResult",
    "SymbolicController",
    "nlp_form",
    "polish",
]

SYM = ca.MX
"""Symbol type of the NLP. Matrix expressions: a requirement on n frequencies is a handful of vector
operations on numeric columns, not n scalar graphs, so building the solver (derivatives included) costs
milliseconds instead of a tenth of a second for a few thousand constraints."""

IPOPT_OPTIONS = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": 1500,
                 "ipopt.hessian_approximation": "limited-memory",
                 "ipopt.tol": 1e-9, "ipopt.constr_viol_tol": 1e-9}


@dataclass
class NLPResult:
    """Outcome of :func:`polish`."""

    success: bool
    status: str
    controller: Controller
    objective_value: float | None
    rounds: int
    iterations: int
    solve_time: float
    history: list[dict[str, Any]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {"success": self.success, "status": self.status, "controller": self.controller.to_dict(),
                "objective_value": self.objective_value, "rounds": self.rounds, "iterations": self.iterations,
                "solve_time": self.solve_time, "history": self.history}


class SymbolicController:
    """A controller whose free parameters are casadi symbols, scaled by their starting magnitudes."""

    def __init__(self, ctype: str, start: Controller, bounds: dict[str, tuple[float, float]]) -> None:
        self.ctype = ctype
        kind = start.kind
        self.free = [p for p in kind.parameters if bounds[p][0] < bounds[p][1]]
        self.fixed = {p: bounds[p][0] for p in kind.parameters if bounds[p][0] == bounds[p][1]}
        self.bounds = bounds
        x0 = np.array([start.parameters[p] for p in self.free], float)
        span = np.array([bounds[p][1] - bounds[p][0] for p in self.free], float)
        # variables of order one: scaled by their start value, or by 1 % of their range when that is larger
        self.scale = np.maximum(np.abs(x0), np.where(np.isfinite(span), 1e-2 * span, 1.0))
        self.scale = np.where(self.scale > 0, self.scale, 1.0)
        self.u = SYM.sym("u", len(self.free))
        self.u0 = x0 / self.scale
        self.values = {**{p: self.u[i] * self.scale[i] for i, p in enumerate(self.free)}, **self.fixed}

    def lbx(self) -> np.ndarray:
        return np.array([self.bounds[p][0] for p in self.free]) / self.scale

    def ubx(self) -> np.ndarray:
        return np.array([self.bounds[p][1] for p in self.free]) / self.scale

    def response(self, w: Any) -> Cx:
        """``C(j w)`` for a numeric or symbolic ``w`` (> 0)."""
        v = self.values
        jw = Cx(0.0, w)
        if self.ctype == "P":
            return Cx(v["kp"], 0.0)
        if self.ctype == "PI":
            return Cx(v["kp"], -v["ki"] / w)
        if self.ctype == "PID":
            return Cx(v["kp"], -v["ki"] / w) + v["kd"] * jw / (v["tf"] * jw + 1.0)
        if self.ctype == "leadlag":
            return v["k"] * (jw + v["z"]) / (jw + v["p"])
        if self.ctype == RATIONAL:
            m, n = rational_order(v)
            num = polyval_jw([v[f"b{i}"] for i in range(m, -1, -1)], w)
            den = polyval_jw([1.0] + [v[f"a{i}"] for i in range(n - 1, -1, -1)], w)
            return num / den
        raise NotImplementedError(self.ctype)

    def dc(self) -> Any | None:
        """``C(0)`` (None with integral action)."""
        v = self.values
        if self.ctype == "P":
            return v["kp"]
        if self.ctype == "leadlag":
            return v["k"] * v["z"] / v["p"]
        if self.ctype == RATIONAL and not (self.fixed.get("a0") == 0.0):
            return v["b0"] / v["a0"]
        return None

    def integral_gain(self) -> Any:
        if self.ctype == RATIONAL:
            return self.values["b0"] / self.values["a1"] if "a1" in self.values else self.values["b0"]
        return self.values["ki"]

    def controller(self, u: np.ndarray) -> Controller:
        vals = {**{p: float(u[i] * self.scale[i]) for i, p in enumerate(self.free)}, **self.fixed}
        return Controller(self.ctype, vals)


class _Builder:
    """Collects variables, constraints and the objective of one NLP."""

    def __init__(self, ctrl: SymbolicController) -> None:
        self.ctrl = ctrl
        self.x = [ctrl.u]
        self.x0 = [ctrl.u0]
        self.lbx = [ctrl.lbx()]
        self.ubx = [ctrl.ubx()]
        self.g: list[Any] = []
        self.lbg: list[float] = []
        self.ubg: list[float] = []
        self.f: Any = 0.0

    def var(self, name: str, x0: float, lo: float, hi: float) -> Any:
        v = SYM.sym(name)
        self.x.append(v)
        self.x0.append(np.array([x0]))
        self.lbx.append(np.array([lo]))
        self.ubx.append(np.array([hi]))
        return v

    def geq(self, expr: Any) -> None:
        """``expr >= 0`` (a scalar or one entry per frequency)."""
        self._add(expr, np.inf)

    def eq(self, expr: Any) -> None:
        """``expr == 0``."""
        self._add(expr, 0.0)

    def _add(self, expr: Any, upper: float) -> None:
        expr = expr if isinstance(expr, (ca.SX, ca.MX)) else SYM(expr)
        self.g.append(expr)
        self.lbg.extend([0.0] * expr.numel())
        self.ubg.extend([upper] * expr.numel())

    def solve(self) -> tuple[np.ndarray, dict[str, Any]]:
        x = ca.vertcat(*self.x)
        g = ca.vertcat(*self.g) if self.g else SYM(0, 1)
        solver = ca.nlpsol("polish", "ipopt", {"x": x, "f": self.f, "g": g}, IPOPT_OPTIONS)
        res = solver(x0=np.concatenate(self.x0), lbx=np.concatenate(self.lbx), ubx=np.concatenate(self.ubx),
                     lbg=np.array(self.lbg), ubg=np.array(self.ubg))
        return np.asarray(res["x"]).ravel(), solver.stats()


def _loop(ctrl: SymbolicController, plant: Plant, w: Any) -> tuple[Cx, Cx]:
    """``(C(jw), L(jw))`` with the plant exact (delay included).

    ``w`` is a casadi symbol, a number, or an array of frequencies: then every
    part is a column with one entry per frequency (one vectorized expression
    instead of one per frequency, which keeps building the NLP cheap).
    """
    C = ctrl.response(w)
    if isinstance(w, (ca.SX, ca.MX)):
        G = polyval_jw(plant.num, w) / polyval_jw(plant.den, w) * delay_jw(plant.delay, w)
    elif np.ndim(w):
        g = plant.freqresp(np.asarray(w, float))
        G = Cx(np.real(g), np.imag(g))
    else:
        G = Cx.of(complex(plant.freqresp(np.array([w]))[0]))
    return C, C * G


def _t0_squared(ctrl: SymbolicController, plant: Plant) -> Any:
    dc = ctrl.dc()
    if dc is None:
        return 1.0
    l0 = dc * plant.dc_gain()
    return (l0 / (1.0 + l0)) ** 2


def _positive(w: np.ndarray) -> np.ndarray:
    return w[w > 0]


BACKOFF = 1e-4
"""Relative tightening of magnitude bounds (as in the convex stage): about 0.001 dB."""


def _band(req: Any, grid: np.ndarray, extra: np.ndarray, per_decade: int) -> np.ndarray:
    auto = (float(grid[0]), float(grid[-1]))
    band = getattr(req, "band", None)
    if band is None:
        return np.unique(np.concatenate([grid, extra]))
    w = _positive(band_grid(band, auto, per_decade))
    inside = extra[(extra >= band[0]) & (extra <= band[1])]
    return np.unique(np.concatenate([w, inside]))


NLP_FORMS = FormRegistry("NLP")
"""The NLP form of each requirement type (filled by :func:`nlp_form` below)."""


def nlp_form(requirement: type[Requirement], *, exact: bool) -> Callable[[Callable], Callable]:
    """Decorator: register ``build(b, req, plant, ctx)`` as the NLP form of ``requirement`` (it adds the
    requirement's constraints on one plant to the problem being built).

    Examples
    --------
    >>> from synth.requirements import MarginsRequirement
    >>> NLP_FORMS.entry(MarginsRequirement).exact
    True
    """
    return NLP_FORMS.register(requirement, exact=exact)


@dataclass
class NLPContext:
    """What every NLP form is built from: the design grid, the extra frequencies found between its
    points, the band density and the design the problem starts from."""

    grid: np.ndarray
    extra: np.ndarray
    per_decade: int
    start: Controller

    def points(self, req: Any) -> np.ndarray:
        """The requirement's band (the design grid without one), with the extra frequencies inside it."""
        return _band(req, self.grid, self.extra, self.per_decade)


TIGHT = 1.0 - 2 * BACKOFF
"""Tightening of squared magnitudes."""


@nlp_form(Sensitivity, exact=True)
@nlp_form(PeakSensitivity, exact=True)
def _sensitivity(b: _Builder, req: Sensitivity | PeakSensitivity, plant: Plant, ctx: NLPContext) -> None:
    m2 = req.linear_bound("max_db") ** 2 * TIGHT
    _, L = _loop(b.ctrl, plant, ctx.points(req))
    b.geq(m2 * (1.0 + L).abs2() - 1.0)


@nlp_form(StaticSensitivity, exact=True)
def _static_sensitivity(b: _Builder, req: StaticSensitivity, plant: Plant, ctx: NLPContext) -> None:
    dc = b.ctrl.dc()
    if dc is not None:
        g = req.plant_gain if req.plant_gain is not None else plant.dc_gain()
        b.geq(TIGHT / req.linear_bound("max_db") ** 2 * (1.0 + g * dc) ** 2 - 1.0)


@nlp_form(PeakComplementary, exact=True)
def _peak_complementary(b: _Builder, req: PeakComplementary, plant: Plant, ctx: NLPContext) -> None:
    _, L = _loop(b.ctrl, plant, ctx.points(req))
    b.geq((1.0 + L).abs2() - L.abs2() / (req.linear_bound("max_db") ** 2 * TIGHT))


@nlp_form(PeakControlSensitivity, exact=True)
def _peak_control_sensitivity(b: _Builder, req: PeakControlSensitivity, plant: Plant, ctx: NLPContext) -> None:
    C, L = _loop(b.ctrl, plant, ctx.points(req))
    b.geq((1.0 + L).abs2() - C.abs2() / (req.linear_bound("max_db") ** 2 * TIGHT))


@nlp_form(SlewRate, exact=True)
def _slew_rate(b: _Builder, req: SlewRate, plant: Plant, ctx: NLPContext) -> None:
    w = ctx.points(req)
    C, _ = _loop(b.ctrl, plant, w)
    b.geq(TIGHT - (req.max_error * w / req.rate_limit) ** 2 * C.abs2())


@nlp_form(Bandwidth, exact=True)
def _bandwidth(b: _Builder, req: Bandwidth, plant: Plant, ctx: NLPContext) -> None:
    t02 = _t0_squared(b.ctrl, plant)
    grid, extra = ctx.grid, ctx.extra
    if req.min is not None:
        pts = np.concatenate([grid[grid < req.min], extra[extra < req.min], [req.min]])
        _, L = _loop(b.ctrl, plant, np.unique(pts))
        b.geq(TIGHT * L.abs2() - BANDWIDTH_LEVEL**2 * t02 * (1.0 + L).abs2())
    if req.max is not None:
        _, L = _loop(b.ctrl, plant, float(req.max))
        b.geq(TIGHT * BANDWIDTH_LEVEL**2 * t02 * (1.0 + L).abs2() - L.abs2())


@nlp_form(MarginsRequirement, exact=True)
def _margins(b: _Builder, req: MarginsRequirement, plant: Plant, ctx: NLPContext) -> None:
    loop = Loop(plant, ctx.start)
    ctrl = b.ctrl
    for wc in loop.gain_crossovers():
        v = b.var("wc", float(wc), wc / 3.0, 3.0 * wc)
        _, L = _loop(ctrl, plant, v)
        b.eq(L.abs2() - 1.0)
        if req.phase_margin_deg is not None:
            b.geq((1.0 + L).abs2() - 4 * np.sin(np.radians(req.phase_margin_deg * (1 + BACKOFF)) / 2) ** 2)
        if req.delay_margin is not None:
            b.geq((1.0 + L).abs2() - 4 * ca.sin(ca.fmin(v * req.delay_margin, np.pi) / 2) ** 2)
    if req.gain_margin_db is not None:
        for wp in _phase_crossovers(loop):
            v = b.var("wp", float(wp), wp / 3.0, 3.0 * wp)
            _, L = _loop(ctrl, plant, v)
            b.eq(L.im)
            b.geq(L.re + 1.0 / magnitude(req.gain_margin_db * (1 + BACKOFF)))


def _phase_crossovers(loop: Loop) -> np.ndarray:
    """Frequencies where ``L`` crosses the negative real axis inside the unit circle."""
    from synth.freqgrid import crossings, log_grid

    lo, hi = loop.frequency_range
    grid = log_grid(lo, hi * 10, 200)
    imag = crossings(lambda w: np.imag(loop.L(w)), 0.0, grid)
    L = loop.L(imag)
    keep = (np.real(L) < 0) & (np.abs(L) < 1.0)
    return imag[keep]


def _term(b: _Builder, name: str, plants: list[Plant], grid: np.ndarray, start: Controller) -> Any:
    """The measure ``name`` as a casadi expression in its natural unit (adds helper variables)."""
    ctrl = b.ctrl
    plant = plants[0]
    loop0 = Loop(plant, start)
    if name == "integral_gain":
        return ctrl.integral_gain()
    if name == "low_frequency_gain":
        dc = ctrl.dc()
        return ctrl.integral_gain() if dc is None else dc
    if name in ("bandwidth", "crossover"):
        w0 = loop0.bandwidth() if name == "bandwidth" else (loop0.crossover() or grid[0])
        v = b.var(name, float(w0), float(grid[0]), float(grid[-1]))
        t02 = _t0_squared(ctrl, plant)
        for r in np.geomspace(1e-3, 1.0, 80):
            _, L = _loop(ctrl, plant, v * r)
            if name == "bandwidth":
                b.geq(L.abs2() - BANDWIDTH_LEVEL**2 * t02 * (1.0 + L).abs2())
            else:
                b.geq(L.abs2() - 1.0)
        return v
    if name == "peak_sensitivity":
        ms0 = float(np.max(np.abs(loop0.S(grid))))
        gamma = b.var("gamma", 1.0 / ms0, 1e-6, 1.0)
        for p in plants:
            _, L = _loop(ctrl, p, grid)
            b.geq((1.0 + L).abs2() - gamma**2)
        return -20 * ca.log10(gamma)
    if name in ("peak_complementary", "control_effort"):
        curve = loop0.T if name == "peak_complementary" else loop0.KS
        m0 = float(np.max(np.abs(curve(grid))))
        M = b.var("M", m0, 1e-9, 1e3 * m0)
        for p in plants:
            C, L = _loop(ctrl, p, grid)
            top = L if name == "peak_complementary" else C
            b.geq(M**2 * (1.0 + L).abs2() - top.abs2())
        return 20 * ca.log10(M)
    raise ValueError(f"no NLP objective {name}")


def _add_objective(b: _Builder, terms: list[tuple[str, str, float]], plants: list[Plant], grid: np.ndarray,
                   start: Controller) -> None:
    """Minimize ``-sum(w s f)`` scaled by its value at the start (``s`` = +1 maximize, -1 minimize)."""
    from synth.objectives import score

    total = 0.0
    for name, sense, weight in terms:
        total = total + weight * (1.0 if sense == "maximize" else -1.0) * _term(b, name, plants, grid, start)
    scale = max(abs(score(Loop(plants[0], start), terms)), 1e-6)
    b.f = -total / scale


def polish(requirements: list[Requirement], plants: list[Plant], start: Controller,
           bounds: dict[str, tuple[float, float]], objective: list[tuple[str, str, float]], grid: np.ndarray,
           per_decade: int = 40, stability_level: float = 0.05, rounds: int = 6) -> NLPResult:
    """Improve ``start`` with IPOPT on the exact requirements; see the module docstring.

    Parameters
    ----------
    requirements, plants
        As in the spec.
    start : Controller
        Starting design (should meet the requirements).
    bounds : dict
        ``{parameter: (lo, hi)}``; ``lo == hi`` fixes a parameter.
    objective : list of (name, sense, weight)
        Terms of the objective (see :meth:`synth.spec.ObjectiveSpec.terms`).
    grid : ndarray
        Frequency grid (rad/s) for peak-type requirements and stability keeping.

    Returns
    -------
    NLPResult
        ``success`` means IPOPT converged; the caller still certifies the design.

    Examples
    --------
    >>> from synth.requirements import PeakSensitivity
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    >>> req = PeakSensitivity(type="peak_sensitivity", max_db=6)
    >>> r = polish([req], [G], Controller("PI", {"kp": 1.0, "ki": 20.0}), {"kp": (0, 10), "ki": (0, 200)},
    ...            [("integral_gain", "maximize", 1.0)], np.geomspace(0.01, 1e3, 250))
    >>> r.success, round(r.controller.parameters["ki"], 1)
    (True, 24.9)
    """
    t_start = time.perf_counter()
    history: list[dict[str, Any]] = []
    current = start
    iterations = 0
    status = "not run"
    grid = np.asarray(grid, float)
    extra = np.array([])
    success = False
    for rnd in range(rounds):
        ctrl = SymbolicController(current.type, current, bounds)
        b = _Builder(ctrl)
        ctx = NLPContext(grid, extra, per_decade, current)
        for req in requirements:
            build = NLP_FORMS.entry(req).build
            for plant in plants:
                build(b, req, plant, ctx)
        for p in plants:  # keep |1 + L| away from zero: no closed-loop pole crosses the axis on the grid
            _, L = _loop(ctrl, p, grid)
            b.geq((1.0 + L).abs2() - stability_level**2)
        _add_objective(b, objective, plants, grid, current)
        x, stats = b.solve()
        iterations += int(stats.get("iter_count", 0))
        status = str(stats.get("return_status"))
        success = bool(stats.get("success"))
        candidate = ctrl.controller(x[: len(ctrl.free)])
        history.append({"round": rnd, "status": status, "controller": str(candidate)})
        if not success:
            break
        moved = _crossovers_changed(current, candidate, plants)
        between = _violated_frequencies(requirements, plants, candidate)
        from synth.objectives import score as _score

        gain = _score(Loop(plants[0], candidate), objective) - _score(Loop(plants[0], current), objective)
        improved = gain > 1e-6 * max(1.0, abs(_score(Loop(plants[0], current), objective)))
        current = candidate
        if between.size:
            extra = np.unique(np.concatenate([extra, between, between * (1 - 1e-3), between * (1 + 1e-3)]))
        # crossovers are re-detected every round: a round that still improved may have been held back by
        # the crossover variables' boxes around the previous design
        if not moved and not between.size and not improved:
            break
    value = None
    if success:
        from synth.objectives import score

        value = score(Loop(plants[0], current), objective)
    return NLPResult(success, status, current, value, len(history), iterations,
                     time.perf_counter() - t_start, history)


def _violated_frequencies(requirements: list[Requirement], plants: list[Plant], c: Controller) -> np.ndarray:
    """Binding frequencies of requirements the exact check finds violated (between grid points)."""
    from synth.check import evaluate_all

    _, per_plant = evaluate_all(requirements, plants, c, per_decade=160)
    out = [r.binding_frequency for results in per_plant.values() for r in results[1:]
           if r.slack < 0 and r.binding_frequency and r.binding_frequency > 0]
    return np.array(out, float)


def _crossovers_changed(a: Controller, b: Controller, plants: list[Plant]) -> bool:
    for p in plants:
        if Loop(p, a).gain_crossovers().size != Loop(p, b).gain_crossovers().size:
            return True
        if _phase_crossovers(Loop(p, a)).size != _phase_crossovers(Loop(p, b)).size:
            return True
    return False
