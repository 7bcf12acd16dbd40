"""Exact feasible set of one scalar controller parameter (e.g. the gain K of a P controller).

Every requirement's slack is a continuous function of the parameter. Its sign
changes are bracketed on a grid and each boundary is then found by root
finding (Brent) to ``1e-10`` relative, so the interval ends do not depend on
the grid. The bracketing grid is evaluated vectorized (every plant x frequency
x value at once, :meth:`~synth.requirements.base.Requirement.batch_slack`);
the points next to a sign change, and those whose vectorized slack is within
:data:`EXACT_BAND` of zero, are re-evaluated one by one with the exact scalar
slack, which the root finding then uses alone. Closed-loop stability is handled exactly: when the controller is
affine in the parameter the stability boundaries come from the
D-decomposition (every value at which a closed-loop root crosses the
imaginary axis, delay included).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant
from synth.requirements.base import Requirement, unique_names
from synth.stability import stability_floor
from synth.stability_sets import affine_stability_intervals
from synth.synthesis.intervals import intersect, remove, union

__all__ = [
    "EXACT_BAND",
    "GainInterval",
    "GainSet",
    "ScalarFamily",
    "SlackBatch",
    "critical_gains",
    "feasible_gain_set",
    "requirement_set",
    "stability_set",
]

_MET_TOL = 1e-12

EXACT_BAND = 1e-4
"""Vectorized slacks within this distance of zero (Np or rad) are re-evaluated by the exact scalar slack
before the sign is trusted (the vectorized and scalar slacks agree to about 1e-7)."""


@dataclass
class GainInterval:
    """One interval of feasible parameter values, with what binds at each end."""

    lo: float
    hi: float
    lo_binding: list[str]
    hi_binding: list[str]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"lo": self.lo, "hi": self.hi, "lo_binding": self.lo_binding, "hi_binding": self.hi_binding}


@dataclass
class GainSet:
    """Feasible values of one controller parameter.

    Attributes
    ----------
    parameter : str
        Name of the free parameter (``"kp"``).
    bounds : tuple
        Search range from the spec.
    intervals : list of GainInterval
        Values meeting every requirement and keeping the loop stable.
    per_requirement : dict
        For each requirement (and ``"stability"``), the intervals where it alone holds.
    outside_bounds : dict
        For requirements never met within the bounds: where they would be met in
        a range ten times wider (empty list if nowhere).
    """

    parameter: str
    bounds: tuple[float, float]
    intervals: list[GainInterval]
    per_requirement: dict[str, list[tuple[float, float]]]
    outside_bounds: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    method: str = ("root bracketing on each requirement's slack (Brent, 1e-10 relative); "
                   "stability boundaries by D-decomposition with the exact delay")

    def as_list(self) -> list[list[float]]:
        """``[[lo, hi], ...]``.

        Examples
        --------
        >>> GainSet("kp", (0, 1), [GainInterval(0.2, 0.5, ["a"], ["b"])], {}).as_list()
        [[0.2, 0.5]]
        """
        return [[iv.lo, iv.hi] for iv in self.intervals]

    def contains(self, value: float) -> bool:
        """Whether ``value`` lies in one of the intervals.

        Examples
        --------
        >>> GainSet("kp", (0, 1), [GainInterval(0.2, 0.5, [], [])], {}).contains(0.3)
        True
        """
        return any(iv.lo <= value <= iv.hi for iv in self.intervals)

    def conflicts(self) -> list[tuple[str, str]]:
        """Pairs of requirements whose individual feasible sets do not overlap."""
        names = list(self.per_requirement)
        out = []
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                if self.per_requirement[a] and self.per_requirement[b] and not intersect(
                    self.per_requirement[a], self.per_requirement[b]
                ):
                    out.append((a, b))
        return out

    def never_met(self) -> list[str]:
        """Requirements met by no value within the bounds."""
        return [k for k, v in self.per_requirement.items() if not v]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            "parameter": self.parameter,
            "bounds": list(self.bounds),
            "intervals": [iv.to_dict() for iv in self.intervals],
            "per_requirement": {k: [list(i) for i in v] for k, v in self.per_requirement.items()},
            "outside_bounds": {k: [list(i) for i in v] for k, v in self.outside_bounds.items()},
            "conflicts": [list(c) for c in self.conflicts()],
            "never_met": self.never_met(),
            "method": self.method,
        }


class ScalarFamily:
    """Controllers of one type where one parameter varies and the others are fixed."""

    def __init__(self, ctype: str, parameter: str, fixed: dict[str, float]) -> None:
        self.ctype, self.parameter, self.fixed = ctype, parameter, dict(fixed)

    def controller(self, value: float) -> Controller:
        """The controller at ``parameter = value``."""
        return Controller(self.ctype, {**self.fixed, self.parameter: float(value)})

    def affine_parts(self, lo: float, hi: float):
        """``(C0, C1)`` with ``C = C0 + rho C1`` if the controller is affine in the parameter, else None."""
        # three points inside (lo, hi), none at a round fraction: at a zero gain the transfer function's form
        # can differ (PI with ki = 0 is kp / 1 for kp > 0 but 0 / s at kp = 0), which would hide an affine family
        pts = lo + (hi - lo) * np.array([0.2871, 0.6213, 0.9137]) if hi > lo else np.array([lo, lo + 1.0, lo + 2.0])
        try:
            tfs = [self.controller(p).tf() for p in pts]
        except Exception:
            return None
        width = max(max(n.size, d.size) for n, d in tfs)
        nums = [np.pad(n, (width - n.size, 0)) for n, _ in tfs]
        dens = [np.pad(d, (width - d.size, 0)) for _, d in tfs]
        if not (np.allclose(dens[0], dens[1]) and np.allclose(dens[0], dens[2])):
            return None
        slope = (nums[1] - nums[0]) / (pts[1] - pts[0])
        base = nums[0] - pts[0] * slope
        if not np.allclose(base + pts[2] * slope, nums[2], rtol=1e-9, atol=1e-12):
            return None
        # each part with its common factors s cancelled: a PI with ki = 0 is kp s / s, whose s is no pole
        return cancel_origin(base, dens[0]), cancel_origin(slope, dens[0])


def cancel_origin(num: np.ndarray, den: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``num / den`` (highest power first) with the factors ``s`` common to both cancelled (leading zeros
    trimmed; a zero numerator is ``[0.0]``).

    Examples
    --------
    >>> [a.tolist() for a in cancel_origin(np.array([1.0, 0.0]), np.array([1.0, 0.0]))]  # s / s
    [[1.0], [1.0]]
    >>> [a.tolist() for a in cancel_origin(np.array([0.0, 2.0]), np.array([1.0, 0.0]))]  # 2 / s stays
    [[2.0], [1.0, 0.0]]
    """
    num, den = np.trim_zeros(np.asarray(num, float), "f"), np.trim_zeros(np.asarray(den, float), "f")
    num = num if num.size else np.array([0.0])
    while num.size > 1 and den.size > 1 and num[-1] == 0.0 and den[-1] == 0.0:
        num, den = num[:-1], den[:-1]
    return num, den


