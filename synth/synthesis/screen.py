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

import numpy as np

from synth.controllers import Controller
from synth.loop_batch import LoopBatch
from synth.spec import Spec

__all__ = ["SCREEN_ITERATIONS", "SCREEN_POINTS", "screen_points", "screen_starts"]

SCREEN_POINTS = 384
"""Controllers drawn by the screen."""

SCREEN_ITERATIONS = 300
"""IPOPT iterations per round of a polish from a screened start (a start far from any optimum must not cost
a minute: the polish from the convex answer keeps the full limit)."""


def screen_points(spec: Spec, n: int = SCREEN_POINTS) -> list[Controller]:
    """``n`` controllers drawn over the spec's parameter box (seeded by the box itself).

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "pi", "plant": {"tf": "1/(s+1)"}, "requirements": [{"type": "bandwidth",
    ...                    "min": 1.0}], "controller": {"type": "PI", "bounds": {"kp": [0, 10], "ki": [0, 5]}}})
    >>> points = screen_points(spec, 8)
    >>> len(points), all(0 <= c.parameters["kp"] <= 10 and 0 <= c.parameters["ki"] <= 5 for c in points)
    (8, True)
    """
    bounds = spec.controller.all_bounds()
    names = sorted(bounds)
    rng = np.random.default_rng(zlib.crc32(repr([(k, bounds[k]) for k in names]).encode()))
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
    kind = spec.controller.type
    return [Controller(kind, {k: float(columns[k][i]) for k in names}) for i in range(n)]


def screen_starts(spec: Spec, keep: int = 3, n: int = SCREEN_POINTS) -> list[Controller]:
    """The ``keep`` stable controllers of :func:`screen_points` with the largest worst slack (feasible ones
    first), best first; fewer when fewer are stable on every plant.

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
    controllers = screen_points(spec, n)
    worst = np.full(len(controllers), np.inf)
    first = LoopBatch(spec.plants()[0], controllers)
    for k, plant in enumerate(spec.plants()):
        batch = first if k == 0 else first.with_plant(plant)
        unstable = batch.closed_loop_unstable()
        worst = np.where(unstable, -np.inf, worst)
        for req in spec.requirements:
            with np.errstate(all="ignore"):
                slack = np.asarray(req.batch_slack(batch, 20), float)
            worst = np.fmin(worst, np.where(np.isnan(slack), -np.inf, slack))
    order = [i for i in np.argsort(-worst, kind="stable") if np.isfinite(worst[i]) or worst[i] > 0]
    return [controllers[i] for i in order[:keep]]
