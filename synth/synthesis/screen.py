"""Starting points for the NLP from a seeded random screen of the parameter box.

The convex-concave stage is local: from its starts it can stall at a tiny controller while a feasible one
lies elsewhere in the bounds (a rational controller whose feasible set is a thin region, a PID on an
unstable plant). When no design it produced passes the certificate, the screen draws controllers over the
whole box (half uniform, half log-uniform over six decades below each positive upper bound), evaluates every
requirement on every plant for all of them at once (:class:`synth.loop_batch.LoopBatch`, exact closed-loop
stability by count), and hands the least-violating stable ones to the NLP polish as starts. The draw is
seeded by the spec's parameter box, so a design is reproducible.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable

import numpy as np

from synth.batch_bandwidth import batch_bandwidths
from synth.controllers import Controller
from synth.loop_batch import LoopBatch
from synth.spec import Spec
from synth.synthesis.screen_sizes import (
    MANY_FROM_PARAMETERS,
    SCREEN_POINTS,
    SCREEN_POINTS_MANY,
    near_screen_size,
    screen_size,
)
from synth.synthesis.start_spread import apart

__all__ = ["MANY_FROM_PARAMETERS", "NEAR_POOL", "PARAMETER_MEASURES", "SCREEN_ITERATIONS", "SCREEN_POINTS",
           "SCREEN_POINTS_MANY", "near_screen_size", "screen_improving", "screen_near_improving", "screen_points",
           "screen_scores", "screen_size", "screen_starts"]

STABILITY_BASED = ("margins", "delay_margin")
"""Requirement types whose batch form counts every loop's closed-loop roots (milliseconds per loop): the
improvement screen evaluates them last, on the few controllers that passed the rest and score better."""

PARAMETER_MEASURES = ("integral_gain", "low_frequency_gain")
"""Objective measures read off the controller's parameters: scored before any requirement is evaluated."""

SCREEN_ITERATIONS = 300
"""IPOPT iterations per round of a polish from a screened start (a start far from any optimum must not cost
a minute: the polish from the convex answer keeps the full limit)."""


def screen_points(spec: Spec, n: int | None = None) -> list[Controller]:
    """``n`` controllers drawn over the spec's parameter box (seeded by the box itself), then ``n // 3`` copies
    of the first ones with a random half of their parameters at the lower bounds and ``n // 3`` copies of the
    next ones with a random half at the upper bounds. Above :data:`SCREEN_POINTS` the draw is made in blocks of
    that size, the first one the draw of :data:`SCREEN_POINTS` itself: a larger screen holds every point of the
    smaller one (drawn first, its copies first in their groups).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "requirements": [{"type": "bandwidth",
    ...                    "min": 1.0}], "controller": {"type": "PI", "bounds": {"kp": [0, 10], "ki": [0, 5]}}})
    >>> points = screen_points(spec, 9)
    >>> len(points), all(0 <= c.parameters["kp"] <= 10 and 0 <= c.parameters["ki"] <= 5 for c in points)
    (15, True)
    >>> small, large = screen_points(spec, 384), screen_points(spec, 1536)
    >>> large[:384] == small[:384] and large[1536:1664] == small[384:512] and large[2048:2176] == small[512:]
    True
    """
    n = screen_size(spec) if n is None else n
    bounds = spec.controller.all_bounds()
    names = sorted(bounds)
    seed = zlib.crc32(repr([(k, bounds[k]) for k in names]).encode())
    sizes = [n] if n <= SCREEN_POINTS else [SCREEN_POINTS] * (n // SCREEN_POINTS) + (
        [n % SCREEN_POINTS] if n % SCREEN_POINTS else [])
    blocks = [_draw(bounds, names, size, np.random.default_rng(seed if b == 0 else [seed, b]))
              for b, size in enumerate(sizes)]
    drawn, lower, upper = ([c for block in blocks for c in block[part]] for part in range(3))
    kind = spec.controller.type
    return [Controller(kind, params) for params in drawn + lower + upper]