def stability_set(family: ScalarFamily, plants: list[Plant], lo: float, hi: float) -> list[tuple[float, float]]:
    """Values in ``[lo, hi]`` that keep the closed loop stable on every plant."""
    parts = family.affine_parts(lo, hi)
    total: list[tuple[float, float]] | None = None
    for plant in plants:
        if parts is not None:
            c0, c1 = parts
            c0 = None if not np.any(c0[0]) else c0
            ivs = [(iv.lo, iv.hi) for iv in affine_stability_intervals(
                c0, c1, plant.num, plant.den, plant.delay, lo, hi, floor=stability_floor(plant.num, plant.den, plant.delay))]
        else:
            ivs = _boolean_set(lambda v, p=plant: Loop(p, family.controller(v)).stability().stable, lo, hi)
        total = ivs if total is None else intersect(total, ivs)
    return total or []


def _grid(lo: float, hi: float, n: int) -> np.ndarray:
    pts = [np.linspace(lo, hi, n)]
    if lo >= 0 and hi > 0:
        pts.append(np.geomspace(max(lo, hi * 1e-4), hi, n // 2))
    return np.unique(np.concatenate(pts))


def _boolean_set(ok: Callable[[float], bool], lo: float, hi: float, n: int = 121) -> list[tuple[float, float]]:
    grid = _grid(lo, hi, n)
    flags = [ok(v) for v in grid]
    return _assemble(grid, flags, lambda a, b, fa: _bisect_flag(ok, a, b, fa))


def _bisect_flag(ok: Callable[[float], bool], a: float, b: float, fa: bool) -> float:
    for _ in range(60):
        m = 0.5 * (a + b)
        if ok(m) == fa:
            a = m
        else:
            b = m
        if b - a <= 1e-12 * max(1.0, abs(b)):
            break
    return 0.5 * (a + b)


def _assemble(grid: np.ndarray, flags: list[bool], root: Callable[[float, float, bool], float]):
    out: list[tuple[float, float]] = []
    start = grid[0] if flags[0] else None
    for i in range(1, grid.size):
        if flags[i] != flags[i - 1]:
            x = root(grid[i - 1], grid[i], flags[i - 1])
            if flags[i]:
                start = x
            else:
                out.append((start, x))
                start = None
    if start is not None:
        out.append((start, grid[-1]))
    return out


def requirement_set(slack: Callable[[float], float], lo: float, hi: float,
                    n: int = 121, batch: Callable[[np.ndarray], np.ndarray] | None = None,
                    ) -> list[tuple[float, float]]:
    """Intervals of ``[lo, hi]`` where ``slack(v) >= 0``: bracketed on a grid, refined by Brent.

    ``batch`` (optional) gives approximate slacks at many values at once; the grid is then evaluated
    by it and only the points next to a sign change or within :data:`EXACT_BAND` of zero by ``slack``
    (repeated until every sign change lies between exactly evaluated points), so the result is the same
    as with ``slack`` alone.

    Examples
    --------
    >>> slack = lambda k: np.log(2.5 / k) if k > 0 else np.inf  # met for k <= 2.5
    >>> [(float(a), float(b)) for a, b in requirement_set(slack, 0.0, 10.0)]
    [(0.0, 2.5)]
    >>> fast = lambda ks: np.log(2.5 / np.maximum(ks, 1e-300))
    >>> [(float(a), float(b)) for a, b in requirement_set(slack, 0.0, 10.0, batch=fast)]
    [(0.0, 2.5)]
    """
    from scipy.optimize import brentq

    grid = _grid(lo, hi, n)
    values = _grid_values(slack, grid, batch)
    flags = list(values >= -_MET_TOL)
    known = {float(v): float(x) for v, x in zip(grid, values)}

    def exact(v: float) -> float:
        return known[v] if v in known else slack(v)

    def root(a: float, b: float, fa: bool) -> float:
        sa, sb = exact(a), exact(b)
        if np.isfinite(sa) and np.isfinite(sb):
            return float(brentq(lambda v: slack(v) + _MET_TOL, a, b, xtol=1e-12, rtol=1e-10))
        return _bisect_flag(lambda v: slack(v) >= -_MET_TOL, a, b, fa)

    return _assemble(grid, flags, root)


def _grid_values(slack: Callable[[float], float], grid: np.ndarray,
                 batch: Callable[[np.ndarray], np.ndarray] | None) -> np.ndarray:
    """Slack on the grid: exact everywhere (no ``batch``), or vectorized with exact values where the sign
    matters (near zero, unknown, or on either side of a sign change)."""
    if batch is None:
        return np.array([slack(v) for v in grid], dtype=float)
    values = np.array(batch(grid), dtype=float)
    done = np.zeros(grid.size, bool)
    need = np.isnan(values) | (np.abs(values) <= EXACT_BAND)
    while True:
        flags = values >= -_MET_TOL
        change = np.flatnonzero(flags[1:] != flags[:-1])
        need[change] = True
        need[change + 1] = True
        need &= ~done
        if not need.any():
            return values
        for i in np.flatnonzero(need):
            values[i] = slack(float(grid[i]))
        done |= need
        need[:] = False


class SlackBatch:
    """Vectorized slacks of requirements over many values of a family's parameter, the worst over
    the plants (one :class:`~synth.loop.LoopBatch` per plant and set of values, shared by the
    requirements).

    Examples
    --------
    >>> from synth.requirements import Bandwidth
    >>> from synth.plant import Plant
    >>> sb = SlackBatch(ScalarFamily("P", "kp", {}), [Plant.from_string("1/(s+1)")])
    >>> sb.slack(Bandwidth(min=100), np.array([9.0, 200.0])).round(3)
    array([-2.305,  0.696])
    """

    def __init__(self, family: ScalarFamily, plants: list[Plant], per_decade: int = 80) -> None:
        self.family, self.plants, self.per_decade = family, plants, per_decade
        self._batches: dict[bytes, list[LoopBatch]] = {}

    def batches(self, values: np.ndarray) -> list[LoopBatch]:
        """One :class:`~synth.loop.LoopBatch` per plant for the controllers at ``values`` (cached)."""
        values = np.asarray(values, dtype=float)
        key = values.tobytes()
        if key not in self._batches:
            first = LoopBatch(self.plants[0], [self.family.controller(v) for v in values])
            self._batches[key] = [first] + [first.with_plant(p) for p in self.plants[1:]]
        return self._batches[key]

    def slack(self, requirement: Requirement, values: np.ndarray) -> np.ndarray:
        """Worst slack over the plants of ``requirement`` at every value."""
        out = [requirement.batch_slack(b, self.per_decade) for b in self.batches(values)]
        return np.min(np.array(out), axis=0)


def feasible_gain_set(
    requirements: list[Requirement],
    plants: list[Plant],
    family: ScalarFamily,
    bounds: tuple[float, float],
    n_bracket: int = 121,
    vectorized: bool = True,
) -> GainSet:
    """All values of the family's parameter within ``bounds`` meeting every requirement on every plant.

    Parameters
    ----------
    requirements : list of Requirement
    plants : list of Plant
    family : ScalarFamily
        The controller type, the varying parameter and the fixed ones.
    bounds : (lo, hi)
    n_bracket : int
        Points of the bracketing grid (the ends are then refined by root finding).
    vectorized : bool
        Evaluate the bracketing grid vectorized (:class:`SlackBatch`; the default) or one value at a
        time with the exact scalar slack (same result, slower).

    Returns
    -------
    GainSet

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> gs = feasible_gain_set(list(spec.requirements), spec.plants(), ScalarFamily("P", "kp", {}), (0, 20))
    >>> [[round(a, 4), round(b, 4)] for a, b in gs.as_list()], gs.intervals[0].lo_binding
    ([[2.5686, 20.0]], ['sensitivity_static'])
    """
    lo, hi = float(bounds[0]), float(bounds[1])
    names = unique_names(requirements)
    sets: dict[str, list[tuple[float, float]]] = {"stability": stability_set(family, plants, lo, hi)}

    def slack_fn(req: Requirement) -> Callable[[float], float]:
        def f(v: float) -> float:
            c = family.controller(v)
            return min(req.slack(Loop(p, c)) for p in plants)
        return f

    narrow = _under_resolved(sets["stability"], lo, hi, n_bracket)
    fast = SlackBatch(family, plants)
    slack_fns = {}
    batch_fns = {}
    for name, req in zip(names, requirements):
        slack_fns[name] = slack_fn(req)
        batch_fns[name] = (lambda values, r=req: fast.slack(r, values)) if vectorized else None
        sets[name] = requirement_set(slack_fns[name], lo, hi, n_bracket, batch_fns[name])
        for a, b in narrow:  # the feasible set lies inside the stabilizing set: resolve the requirement there
            sets[name] = union(remove(sets[name], a, b), requirement_set(slack_fns[name], a, b, n_bracket,
                                                                         batch_fns[name]))

    total: list[tuple[float, float]] = [(lo, hi)]
    for ivs in sets.values():
        total = intersect(total, ivs)
    intervals = []
    for a, b in total:
        intervals.append(GainInterval(a, b, _binding(a, sets, lo, hi, slack_fns, family, batch_fns),
                                      _binding(b, sets, lo, hi, slack_fns, family, batch_fns)))
    outside: dict[str, list[tuple[float, float]]] = {}
    for name in names:
        if not sets[name]:
            wide_lo = lo if lo <= 0 else lo / 10.0
            outside[name] = requirement_set(slack_fns[name], wide_lo, hi * 10 if hi > 0 else hi + 10, n_bracket,
                                            batch_fns[name])
    return GainSet(family.parameter, (lo, hi), intervals, sets, outside)


MIN_POINTS_INSIDE = 20
"""Bracketing points a stabilizing interval must hold for the requirement grid over the whole range to be
trusted there; a narrower one is bracketed on a grid of its own."""


def _under_resolved(stable: list[tuple[float, float]], lo: float, hi: float, n: int) -> list[tuple[float, float]]:
    """The stabilizing intervals that the bracketing grid over ``[lo, hi]`` (``n`` points) resolves with fewer
    than :data:`MIN_POINTS_INSIDE` points (a stabilizing interval of 1e-5 of the range holds none): each
    requirement is bracketed again on a grid of its own there."""
    grid = _grid(lo, hi, n)
    return [(a, b) for a, b in stable if b > a and np.count_nonzero((grid > a) & (grid < b)) < MIN_POINTS_INSIDE]


def _binding(x: float, sets: dict[str, list[tuple[float, float]]], lo: float, hi: float,
             slack_fns: dict[str, Callable[[float], float]], family: ScalarFamily,
             batch_fns: dict[str, Callable[[np.ndarray], np.ndarray] | None]) -> list[str]:
    tol = 1e-9 * max(1.0, abs(x))
    out = []
    for name, ivs in sets.items():
        if any((abs(x - a) <= tol and a != lo) or (abs(x - b) <= tol and b != hi) for a, b in ivs):
            out.append(name)
    for name, f in slack_fns.items():
        fast = batch_fns.get(name)
        if fast is not None and abs(float(fast(np.array([x]))[0])) > EXACT_BAND:
            continue  # far from zero: the exact slack cannot be within 1e-9 of it
        if name not in out and abs(f(x)) <= 1e-9:
            out.append(name)  # active exactly at the end (e.g. the bound coincides with it)
    if abs(x - lo) <= tol or abs(x - hi) <= tol:
        at_lo = abs(x - lo) <= tol
        out.append(f"bounds ({family.parameter} {'>=' if at_lo else '<='} {(lo if at_lo else hi) + 0.0:.6g})")
    return out


def critical_gains(plant: Plant, delays: list[float], k_max: float = 1e3) -> list[dict[str, float | None]]:
    """The lowest stabilizing range of a proportional gain, for each in-loop delay: ``critical_gain``, where the loop
    turns unstable (and ``frequency``, where it oscillates then), and ``lowest_gain``, where that range starts (0
    for a plant the smallest gains keep stable; above 0 for an open-loop unstable one, whose small gains leave it
    unstable; ``critical_gain`` 0 where no gain up to ``k_max`` stabilizes).

    Examples
    --------
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
    >>> [round(r["critical_gain"], 2) for r in critical_gains(G, [0.015, 0.02])]
    [4.83, 3.69]
    >>> r = critical_gains(Plant.from_string("10/((s-1)*(s+5))"), [0.02])[0]  # unstable below 0.5
    >>> round(r["lowest_gain"], 3), round(r["critical_gain"], 2)
    (0.5, 20.26)
    """
    out = []
    one = (np.array([1.0]), np.array([1.0]))
    for d in delays:
        p = plant.with_delay(plant.delay + d) if d else plant
        ivs = affine_stability_intervals(None, one, p.num, p.den, p.delay, 0.0, k_max, first_only=True)
        first = next((iv for iv in ivs if iv.lo <= 1e-12), None)
        lowest = 0.0
        if first is None:  # small gains leave the loop unstable: the first range of gains that stabilizes
            first = next(iter(affine_stability_intervals(None, one, p.num, p.den, p.delay, 0.0, k_max)), None)
            lowest = float(first.lo) if first is not None else 0.0
        if first is None:
            crit, w = 0.0, None
        elif first.hi_is_boundary:
            crit, w = first.hi, first.hi_frequency
        else:
            crit, w = float("inf"), None
        out.append({"delay": float(d), "critical_gain": float(crit), "frequency": w, "lowest_gain": lowest})
    return out
