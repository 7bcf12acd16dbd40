"""The pieces an NLP is written with: the controller as casadi symbols, the problem builder, and the
loop's frequency response in those symbols (the plant exact, its delay as ``cos(w tau) - j sin(w tau)``)."""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from synth.controllers import RATIONAL, Controller, rational_order
from synth.loop import Loop
from synth.plant import Plant
from synth.synthesis.cxcomplex import Cx, delay_jw, polyval_jw

__all__ = [
    "BACKOFF",
    "IPOPT_OPTIONS",
    "PHASE_CROSSOVER_FLOOR",
    "SCALAR_FORM",
    "SYM",
    "TIGHT",
    "NLPBuilder",
    "SymbolicController",
    "loop_response",
    "phase_crossings",
    "phase_crossovers",
    "t0_squared",
]

SYM = ca.MX
"""Symbol type of the NLP. Matrix expressions: a requirement on n frequencies is a handful of vector
operations on numeric columns, not n scalar graphs, so building the solver (derivatives included) costs
milliseconds instead of a tenth of a second for a few thousand constraints."""

IPOPT_OPTIONS = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": 1500,
                 "ipopt.hessian_approximation": "limited-memory",
                 "ipopt.tol": 1e-9, "ipopt.constr_viol_tol": 1e-9, "ipopt.mu_max": 1e-3, "show_eval_warnings": False}
"""IPOPT's options for the polish. A trial point where a constraint is NaN is rejected by IPOPT's line search;
casadi's warning about it went to the terminal of ``synth design --quiet`` (``show_eval_warnings``).
``mu_max`` caps the barrier parameter of the adaptive strategy (IPOPT's
choice under the limited-memory Hessian). A polish starts from a design that already meets the requirements,
usually near an optimum; with hundreds of grid constraints, the barrier terms of a large ``mu`` outweigh the
objective and pulled the iterates far from that start, which then took hundreds of small steps to come back
(the servo PID of ``benchmarks/cli_speed.py``: 714 iterations instead of 8; seed 8 #272's PD polish: 2,289
instead of 54, the same answers; benchmarks/README.md, session 18)."""


SCALAR_FORM = True
"""Whether ``NLPBuilder.solve(expand=True)`` evaluates the problem as scalar expressions; False keeps every solve
in matrix expressions (the baseline of ``benchmarks/polish_scalar_form.py``)."""

BACKOFF = 1e-4
"""Relative tightening of magnitude bounds (as in the convex stage): about 0.001 dB."""


TIGHT = 1.0 - 2 * BACKOFF
"""Tightening of squared magnitudes."""


class SymbolicController:
    """A controller whose free parameters are casadi symbols, scaled by their starting magnitudes."""

    def __init__(self, ctype: str, start: Controller, bounds: dict[str, tuple[float, float]],
                 box: dict[str, tuple[float, float]] | None = None) -> None:
        self.ctype = ctype
        self.box = box or bounds  # the variables' bounds this time (a trust region inside ``bounds``)
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
        return np.array([self.box[p][0] for p in self.free]) / self.scale

    def ubx(self) -> np.ndarray:
        return np.array([self.box[p][1] for p in self.free]) / self.scale

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
        """``C(0)`` (None with integral action). A PI or PID whose ``ki`` is fixed at 0 (the design without
        integral action) has none: ``C(0) = kp``."""
        parts = self.dc_parts()
        return None if parts is None else parts[0] if isinstance(parts[1], float) else parts[0] / parts[1]

    def dc_parts(self) -> tuple[Any, Any] | None:
        """``C(0)`` as ``(numerator, denominator)`` (None with integral action), so that a rational
        controller's free ``a0`` may reach 0 (an integrator) without a division by zero in the NLP."""
        v = self.values
        if self.ctype == "P" or (self.ctype in ("PI", "PID") and self.fixed.get("ki") == 0.0):
            return v["kp"], 1.0
        if self.ctype == "leadlag":
            return v["k"] * v["z"], v["p"]
        if self.ctype == RATIONAL and not (self.fixed.get("a0") == 0.0):
            return v["b0"], v["a0"]
        return None

    def integral_gain(self) -> Any:
        if self.ctype == RATIONAL:
            return self.values["b0"] / self.values["a1"] if "a1" in self.values else self.values["b0"]
        return self.values["ki"]

    def controller(self, u: np.ndarray) -> Controller:
        """The controller at the scaled variables ``u``, each parameter clipped into its bounds (IPOPT may end
        a relative 1e-8 outside them)."""
        vals = {**{p: float(np.clip(u[i] * self.scale[i], *self.bounds[p])) for i, p in enumerate(self.free)},
                **self.fixed}
        return Controller(self.ctype, vals)