def _draw(bounds: dict[str, tuple[float, float]], names: list[str], n: int, rng: np.random.Generator,
          ) -> tuple[list[dict[str, float]], list[dict[str, float]], list[dict[str, float]]]:
    """One block of :func:`screen_points`: its ``n`` drawn points, the copies at lower bounds and the copies at
    upper bounds (``n // 3`` each), as parameter dicts."""
    columns = {}
    for k in names:
        lo, hi = (float(v) for v in bounds[k])
        if lo == hi:
            columns[k] = np.full(n, lo)
            continue
        uniform = rng.uniform(lo, hi, n)
        if hi > 0:
            floor = max(lo, hi * 1e-6) if lo >= 0 else hi * 1e-6
            logs = np.exp(rng.uniform(np.log(floor), np.log(hi), n))
            uniform = np.where(np.arange(n) % 2 == 1, logs, uniform)
        columns[k] = uniform
    extra = n // 3  # copies of the first points with a random half of their parameters at the lower bounds
    pinned = rng.random((extra, len(names))) < 0.5  # (a0 = 0: an integrator; ki = 0), never drawn exactly
    upper = rng.random((extra, len(names))) < 0.5  # and copies with a random half at the upper bounds (an
    # optimum in a corner of the box: the largest gain and pole a lead-lag may have)
    for j, k in enumerate(names):
        columns[k] = np.concatenate([columns[k], np.where(pinned[:, j], float(bounds[k][0]), columns[k][:extra]),
                                     np.where(upper[:, j], float(bounds[k][1]), columns[k][extra:2 * extra])])
    points = [{k: float(columns[k][i]) for k in names} for i in range(n + 2 * extra)]
    return points[:n], points[n:n + extra], points[n + extra:]


