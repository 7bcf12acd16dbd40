"""A derivative-free fallback: pattern search on the exact check, from a design the NLP could not polish.

The NLP polish moves a design by gradients of requirements on a grid. Where every polish from the screen's
starts failed (each answer left the stabilizing set, or IPOPT stalled), the screen's own point was the best
certified design: a random point of the box, not optimized. Pattern search improves it using only what the
certificate itself trusts: :func:`synth.check.check` (every requirement, exact closed-loop stability with
the delay) and the objective's score, by Hooke and Jeeves' pattern search (:func:`synth.search.hooke_jeeves`)
in each parameter's scale: a move is kept when the moved design passes the check and scores better (or as
well, with more slack: a parameter the objective does not read still makes room). It is slow (one check per
trial) and finds only a local improvement, which is why it runs only there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.check import margin_slack, quick_check
from synth.controllers import Controller
from synth.errors import SynthError
from synth.freqgrid import log_grid, peak
from synth.loop import Loop
from synth.objectives import score
from synth.results import SEARCH_PER_DECADE
from synth.search import hooke_jeeves
from synth.spec import Spec
from synth.speculation import Speculator
from synth.synthesis.convex_settings import ConvexSettings, design_grid
from synth.synthesis.delay_grid import controller_gain_bound
from synth.synthesis.parametrization import parametrize

__all__ = ["BOUNDARY_CHECKS", "PATTERN_CHECKS", "PatternResult", "closest_approach", "parameter_scales", "pattern_search"]

Checked = tuple[float, float, Any]
"""A point's check in the search: (objective score, smallest requirement slack, the point's parameters or None)."""

PATTERN_CHECKS = 160
"""Most checks a pattern search makes (by default)."""

BOUNDARY_CHECKS = 400
"""Most checks of the search from a design no converged stage produced, which also moves along the active
boundary (:func:`_boundary_move`): such moves cost a few checks each."""


@dataclass(frozen=True)
class PatternResult:
    """Outcome of :func:`pattern_search`.

    Attributes
    ----------
    controller : Controller
        The best design found (the start when nothing improved it).
    improved : bool
        Whether a move improved the start.
    checks : int
        Checks made.
    final_step : float
        The largest remaining step, relative to each parameter's scale, when the search ended.
    """

    controller: Controller
    improved: bool
    checks: int
    final_step: float


def parameter_scales(x: dict[str, float], bounds: dict[str, tuple[float, float]], names: list[str]) -> np.ndarray:
    """Each parameter's scale, the unit of a search's steps: its size plus 1 % of its range.

    Examples
    --------
    >>> parameter_scales({"kp": 2.0, "ki": 0.0}, {"kp": (0.0, 10.0), "ki": (0.0, 200.0)}, ["kp", "ki"]).tolist()
    [2.1, 2.0]
    """
    return np.array([abs(x[k]) + 0.01 * (bounds[k][1] - bounds[k][0]) for k in names])


def closest_approach(plants: list[Any], c: Controller, grid: np.ndarray | None = None) -> float:
    """Smallest ``|1 + L|`` over the plants on ``grid`` (default: each loop's frequency range at
    :data:`~synth.results.SEARCH_PER_DECADE`), its minima refined between grid points (a move along a requirement's
    boundary can bring the Nyquist curve to -1 where no grid point sees it).

    Examples
    --------
    >>> from synth.plant import Plant
    >>> round(closest_approach([Plant.from_string("1/(s*(s+1))")], Controller("P", {"kp": 1.0})), 3)
    0.681
    """
    out = np.inf
    with np.errstate(all="ignore"):
        for p in plants:
            loop = Loop(p, c)
            w = grid if grid is not None else log_grid(*loop.frequency_range, SEARCH_PER_DECADE)
            peak_s, _ = peak(lambda w, loop=loop: np.abs(loop.S(w)), w)
            out = min(out, 0.0 if not np.isfinite(peak_s) else 1.0 / peak_s)
    return out


def pattern_search(spec: Spec, start: Controller, terms: list[tuple[str, str, float]],
                   max_checks: int = PATTERN_CHECKS, first_step: float = 0.1, min_step: float = 1e-4,
                   per_decade: int = SEARCH_PER_DECADE, keeping: float = 0.0, boundary_moves: bool = False,
                   ) -> PatternResult:
    """Improve ``start`` (which should pass the check) by pattern search over the spec's free parameters.

    Parameters
    ----------
    spec : Spec
    start : Controller
    terms : list of (name, sense, weight)
        The objective (:func:`synth.synthesis.integral_action.objective_terms`).
    max_checks : int
        Budget of checks.
    first_step, min_step : float
        Initial and smallest step, relative to each parameter's scale (its value plus 1 % of its range).
    per_decade : int
        Density of the checks (the caller certifies the answer at its own density).
    keeping : float
        Smallest ``|1 + L|`` a move may leave on every plant (on the design grid at ``per_decade``): the
        stability keeping of the convex and NLP stages (:class:`~synth.synthesis.convex_settings.ConvexSettings`'
        ``stability_level``), so that the search does not walk a design to the edge of stability. A start that
        comes closer to -1 on this grid (the stages keep ``|1 + L|`` only on their own grid) sets the floor
        instead: no move comes closer than the start.
    boundary_moves : bool
        Where the coordinate and pattern moves stall, also try moves along the active boundary
        (:func:`_boundary_move`) and restart from a point they find.

    Returns
    -------
    PatternResult

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))"}, "requirements": [{"type":
    ...                    "peak_sensitivity", "max_db": 6}], "controller": {"type": "PI", "bounds": {"kp": [0, 5],
    ...                    "ki": [0, 20]}}, "objective": {"maximize": "integral_gain"}})
    >>> r = pattern_search(spec, Controller("PI", {"kp": 1.0, "ki": 2.0}), [("integral_gain", "maximize", 1.0)])
    >>> r.improved, r.controller.parameters["ki"] > 5.0
    (True, True)
    """
    bounds = spec.controller.all_bounds()
    free = [k for k in sorted(bounds) if bounds[k][0] < bounds[k][1]]
    nominal = spec.nominal_plant()
    x = {k: float(v) for k, v in start.parameters.items()}
    checks = 0
    grid = design_grid(spec.plants(), list(spec.requirements), ConvexSettings(per_decade=per_decade),
                       _gain_bound(spec))

    def closest(c: Controller) -> float:
        return closest_approach(spec.plants(), c, grid)

    if keeping > 0:  # a start closer to -1 than that (between the stage's own grid points): no move comes closer
        keeping = min(keeping, closest(start))

    def value(params: dict[str, float]) -> Checked:
        nonlocal checks
        checks += 1
        return evaluated(params)

    def evaluated(params: dict[str, float]) -> Checked:
        """(objective score, smallest requirement slack, the point); (-inf, -inf, None) when the check fails or
        cannot be made (e.g. a Nyquist count that does not converge). The gain margins, the rest of the check's
        slack, wait for :func:`slack`: only a tie of scores reads the slack (a lead-lag's searches spent 19 % of a
        design's time on them)."""
        c = Controller(start.type, params)
        try:
            with np.errstate(all="ignore"):
                result = quick_check(spec, c, per_decade, margins=False)
                if not result.feasible or (keeping > 0 and closest(c) < keeping):
                    return -np.inf, -np.inf, None
                return float(score(Loop(nominal, c), terms)), result.min_slack, tuple(params.items())
        except (ArithmeticError, ValueError, RuntimeError, SynthError):  # a count that failed: not certified
            return -np.inf, -np.inf, None

    margins: dict[tuple, float] = {}

    def slack(v: Checked) -> float:
        """The check's smallest slack at ``v``'s point: its requirements' and its gain margins' (computed once; -inf
        where they cannot be, as the check that failed over them before)."""
        if v[2] is None:
            return v[1]
        if v[2] not in margins:
            try:
                with np.errstate(all="ignore"):
                    margins[v[2]] = margin_slack(spec, Controller(start.type, dict(v[2])))
            except (ArithmeticError, ValueError, RuntimeError, SynthError):
                margins[v[2]] = -np.inf
        return min(v[1], margins[v[2]])

    def better(a: Checked, b: Checked) -> bool:
        """A better score, or the same score with more slack (a move along a parameter the objective does not
        read, e.g. kp when maximizing ki, makes room for the next move of the one it reads)."""
        tie = 1e-12 * max(abs(a[0]), abs(b[0]), 1.0)
        return a[0] > b[0] + tie or (abs(a[0] - b[0]) <= tie and slack(a) > slack(b))

    first = value(x)
    if not np.isfinite(first[0]) or not free:
        return PatternResult(start, False, checks, 0.0)
    scale = parameter_scales(x, bounds, free)
    lo = np.array([bounds[k][0] for k in free]) / scale
    hi = np.array([bounds[k][1] for k in free]) / scale

    def at(z: np.ndarray) -> dict[str, float]:
        return {**x, **{k: float(np.clip(zi * si, *bounds[k])) for k, zi, si in zip(free, z, scale)}}

    z, vz = np.array([x[k] for k in free]) / scale, first
    step = first_step
    # exploratory moves come back to points they tried (the start too), by another rounding of z at times
    seen = {tuple(at(z).values()): first}
    with Speculator(lambda key: evaluated(at(np.array(key)))) as guesses:  # the likely next check on the idle core

        def searched(z: np.ndarray) -> Checked:
            nonlocal checks
            checks += 1  # counted as a check all the same: the search's path and budget do not change
            point = tuple(at(z).values())
            if point not in seen:
                seen[point] = guesses.value(tuple(z))
            return seen[point]

        def guess(z: np.ndarray) -> None:  # a point already checked needs no helper
            if tuple(at(z).values()) not in seen:
                guesses.ahead(tuple(z))

        while True:  # coordinate and pattern moves; where they stall, a move along the active boundary restarts
            found = hooke_jeeves(searched, z, lo, hi, better, step, min_step, max_checks - checks - 1,
                                 start_value=vz, ahead=guess)
            z, vz = found.z, found.value
            if not boundary_moves or len(free) < 2 or checks >= max_checks:
                break
            traded = _boundary_move(lambda z: value(at(z)), z, vz, lo, hi, better, step, min_step,
                                    lambda: max_checks - checks)
            if traded is None:
                break
            z, vz, moved_by = traded
            step = min(2 * moved_by, first_step)  # the next moves start near the scale that worked
    # a point whose gain margins cannot be computed was a failed check (they are computed at the end at the latest)
    improved = vz[0] > first[0] and better(vz, first) and slack(vz) > -np.inf
    return PatternResult(Controller(start.type, at(z)) if improved else start, improved, checks, found.step)


def _boundary_move(value: Callable[[np.ndarray], Checked], z: np.ndarray, vz: Checked,
                   lo: np.ndarray, hi: np.ndarray, better: Callable[[Checked, Checked], bool],
                   step: float, min_step: float, left: Callable[[], int],
                   ) -> tuple[np.ndarray, Checked, float] | None:
    """A move along an active requirement where coordinate moves stall: one coordinate moved by ``h`` to a
    point that passes the check but scores worse (it made slack), then another moved to where it scores best
    and better than ``z`` (:func:`_along`). ``h`` starts at ``step`` and is quartered down to ``min_step``; returns
    the point, its value and ``h``, or None when no such move helps or
    the checks left (``left()``) run out. Seed 16 #69 of the design benchmark: the bandwidth of a rational
    controller grows along its peak-|S| boundary as b0 and a0 fall together, while b0 alone lowers it and a0
    alone breaks the bound.

    Examples
    --------
    >>> def f(z):  # maximize z0 + z1 subject to z1 <= 1 - 4 z0^2 (a curved boundary; 0 slack inside)
    ...     return (float(z[0] + z[1]), 0.0) if z[1] <= 1 - 4 * z[0] ** 2 else (-np.inf, -np.inf)
    >>> better = lambda a, b: a[0] > b[0] + 1e-12
    >>> z = np.array([0.0, 1.0])  # on the boundary: moving z0 alone breaks it, z1 alone lowers the sum
    >>> moved = _boundary_move(f, z, f(z), np.full(2, -2.0), np.full(2, 2.0), better, 0.1, 1e-4, lambda: 100)
    >>> moved is not None and moved[1][0] > 1.0
    True
    """
    n = z.size
    h = step
    while h > min_step:
        for i in range(n):
            for s in (h, -h):
                y = z.copy()
                y[i] = min(max(y[i] + s, lo[i]), hi[i])
                if y[i] == z[i] or left() <= 0:
                    continue
                vy = value(y)
                if not np.isfinite(vy[0]) or better(vy, vz):
                    continue  # fails the check, or a plain coordinate move (the pattern search's own)
                for j in (j for j in range(n) if j != i):
                    for t in (h, -h):
                        best = _along(value, y, j, t, vz, lo, hi, better, left)
                        if best is not None:
                            return (*best, h)
        h /= 4
    return None


def _along(value: Callable[[np.ndarray], Checked], y: np.ndarray, j: int, t: float,
           vz: Checked, lo: np.ndarray, hi: np.ndarray,
           better: Callable[[Checked, Checked], bool], left: Callable[[], int],
           ) -> tuple[np.ndarray, Checked] | None:
    """The best point ``y + d e_j`` better than ``vz``, for ``d`` = ``t``, ``2 t``, ``4 t``, ``8 t`` (outwards
    while the check passes), then ``t / 2``, ... ``t / 32`` if none was; None when none is."""
    best: tuple[np.ndarray, Checked] | None = None

    def at(d: float) -> tuple[np.ndarray, Checked]:
        w = y.copy()
        w[j] = min(max(w[j] + d, lo[j]), hi[j])
        return w, value(w)

    for d in (t, 2 * t, 4 * t, 8 * t):
        if left() <= 0:
            return best
        w, vw = at(d)
        if not np.isfinite(vw[0]):
            break
        if better(vw, best[1] if best else vz):
            best = (w, vw)
    for d in () if best is not None else (t / 2, t / 4, t / 8, t / 16, t / 32):
        if left() <= 0:
            break
        w, vw = at(d)
        if better(vw, vz):
            return w, vw
    return best


def _gain_bound(spec: Spec) -> Callable[[np.ndarray], np.ndarray] | None:
    """The controller's gain bound for the delay points of the grid (None when its type has none)."""
    try:
        return controller_gain_bound(parametrize(spec.controller.type, spec.controller.all_bounds()))
    except (SynthError, KeyError):  # a free PID filter or lead-lag pole: no linear parametrization
        return None
