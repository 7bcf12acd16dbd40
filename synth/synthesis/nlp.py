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

Rounds. Each NLP is built around its start design: its gain and phase crossovers (variables in boxes
around them that reach half-way to the neighbouring crossings, so that a held crossing cannot slide onto
another; with a delay the phase crossings are found on a grid that resolves the delay's phase, and those far
below the gain margin's bound are left out, :func:`~synth.synthesis.nlp_problem.phase_crossings`), the
local maxima of ``|S|``, ``|T|``, ``|KS|`` near a peak bound (variables held at a stationary point of the
curve between its neighbouring minima, :mod:`synth.synthesis.nlp_peaks`, so a peak narrower than the grid's
spacing is bounded where it is) and points around every lightly damped root of the loop. Another round starts from
the answer when its crossovers changed or a helper variable ended on its box; an answer violated only between
grid points is solved again from the same start with those frequencies (and the answer's sharp peaks) added,
since an interior-point method restarted at an optimum with its constraints active wanders. A peak objective's
maximum that the answer has off the grid (searched where the score searches it, which reaches below the grid
where ``|S|`` rises towards ``|S(0)|``) is bounded in the next round's objective. Likewise a bandwidth objective's dip: where
the answer's ``|T|`` falls below the level between the ratios' samples, short of the bandwidth variable, its least
value is held at the level in the next round, from the same start. An answer whose
closed loop is unstable (a step jumped over the thin region where ``|1 + L|`` is small on the grid) is
discarded and the round repeated in a trust region around its start, which grows again when it held a step
back; from then on every close approach of the start's Nyquist curve to -1 is held on its side
(:mod:`synth.synthesis.nlp_sides`), so that the next answers cannot cross it between the grid's points
either. Where IPOPT stopped unconverged at a stable loop is offered to the certificate like every candidate.
IPOPT runs with a limited-memory BFGS Hessian and its adaptive barrier parameter capped
(:data:`~synth.synthesis.nlp_problem.IPOPT_OPTIONS`); a round that stops at the iteration limit (the quasi-Newton
steps can crawl along curved active constraints) is continued from where it stopped with the exact Hessian.
"""

import time
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from synth.controllers import Controller
from synth.loop import BANDWIDTH_LEVEL, Loop
from synth.plant import Plant
from synth.requirements import Bandwidth, PeakSensitivity
from synth.requirements.base import Requirement
from synth.synthesis.convex_settings import resonance_points
from synth.synthesis.nlp_forms import NLP_FORMS, NLPContext
from synth.synthesis.nlp_problem import (
    TIGHT,
    NLPBuilder,
    SymbolicController,
    loop_response,
    phase_crossovers,
    t0_squared,
)
from synth.synthesis.nlp_sides import hold_sides

__all__ = ["NLPResult", "polish"]


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
    candidates: list[Controller] = field(default_factory=list)
    """The design of every round IPOPT solved, last first (a later round that fails keeps the earlier ones), and
    where an unconverged round stopped at a stable loop (first): every one is only a candidate for the
    certificate."""

    def to_dict(self) -> dict[str, Any]:
        return {"success": self.success, "status": self.status, "controller": self.controller.to_dict(),
                "objective_value": self.objective_value, "rounds": self.rounds, "iterations": self.iterations,
                "solve_time": self.solve_time, "history": self.history}


def _term(b: NLPBuilder, name: str, plants: list[Plant], grid: np.ndarray, start: Controller,
          peaks_at: np.ndarray, dips: np.ndarray) -> Any:
    """The measure ``name`` as a casadi expression in its natural unit (adds helper variables); a peak is
    bounded on ``grid`` and at ``peaks_at`` (the maxima earlier rounds' answers had off the grid), a bandwidth
    also held at ``dips`` (where earlier answers' ``|T|`` fell below the level between the ratios' samples)."""
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
        t02 = t0_squared(ctrl, plant)
        _, L = loop_response(ctrl, plant, v * ca.DM(np.geomspace(1e-3, 1.0, 80)))  # one column: 80 ratios
        if name == "bandwidth":
            b.geq(L.abs2() - BANDWIDTH_LEVEL**2 * t02 * (1.0 + L).abs2())
            if dips.size:  # with the backoff of magnitude bounds: the dip moves a little with the next answer
                _, Ld = loop_response(ctrl, plant, dips)
                b.geq(TIGHT * Ld.abs2() - BANDWIDTH_LEVEL**2 * t02 * (1.0 + Ld).abs2())
        else:
            b.geq(L.abs2() - 1.0)
        return v
    grid = np.union1d(grid, peaks_at)  # for the peaks below; a bandwidth or crossover stays within the grid's range
    if name == "peak_sensitivity":
        ms0 = float(np.max(np.abs(loop0.S(grid))))
        gamma = b.var("gamma", 1.0 / ms0, 1e-6, 1.0)
        for p in plants:
            _, L = loop_response(ctrl, p, grid)
            b.geq((1.0 + L).abs2() - gamma**2)
        return -20 * ca.log10(gamma)
    if name in ("peak_complementary", "control_effort"):
        curve = loop0.T if name == "peak_complementary" else loop0.KS
        m0 = float(np.max(np.abs(curve(grid))))
        M = b.var("M", max(m0, 1e-9), 1e-9, max(1e3 * m0, 1e-6))  # a start without gain: m0 = 0
        for p in plants:
            C, L = loop_response(ctrl, p, grid)
            top = L if name == "peak_complementary" else C
            b.geq(M**2 * (1.0 + L).abs2() - top.abs2())
        return 20 * ca.log10(M)
    raise ValueError(f"no NLP objective {name}")


def _add_objective(b: NLPBuilder, terms: list[tuple[str, str, float]], plants: list[Plant], grid: np.ndarray,
                   start: Controller, peaks_at: np.ndarray, dips: np.ndarray) -> None:
    """Minimize ``-sum(w s f)`` scaled by its value at the start (``s`` = +1 maximize, -1 minimize)."""
    from synth.objectives import score

    total = 0.0
    for name, sense, weight in terms:
        total = total + weight * (1.0 if sense == "maximize" else -1.0) * _term(b, name, plants, grid, start, peaks_at, dips)
    scale = max(abs(score(Loop(plants[0], start), terms)), 1e-6)
    b.f = -total / scale


def polish(requirements: list[Requirement], plants: list[Plant], start: Controller,
           bounds: dict[str, tuple[float, float]], objective: list[tuple[str, str, float]], grid: np.ndarray,
           per_decade: int = 40, stability_level: float = 0.05, rounds: int = 6,
           max_iter: int | None = None) -> NLPResult:
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
    max_iter : int, optional
        IPOPT's iteration limit per round (default :data:`IPOPT_OPTIONS`'s).

    Returns
    -------
    NLPResult
        ``success`` means IPOPT converged in at least one round; ``candidates`` holds each such round's design
        and, when a round stopped unconverged (an iteration limit) at a stable loop, where it stopped;
        ``controller`` is the last of them. The caller certifies every candidate.

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
    bounds = _regime_bounds(bounds, start, requirements, objective)
    history: list[dict[str, Any]] = []
    current = start
    iterations = 0
    status = "not run"
    grid = np.asarray(grid, float)
    extra = np.array([])
    missed = np.array([])  # maxima of a peak objective that earlier answers had off the grid
    dips = np.array([])  # minima of |T| below a bandwidth objective that earlier answers had between its samples
    converged = False
    solved: list[Controller] = []
    radius: float | None = None  # a trust region once a step has jumped out of the stabilizing set
    exact_from_now = False
    hold_sides_now = HOLD_SIDES == "always"
    shrinks = 0
    settled = False  # the last answer needed no further round
    # a peak |S| bound of at most 1/stability_level holds |1 + L| further from zero on the grid and every extra point:
    # the keeping's rows would repeat it (a third of a robust PI's 2,835 rows; IPOPT's time grows with them)
    kept_by_peak = any(isinstance(r, PeakSensitivity) and r.linear_bound("max_db") * stability_level <= 1.0
                       for r in requirements)
    for rnd in range(rounds + MAX_SHRINKS):
        if rnd - shrinks >= rounds:
            break
        ctrl = SymbolicController(current.type, current, bounds, _trust_box(bounds, current, radius))
        b = NLPBuilder(ctrl)
        ctx = NLPContext(grid, np.union1d(extra, resonance_points(plants, current, grid)), per_decade, current,
                         tuple(solved[:1]) if solved and solved[0] is not current else ())
        for req in requirements:
            build = NLP_FORMS.entry(req).build
            for plant in plants:
                build(b, req, plant, ctx)
        held = 0
        for p in plants:  # keep |1 + L| away from zero: no closed-loop pole crosses the axis on the grid
            _, L = loop_response(ctrl, p, grid)
            if not kept_by_peak:
                b.geq((1.0 + L).abs2() - stability_level**2)
            if hold_sides_now:  # an earlier answer crossed -1: the start's close approaches keep their side
                held += hold_sides(b, p, current, (float(grid[0]), float(grid[-1])), stability_level)
        _add_objective(b, objective, plants, grid, current, missed, dips)
        if exact_from_now:  # an earlier round's quasi-Newton steps crawled: this problem gets the exact Hessian
            x, stats = b.solve(EXACT_HESSIAN, expand=True)
        else:
            x, stats = b.solve(None if max_iter is None else {"ipopt.max_iter": max_iter})
        iterations += int(stats.get("iter_count", 0))
        exact = max_iter is None and not exact_from_now \
            and str(stats.get("return_status")) == "Maximum_Iterations_Exceeded" and bool(np.all(np.isfinite(x)))
        if exact:
            # limited-memory BFGS can crawl along a curved active set in steps of a constant size: the same NLP
            # with the exact Hessian, from where it stopped (not for the screen's short polishes), and so the
            # rounds after it; where the crawl stopped stays a candidate
            exact_from_now = True
            stopped = ctrl.controller(x[: len(ctrl.free)])
            if _stable(plants, stopped):
                solved.insert(0, stopped)
                history.append({"round": rnd, "status": str(stats.get("return_status")), "controller": str(stopped),
                                "offered": True})
            x, stats = b.solve(EXACT_HESSIAN, x, expand=True)
            iterations += int(stats.get("iter_count", 0))
        status = str(stats.get("return_status"))
        success = bool(stats.get("success"))
        candidate = ctrl.controller(x[: len(ctrl.free)])
        history.append({"round": rnd, "status": status, "controller": str(candidate),
                        **({"exact_hessian": "after limited-memory BFGS stopped at its iteration limit"}
                           if exact_from_now else {}), **({"held_approaches_to_minus_one": held} if held else {})})
        converged = converged or success
        if not success:  # where IPOPT stopped may still pass: the certificate decides, as for every candidate
            if np.all(np.isfinite(x)) and _stable(plants, candidate):
                solved.insert(0, candidate)
                history[-1]["offered"] = True
            break
        if not _stable(plants, candidate):  # |1 + L| >= level on the grid, yet a step jumped over the boundary
            history[-1]["unstable"] = True
            hold_sides_now = HOLD_SIDES != "never"
            if shrinks == MAX_SHRINKS:
                break
            radius, shrinks = (1.0 if radius is None else radius / 4), shrinks + 1
            continue
        solved.insert(0, candidate)
        between = _violated_frequencies(requirements, plants, candidate)
        peaks = _missed_peaks(objective, plants, candidate, np.union1d(np.union1d(grid, extra), missed))
        missed = np.union1d(missed, _with_neighbours(peaks))
        # (only a bandwidth objective makes a variable of that name)
        dip = _missed_dip(plants[0], candidate, float(x[b.offsets["bandwidth"]]) if "bandwidth" in b.offsets else None)
        dips = np.union1d(dips, _with_neighbours(dip))
        between = np.concatenate([between, peaks, dip])
        if between.size:  # and the candidate's sharp features, which the next answer moves only a little
            extra = np.unique(np.concatenate([extra, _with_neighbours(between),
                                              resonance_points(plants, candidate, grid)]))
        # the NLP is built around this round's start (its crossovers, boxes of the crossover and bandwidth
        # variables): another round from the candidate is needed when its crossovers changed or a helper
        # variable ended on its box; otherwise the same NLP from the candidate would end where it is
        trust_edge = radius is not None and _at_trust_edge(ctrl, candidate)
        if trust_edge:  # the trust region held the step back: the next one may go further
            radius *= 4
        if _crossovers_changed(current, candidate, plants) or _at_helper_box(b, x, len(ctrl.free)) or trust_edge:
            current, settled = candidate, False
        elif not between.size:
            settled = True
            break
        # else violated only between grid points: the same start again with those frequencies added (an interior
        # point method restarted at an optimum, its constraints active, wanders; cf. the servo PID in benchmarks)
    if not settled and solved:
        # the rounds ran out while the last answer asked for another (on its trust region's edge, a helper on its
        # box, crossovers that moved; or the round after it left the stabilizing set): a KKT point of that
        # round's NLP, not shown to be one of the problem's
        last = next(h for h in reversed(history) if h["controller"] == str(solved[0]) and not h.get("unstable"))
        if not last.get("offered"):
            last.update(offered=True, rounds_exhausted=True)
    value = None
    if solved:
        from synth.objectives import score

        current = solved[0]
        value = score(Loop(plants[0], current), objective)
    return NLPResult(converged, status, current, value, len({h["round"] for h in history}), iterations,
                     time.perf_counter() - t_start, history, solved)


def _regime_bounds(bounds: dict[str, tuple[float, float]], start: Controller, requirements: list[Requirement],
                  objective: list[tuple[str, str, float]]) -> dict[str, tuple[float, float]]:
    """The bounds of a polish from ``start``: a PI or PID whose ``ki`` is 0 there keeps it at 0 where the NLP
    measures a bandwidth against ``|T(0)|`` (a bandwidth objective or requirement). ``|T(0)|`` jumps from
    ``kp G(0)/(1 + kp G(0))`` at ``ki = 0`` to 1 at any ``ki > 0``, and the NLP takes 1 for a free ``ki``: from such
    a start its bandwidth rows were unmeetable, and IPOPT wandered for hundreds of iterations to "infeasible"
    (a robust PI, 406 iterations, 4.5 s). The regime with integral action is the other starts'.

    Examples
    --------
    >>> from synth.requirements import Bandwidth
    >>> box = {"kp": (0.0, 5.0), "ki": (0.0, 5.0)}
    >>> _regime_bounds(box, Controller("PI", {"kp": 1.0, "ki": 0.0}), [], [("bandwidth", "maximize", 1.0)])["ki"]
    (0.0, 0.0)
    >>> _regime_bounds(box, Controller("PI", {"kp": 1.0, "ki": 0.5}), [Bandwidth(type="bandwidth", min=2.0)], [])["ki"]
    (0.0, 5.0)
    """
    t0_relative = any(name == "bandwidth" for name, _, _ in objective) or any(isinstance(r, Bandwidth)
                                                                               for r in requirements)
    if t0_relative and start.type in ("PI", "PID") and start.parameters.get("ki") == 0.0 and "ki" in bounds:
        return {**bounds, "ki": (0.0, 0.0)}
    return bounds


HOLD_SIDES = "after_unstable"
"""When the polish holds the start's close approaches to -1 on their side (:mod:`synth.synthesis.nlp_sides`):
``"after_unstable"`` (from the round after an answer whose closed loop was unstable), ``"always"`` or ``"never"``
(the behaviour before, for comparisons)."""

MAX_SHRINKS = 3
"""Times a round is repeated in a smaller trust region after its answer left the stabilizing set."""

EXACT_ITERATIONS = 500
"""IPOPT's iteration limit when a round that stopped at its limit goes on with the exact Hessian."""

EXACT_HESSIAN = {"ipopt.hessian_approximation": "exact", "ipopt.max_iter": EXACT_ITERATIONS}


def _trust_box(bounds: dict[str, tuple[float, float]], at: Controller, radius: float | None,
               ) -> dict[str, tuple[float, float]] | None:
    """``bounds`` cut to ``at +- radius (|value| + 1 % of the range)`` (None: no trust region)."""
    if radius is None:
        return None
    box = {}
    for k, (lo, hi) in bounds.items():
        x = float(at.parameters[k])
        half = radius * (abs(x) + 0.01 * (hi - lo if np.isfinite(hi - lo) else max(abs(x), 1.0)))
        box[k] = (lo, hi) if lo == hi else (max(lo, x - half), min(hi, x + half))
    return box


def _at_trust_edge(ctrl: SymbolicController, c: Controller, tol: float = 1e-6) -> bool:
    """Whether a free parameter of ``c`` sits on the trust region's edge where it is inside the bounds."""
    for k in ctrl.free:
        (lo, hi), (blo, bhi), v = ctrl.box[k], ctrl.bounds[k], float(c.parameters[k])
        size = tol * max(abs(v), hi - lo, 1e-12)
        if (lo > blo and v - lo <= size) or (hi < bhi and hi - v <= size):
            return True
    return False


def _stable(plants: list[Plant], c: Controller) -> bool:
    """Closed loop stable on every plant (the exact count; "not certified" counts as unstable)."""
    for p in plants:
        try:
            if not Loop(p, c).stability().stable:
                return False
        except (ArithmeticError, ValueError, RuntimeError):
            return False
    return True


def _at_helper_box(b: NLPBuilder, x: np.ndarray, n_controller: int, tol: float = 1e-6) -> bool:
    """Whether a helper variable of the solved NLP (those after the controller's ``n_controller``) ended on its
    box (within ``tol`` of its size)."""
    lo, hi = np.concatenate(b.lbx)[n_controller:], np.concatenate(b.ubx)[n_controller:]
    v = x[n_controller:]
    size = tol * np.maximum(np.abs(v), 1e-12)
    return bool(np.any((v - lo <= size) | (hi - v <= size)))


_PEAK_CURVES = {"peak_sensitivity": "S", "peak_complementary": "T", "control_effort": "KS"}


def _with_neighbours(w: np.ndarray) -> np.ndarray:
    """``w`` and the points 0.1 % either side of each (a feature the next answer moves only a little)."""
    return np.concatenate([w, w * (1 - 1e-3), w * (1 + 1e-3)])


def _missed_peaks(objective: list[tuple[str, str, float]], plants: list[Plant], c: Controller, grid: np.ndarray,
                  tol_db: float = 0.01) -> np.ndarray:
    """Frequencies of a peak-type objective's maximum (on any plant) that the NLP's grid misses by more than
    ``tol_db``: the NLP minimized the peak it could see. The maximum is searched where the objective's score
    searches it (:attr:`Loop.frequency_range`, to ten times its top), which may reach beyond the grid: below it
    where ``|S|`` rises towards ``|S(0)|``."""
    from synth.freqgrid import log_grid, peak

    out = []
    for name, _, _ in objective:
        if name not in _PEAK_CURVES:
            continue
        for p in plants:
            loop = Loop(p, c)
            curve = getattr(loop, _PEAK_CURVES[name])
            lo, hi = loop.frequency_range
            with np.errstate(all="ignore"):
                true, w = peak(lambda v, f=curve: np.abs(f(v)), np.union1d(log_grid(lo, 10 * hi, 160), grid))
                seen = float(np.max(np.abs(curve(grid))))
            if np.isfinite(true) and 20 * np.log10(true / max(seen, 1e-300)) > tol_db:
                out.append(w)
    return np.array(out, float)


def _missed_dip(plant: Plant, c: Controller, wb: float | None) -> np.ndarray:
    """The frequency (none or one) where ``|T|`` of ``c`` is least between its bandwidth and the NLP's bandwidth
    variable ``wb``, when the bandwidth falls short of ``wb``: the NLP held ``|T|`` at the level only on its
    ratios' samples, and a dip between two of them that reaches below the level ends the bandwidth there (seed
    18 #15 of the design benchmark: a PID's polish ended at 12.8 rad/s, its NLP's bandwidth 87.7 rad/s, the dip's
    least ``|T|`` 0.15 % under the level)."""
    from synth.freqgrid import log_grid, peak

    if wb is None:
        return np.array([])
    loop = Loop(plant, c)
    true = loop.bandwidth()
    if not np.isfinite(true) or true >= wb * (1.0 - 1e-6):
        return np.array([])
    with np.errstate(all="ignore"):
        _, w = peak(lambda v: 1.0 / np.abs(loop.T(v)), log_grid(true, wb, 400))
    return np.array([w], float) if np.isfinite(w) else np.array([])


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
        if phase_crossovers(Loop(p, a)).size != phase_crossovers(Loop(p, b)).size:
            return True
    return False