def _pick(order: list[int], n: int, keep: int, usable: Callable[[int], bool],
          key: Callable[[int], object] = lambda i: i) -> list[int]:
    """The first ``keep`` usable indices of ``order`` among the drawn points (``< n``), and the first usable
    one among each group of pinned copies (at lower bounds, ``n .. n + n // 3``; at upper bounds, after): the
    pinned points add starts, they never displace one. An index whose ``key`` (its controller's parameters)
    equals a picked one's is passed over: a copy whose draw pinned no parameter is its original again, and a
    second polish from it would repeat the first.

    Examples
    --------
    >>> _pick([0, 4, 1, 5], 4, 2, lambda i: True)
    [0, 1, 4, 5]
    >>> _pick([0, 4, 1, 5], 4, 2, lambda i: True, key=lambda i: i % 4)  # copy 4 is point 0 again, 5 is 1
    [0, 1]
    """
    picked: set[object] = set()

    def take(i: int) -> bool:
        k = key(i)
        if k in picked or not usable(i):
            return False
        picked.add(k)
        return True

    drawn = [i for i in order if i < n]
    out: list[int] = []
    for i in drawn:
        if len(out) == keep:
            break
        if take(i):
            out.append(i)
    extra = max(n // 3, 1)
    for group in range(2):
        pinned = (i for i in order if n + group * extra <= i < n + (group + 1) * extra)
        out += next(([i] for i in pinned if take(i)), [])
    return out


def _parameters(controllers: list[Controller]) -> Callable[[int], object]:
    """The key of :func:`_pick`: controller ``i``'s parameter values."""
    return lambda i: tuple(sorted(controllers[i].parameters.items()))


def screen_starts(spec: Spec, keep: int = 3, n: int | None = None) -> list[Controller]:
    """The ``keep`` stable controllers of :func:`screen_points` with the largest worst slack (feasible ones
    first), best first, and the best of each group of pinned copies; fewer when fewer are stable on every
    plant.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s-1)*(s+5))"}, "requirements": [{"type":
    ...                    "bandwidth", "min": 2.0}], "controller": {"type": "PI", "bounds": {"kp": [0, 5],
    ...                    "ki": [0, 5]}}})
    >>> from synth.check import check
    >>> check(spec, screen_starts(spec, 1)[0]).feasible
    True
    """
    n = screen_size(spec) if n is None else n
    controllers = screen_points(spec, n)
    worst = _worst_slack(controllers, np.arange(len(controllers)), list(spec.requirements), spec.plants(),
                         stable_only=True)
    order = [int(i) for i in np.argsort(-worst, kind="stable")]
    return [controllers[i] for i in _pick(order, n, keep, lambda i: bool(np.isfinite(worst[i]) or worst[i] > 0),
                                          _parameters(controllers))]


def screen_improving(spec: Spec, terms: list[tuple[str, str, float]], above: float, keep: int = 2,
                     n: int | None = None) -> list[Controller]:
    """Up to ``keep`` controllers of :func:`screen_points` (and one of each group of its pinned copies) that meet every
    requirement on the screen's grid,
    keep every closed loop stable and score above ``above`` (:func:`synth.objectives.score` on the nominal
    plant), best first: starts for the NLP where the local stages' design may be a local optimum.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))"}, "requirements": [{"type":
    ...                    "peak_sensitivity", "max_db": 6}], "controller": {"type": "PI", "bounds": {"kp": [0, 5],
    ...                    "ki": [0, 5]}}, "objective": {"maximize": "integral_gain"}})
    >>> [c.parameters["ki"] > 4.0 for c in screen_improving(spec, [("integral_gain", "maximize", 1.0)], 4.0)]
    [True, True, True]
    """
    from synth.loop import Loop

    n = screen_size(spec) if n is None else n
    controllers = screen_points(spec, n)
    plants = spec.plants()
    light = [r for r in spec.requirements if r.type not in STABILITY_BASED]
    heavy = [r for r in spec.requirements if r.type in STABILITY_BASED]
    idx = np.arange(len(controllers))
    if not all(name in PARAMETER_MEASURES for name, _, _ in terms):  # else the score is cheaper than any slack
        idx = _meeting(controllers, idx, light, plants, assume_stable=True)
    # the objective before the requirements that count closed-loop roots (the costly part), every loop at once
    values = screen_scores(spec, [controllers[i] for i in idx], terms, exact=True)
    scored = [(float(v), int(i)) for v, i in zip(values, idx) if np.isfinite(v) and v > above]
    if all(name in PARAMETER_MEASURES for name, _, _ in terms):
        idx = _meeting(controllers, np.array([i for _, i in scored], int), light, plants, assume_stable=True)
        meeting = set(idx.tolist())
        scored = [(v, i) for v, i in scored if i in meeting]
    order = [i for _, i in sorted(scored, reverse=True)]
    meets_heavy = _InScoreOrder(order, n, lambda chunk: _meeting(controllers, chunk, heavy, plants))
    return [controllers[i] for i in _pick(order, n, keep, lambda i: meets_heavy(i) and all(
        Loop(p, controllers[i]).stability().stable for p in plants), _parameters(controllers))]


NEAR_POOL = 192
"""Controllers scoring better whose closed-loop roots :func:`screen_near_improving` counts at once (the next as
many only while fewer than it picks are stable)."""


def screen_near_improving(spec: Spec, terms: list[tuple[str, str, float]], above: float, keep: int = 2,
                          n: int | None = None) -> list[Controller]:
    """Up to ``keep`` controllers of :func:`screen_points` that keep every closed loop stable and score above
    ``above`` but miss a requirement, least violating first (their worst slack over every requirement and
    plant): starts for the NLP where no screened point both meets the requirements and scores better, and
    the better designs lie in a thin feasible region that a polish reaches from just outside it. Each pick after
    the first is the least violating of those :func:`synth.synthesis.start_spread.apart` from every earlier
    pick: a second start from the same basin would end where the first did, and the better design may lie in
    another (seed 26 #41 of the design benchmark: a lead-lag's best is a lag, 4.58 dB of peak |S|, while every
    near miss close to the first was a lead, which polished to 5.43 dB). As for the screen's other starts
    (:func:`_pick`), the drawn points come first and the copies with parameters pinned at a bound only after
    them, so a pinned copy is a start only when fewer than ``keep`` drawn points qualify.

    Every point is scored at once (:func:`screen_scores`); those that score better are taken in the order of
    their worst slack on the requirements that count no closed-loop roots (every loop taken as stable); the
    first :data:`NEAR_POOL` of them have their closed-loop roots counted (in one batch: counted a few at a time,
    the batches' fixed costs outweighed the counts saved), and the next as many while fewer than ``keep`` are
    stable. The stable ones' slack on the requirements that
    count roots (margins) is evaluated in that order, a few at a time, only until no later point can rank among
    the picks (:func:`_best_bounded`: a point's worst slack is at most its slack on the other requirements):
    the same picks as evaluating every one of them (servo_pid's screen: 8 of 12 stable points).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> from synth.check import check
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)^3"}, "requirements": [{"type":
    ...                    "peak_sensitivity", "max_db": 3}], "controller": {"type": "PI", "bounds": {"kp": [0, 5],
    ...                    "ki": [0, 5]}}, "objective": {"maximize": "integral_gain"}})
    >>> terms = [("integral_gain", "maximize", 1.0)]
    >>> screen_improving(spec, terms, 0.3)  # no screened point meets |S| <= 3 dB with ki > 0.3
    []
    >>> near = screen_near_improving(spec, terms, 0.3)
    >>> [(c.parameters["ki"] > 0.3, check(spec, c).feasible) for c in near]
    [(True, False), (True, False)]
    >>> apart(near[0].parameters, near[1].parameters, spec.controller.all_bounds())
    True
    """
    n = near_screen_size(spec) if n is None else n
    controllers = screen_points(spec, n)
    plants = spec.plants()
    light = [r for r in spec.requirements if r.type not in STABILITY_BASED]
    heavy = [r for r in spec.requirements if r.type in STABILITY_BASED]
    better = np.flatnonzero(screen_scores(spec, controllers, terms) > above)
    light_worst = _worst_slack(controllers, better, light, plants, assume_stable=True)
    order = np.argsort(-light_worst, kind="stable")
    order = order[light_worst[order] > -np.inf]
    stable: list[int] = []
    for first in range(0, order.size, NEAR_POOL):  # a pool's roots in one batch; the next pool while too few
        pool = order[first:first + NEAR_POOL]  # are stable (those meeting the light requirements best may all be
        stable.extend(pool[_worst_slack(controllers, better[pool], [], plants, stable_only=True) > -np.inf])
        if len(stable) >= keep:  # unstable: seed 28 #20's first 192 of 308)
            break
    better, light_worst = better[stable], light_worst[stable]

    def heavy_slack(chunk: np.ndarray) -> np.ndarray:  # every loop of these is stable: roots not counted again
        return _worst_slack(controllers, chunk, heavy, plants, assume_stable=True)

    known: dict[int, float] = {}

    def heavy_slack_once(chunk: np.ndarray) -> np.ndarray:  # a later pick asks again for what an earlier one saw
        ask = np.array([i for i in chunk.tolist() if i not in known], int)
        if ask.size:
            known.update(zip(ask.tolist(), heavy_slack(ask).tolist()))
        return np.array([known[i] for i in chunk.tolist()], float)

    key = _parameters(controllers)
    bounds = spec.controller.all_bounds()
    extra = max(n // 3, 1)
    groups = [better < n, (better >= n) & (better < n + extra), better >= n + extra]  # drawn, pinned low, high
    picked: set[object] = set()
    out: list[int] = []

    def passed_over(i: int) -> bool:  # the same parameters as a pick, or not apart from every pick
        return key(i) in picked or any(not apart(controllers[i].parameters, controllers[j].parameters, bounds)
                                       for j in out)

    for members in groups:
        while len(out) < keep:
            got = _best_bounded(better[members], light_worst[members], heavy_slack_once, 1, passed_over)
            if not got:
                break
            picked.add(key(got[0]))
            out.append(got[0])
    return [controllers[i] for i in out]


def _best_bounded(order: np.ndarray, bound: np.ndarray, value: Callable[[np.ndarray], np.ndarray], need: int,
                  skip: Callable[[int], bool], chunk: int = 8) -> list[int]:
    """The first ``need`` indices of ``order`` (not ``skip``-ped) whose worth, the smaller of ``bound``
    (non-increasing along ``order``) and ``value``, lies in ``(-inf, 0)``, the largest first (ties: the earlier
    in ``order``): ``value`` (of an array of indices) is asked ``chunk`` at a time along ``order``, only until
    the ``need``-th best so far is at least the next bound, so no later index could displace it (the chunks
    double: a batch's cost has a fixed part).

    Examples
    --------
    >>> values = {0: -0.5, 1: -0.2, 2: -0.9, 3: -0.45}
    >>> asked = []
    >>> def value(idx):
    ...     asked.extend(idx.tolist()); return np.array([values[int(i)] for i in idx])
    >>> _best_bounded(np.arange(4), np.array([-0.1, -0.15, -0.3, -0.4]), value, 1, lambda i: False, chunk=2)
    [1]
    >>> asked  # 1's -0.2 beats any value bounded by -0.3: 2 and 3 were never evaluated
    [0, 1]
    >>> _best_bounded(np.arange(4), np.array([-0.1, -0.15, -0.3, -0.4]), value, 2, lambda i: False, chunk=1)
    [1, 3]
    """
    found: list[tuple[float, int, int]] = []  # (-value, position, index)
    start = 0
    while need > 0 and start < order.size:
        if len(found) >= need and -found[need - 1][0] >= bound[start]:
            break
        idx = order[start:start + chunk]
        worth = np.fmin(bound[start:start + idx.size], value(idx))
        for pos, (i, v) in enumerate(zip(idx, worth), start):
            if -np.inf < v < 0 and not skip(int(i)):
                found.append((-float(v), pos, int(i)))
        found.sort()
        start, chunk = start + idx.size, 2 * chunk
    return [i for _, _, i in found[:need]]


def screen_scores(spec: Spec, controllers: list[Controller], terms: list[tuple[str, str, float]],
                  exact: bool = False) -> np.ndarray:
    """Every controller's objective (:func:`synth.objectives.score` on the nominal plant, every loop taken as
    stable), the bandwidth read off one grid for all at once (:func:`_grid_bandwidths`; with ``exact``, each
    loop's ``Loop.bandwidth`` by :func:`synth.batch_bandwidth.batch_bandwidths`, also all at once), the other
    measures loop by loop (the parameter measures cost nothing); ``-inf`` where it is not a number. Without
    ``exact``, for ranking starts only: the polish and the certificate judge the designs.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "p", "plant": {"tf": "1/(s+1)"}, "requirements": [{"type": "bandwidth",
    ...                    "min": 1.0}], "controller": {"type": "P", "bounds": {"kp": [0, 10]}}})
    >>> scores = screen_scores(spec, [Controller("P", {"kp": 3.0})], [("bandwidth", "maximize", 1.0)])
    >>> bool(abs(scores[0] - 4.0) < 0.05)  # T = 3/(s+4): -3 dB at 4 rad/s
    True
    """
    from synth.loop import Loop
    from synth.objectives import measure

    nominal = spec.nominal_plant()
    total = np.zeros(len(controllers))
    for name, sense, weight in terms:
        if name == "bandwidth" and not controllers:
            continue
        if name == "bandwidth":
            with np.errstate(all="ignore"):
                batch = LoopBatch(nominal, controllers)
                value = batch_bandwidths(batch) if exact else _grid_bandwidths(batch)
        else:
            with np.errstate(all="ignore"):
                value = np.array([measure(name).evaluate(Loop(nominal, c)) for c in controllers], float)
        total += weight * (value if sense == "maximize" else -value)
    return np.where(np.isnan(total), -np.inf, total)


def _grid_bandwidths(batch: LoopBatch, per_decade: int = 20) -> np.ndarray:
    """Every loop's first fall of ``|T|`` 3 dB below ``|T(0)|`` on one log grid (``per_decade`` points, two
    decades below to one above the batch's frequency ranges), interpolated in log frequency between the grid
    points around it: ``inf`` where it does not fall, ``nan`` where ``T(0) = 0``. No dip between grid points
    counts, unlike ``Loop.bandwidth``: a ranking, not a measurement.

    Examples
    --------
    >>> from synth.plant import Plant
    >>> batch = LoopBatch(Plant.from_string("1/(s+1)"), [Controller("P", {"kp": k}) for k in (1.0, 3.0)])
    >>> [round(float(w), 1) for w in _grid_bandwidths(batch)]  # T = k/(s + 1 + k): -3 dB at 1 + k
    [2.0, 4.0]
    """
    from synth.loop import BANDWIDTH_LEVEL

    lo, hi = float(np.min(batch.frequency_ranges[:, 0])) / 100.0, float(np.max(batch.frequency_ranges[:, 1])) * 10
    grid = np.geomspace(lo, hi, max(int(np.ceil(np.log10(hi / lo) * per_decade)), 2))
    level = batch.T0() * BANDWIDTH_LEVEL
    with np.errstate(all="ignore"):
        mag = np.abs(batch.T(grid))
    below = mag < level[:, None]
    first = np.argmax(below, axis=1)
    prev = np.maximum(first - 1, 0)
    rows = np.arange(len(batch))
    a, b = mag[rows, prev], mag[rows, first]
    with np.errstate(all="ignore"):
        share = np.clip(np.where(a > b, (a - level) / (a - b), 0.0), 0.0, 1.0)
        w = np.exp(np.log(grid[prev]) + share * (np.log(grid[first]) - np.log(grid[prev])))
    w = np.where(below.any(axis=1), w, np.inf)
    return np.where(level > 0, w, np.nan)


def _worst_slack(controllers: list[Controller], idx: np.ndarray, requirements: list, plants: list,
                 assume_stable: bool = False, stable_only: bool = False) -> np.ndarray:
    """Each controller of ``idx``'s smallest slack over ``requirements`` and ``plants`` on the screen's grid
    (``-inf`` where one is not a number; ``+inf`` without requirements); ``assume_stable`` as in
    :func:`_meeting`; ``stable_only``: ``-inf`` where a closed loop is unstable (exact count)."""
    worst = np.full(idx.size, np.inf)
    if not (requirements or stable_only) or idx.size == 0:
        return worst
    first = LoopBatch(plants[0], [controllers[i] for i in idx])
    for k, plant in enumerate(plants):
        batch = first if k == 0 else first.with_plant(plant)
        if stable_only:
            worst = np.where(batch.closed_loop_unstable(), -np.inf, worst)
        if assume_stable:
            batch = batch.with_root_counts(np.zeros(idx.size, int))
        for req in requirements:
            with np.errstate(all="ignore"):
                slack = np.asarray(req.batch_slack(batch, 20), float)
            worst = np.fmin(worst, np.where(np.isnan(slack), -np.inf, slack))
    return worst


class _InScoreOrder:
    """``_meeting`` for the stability-based requirements, evaluated lazily: asked about index ``i``, it
    evaluates ``i`` and the next unevaluated indices of ``order`` in ``i``'s group (drawn or one group of
    pinned copies, as :func:`_pick` scans them), ``CHUNK`` at a time, and remembers the answers. The pick
    stops after a few usable points, so most of the costly root counts are never made."""

    CHUNK = 12

    def __init__(self, order: list[int], n: int, meeting: Callable[[np.ndarray], np.ndarray]) -> None:
        extra = max(n // 3, 1)
        self._group = lambda i: 0 if i < n else 1 + min((i - n) // extra, 1)
        self._order, self._meeting = order, meeting
        self._known: dict[int, bool] = {}

    def __call__(self, i: int) -> bool:
        if i not in self._known:
            g = self._group(i)
            start = self._order.index(i)
            chunk = [j for j in self._order[start:] if self._group(j) == g and j not in self._known][:self.CHUNK]
            passed = set(self._meeting(np.array(chunk, int)).tolist())
            self._known.update({j: j in passed for j in chunk})
        return self._known[i]


def _meeting(controllers: list[Controller], idx: np.ndarray, requirements: list, plants: list,
             assume_stable: bool = False) -> np.ndarray:
    """The indices among ``idx`` whose controllers meet every requirement on every plant on the screen's grid
    (each requirement evaluated on the survivors of the ones before). With ``assume_stable`` the closed-loop
    roots are not counted (every loop is taken as stable: a requirement an unstable loop fails only for its
    instability passes): a cheap first filter, for callers that count the roots of the survivors later."""
    for req in requirements:
        for plant in plants:
            if idx.size == 0:
                return idx
            batch = LoopBatch(plant, [controllers[i] for i in idx])
            if assume_stable:
                batch = batch.with_root_counts(np.zeros(idx.size, int))
            with np.errstate(all="ignore"):
                slack = np.asarray(req.batch_slack(batch, 20), float)
            idx = idx[slack >= 0]  # NaN: not met
    return idx