class NLPBuilder:
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
        self.offsets: dict[str, int] = {}
        """Position in the solution of the first variable of each name."""

    def var(self, name: str, x0: float, lo: float, hi: float) -> Any:
        v = SYM.sym(name)
        self.offsets.setdefault(name, sum(len(a) for a in self.x0))
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

    def solve(self, options: dict[str, Any] | None = None, x0: np.ndarray | None = None, expand: bool = False,
              ) -> tuple[np.ndarray, dict[str, Any]]:
        """Solve with :data:`IPOPT_OPTIONS` updated by ``options`` from ``x0`` (default: the variables' starts);
        the solution and IPOPT's statistics. ``expand`` evaluates the problem as scalar expressions (casadi's
        SX): 0.05-0.25 s more to build; the exact Hessian's evaluation is much faster so (a second-order
        rational controller's design: 78.8 -> 60.4 s of CPU), while the limited-memory solves gained on some
        problems and lost on others (``benchmarks/polish_scalar_form.py``), so they keep the matrix form."""
        x = ca.vertcat(*self.x)
        g = ca.vertcat(*self.g) if self.g else SYM(0, 1)
        solver = ca.nlpsol("polish", "ipopt", {"x": x, "f": self.f, "g": g}, {**IPOPT_OPTIONS, **(options or {}),
                                                                            "expand": expand and SCALAR_FORM})
        res = solver(x0=np.concatenate(self.x0) if x0 is None else x0, lbx=np.concatenate(self.lbx),
                     ubx=np.concatenate(self.ubx), lbg=np.array(self.lbg), ubg=np.array(self.ubg))
        return np.asarray(res["x"]).ravel(), solver.stats()


def loop_response(ctrl: SymbolicController, plant: Plant, w: Any) -> tuple[Cx, Cx]:
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


def t0_squared(ctrl: SymbolicController, plant: Plant) -> Any:
    """``|T(0)|^2`` in the symbols (1 with integral action, in the controller or in the plant)."""
    parts = ctrl.dc_parts()
    g0 = plant.dc_gain()
    if parts is None or not np.isfinite(g0):  # an integrator in the plant: T(0) = 1 for any controller gain
        return 1.0
    n0 = parts[0] * g0  # T(0) = n G(0) / (d + n G(0)) with C(0) = n / d: 1 where d reaches 0 (an integrator)
    return (n0 / (parts[1] + n0)) ** 2


PHASE_CROSSOVER_FLOOR = 0.1
"""Crossings of the negative real axis where ``|L|`` is below this (-20 dB) are not counted as the NLP's
crossovers (a new round starts when their number changes); the margins form holds those within 10 dB of its
gain margin bound. A long delay crosses the axis every ``pi/delay`` rad/s up to where ``|L|`` fades, hundreds
of times for a biproper controller."""


def phase_crossovers(loop: Loop, floor: float = PHASE_CROSSOVER_FLOOR) -> np.ndarray:
    """Frequencies where ``L`` crosses the negative real axis inside the unit circle with ``|L| >= floor``
    (:func:`phase_crossings`).

    Examples
    --------
    >>> from synth.plant import Plant
    >>> from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s+1)", delay=1.0), Controller("P", {"kp": 0.5}))
    >>> phase_crossovers(loop, 0.05).round(3)  # w + atan(w) = pi, 3 pi, ...: |L| = 0.5/sqrt(1 + w^2) to w = 10
    array([2.029, 7.979])
    >>> phase_crossovers(loop).round(3)  # |L| >= 0.1 to w = 4.9
    array([2.029])
    """
    return phase_crossings(loop, floor)[0]


def phase_crossings(loop: Loop, floor: float = PHASE_CROSSOVER_FLOOR,
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(w, lo, hi)``: the crossings of the negative real axis inside the unit circle where ``|L| >= floor``,
    and for each the interval up to the neighbouring zeros of ``Im L`` (half-way, in ``log w``), where it is the
    only zero. With a delay the grid resolves the delay's phase (steps of ``pi/4 / delay``) wherever ``|L|``
    reaches ``floor``: a log grid alone aliases the crossings of a long delay.

    Examples
    --------
    >>> from synth.plant import Plant
    >>> from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s+1)", delay=1.0), Controller("P", {"kp": 0.5}))
    >>> w, lo, hi = phase_crossings(loop, 0.05)
    >>> bool(np.all((lo < w) & (w < hi))), bool(hi[0] <= lo[1])
    (True, True)
    """
    from synth.freqgrid import crossings, log_grid, resolving_grid
    from synth.synthesis.delay_grid import delay_resolving_step

    lo, hi = loop.frequency_range
    grid = log_grid(lo, hi * 10, 200)
    if loop.delay > 0:
        with np.errstate(all="ignore"):
            reach = np.flatnonzero(np.abs(loop.L(grid)) >= floor / 4)  # and the zeros next to the last one
        if reach.size:
            grid = resolving_grid(lo, hi * 10, 200, delay_resolving_step(loop.delay), max_points=500_000,
                                  even_until=float(grid[min(int(reach[-1]) + 1, grid.size - 1)]))
    with np.errstate(all="ignore"):
        zeros = crossings(lambda w: np.imag(loop.L(w)), 0.0, grid)
        L = loop.L(zeros)
    keep = np.flatnonzero((np.real(L) < 0) & (np.abs(L) < 1.0) & (np.abs(L) >= floor))
    w = zeros[keep]
    below = np.where(keep > 0, np.sqrt(zeros[np.maximum(keep - 1, 0)] * w), lo)
    above = np.where(keep < zeros.size - 1, np.sqrt(zeros[np.minimum(keep + 1, zeros.size - 1)] * w), hi * 10)
    return w, below, above
