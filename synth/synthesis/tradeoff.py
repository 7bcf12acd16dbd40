"""Trade-off studies: sweep one or two spec values, design at every point, find the Pareto front.

A sweep names a value in the spec by a dotted path and lists its values:

- ``requirements.bandwidth.min=40:100:13`` (13 values from 40 to 100; a
  requirement is picked by its ``label``, its ``type`` when unique, or its index),
- ``plant.delay=0,0.005,0.01`` (a list),
- ``controller.bounds.kp.1=5:20:4`` (list items by index).

Neighbouring points are warm-started from each other: the points are cut into
contiguous chunks, one per worker, and each chunk is designed in order with the
previous design as ``controller.initial``. Chunks run in a local process pool,
or on a Dask distributed cluster when a scheduler address is given.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from synth.errors import SpecError, SynthError
from synth.spec import Spec
from synth.synthesis.sweep_values import Sweep, check_distinct, item_index, set_value

__all__ = ["Sweep", "TradeoffPoint", "TradeoffResult", "design_chunk", "design_point", "mark_pareto", "non_dominated",
           "set_value", "stricter_when", "tradeoff"]

PLANT_STRICTER_WHEN = {"delay": +1}
"""Swept plant values and their direction: +1 when a larger value makes the design harder."""


def stricter_when(data: dict[str, Any], path: str) -> int:
    """+1 when a larger value at ``path`` makes the spec stricter, -1 when a smaller one does.

    A requirement's value is asked of its class (:meth:`synth.requirements.Requirement.stricter_when`);
    ``plant.delay`` grows stricter; a controller bound ``controller.bounds.P.0`` (lower) grows stricter,
    ``.1`` (upper) shrinks stricter. Anything else is a :class:`SpecError` naming the path.

    Examples
    --------
    >>> d = {"requirements": [{"type": "bandwidth", "min": 60}, {"type": "peak_sensitivity", "max_db": 6}]}
    >>> stricter_when(d, "requirements.bandwidth.min"), stricter_when(d, "requirements.1.max_db")
    (1, -1)
    >>> stricter_when(d, "plant.delay"), stricter_when(d, "controller.bounds.kp.1")
    (1, -1)
    """
    from synth.requirements import REQUIREMENT_TYPES
    from synth.requirements.base import tagged_type

    parts = path.split(".")
    where = f"--sweep {path}"
    if parts[0] == "requirements" and len(parts) >= 3:
        items = data.get("requirements", [])
        item = items[item_index(items, parts[1], ".".join(parts[:2]), "requirements")]
        cls = tagged_type(REQUIREMENT_TYPES, item)
        if cls is None:
            raise SpecError(f"requirement {parts[1]!r} has no known type", where=where)
        index = int(parts[3]) if len(parts) == 4 and parts[3].isdigit() else None
        try:
            return cls.stricter_when(parts[2], index)
        except SpecError as exc:
            raise SpecError(exc.message, where=where) from None
    if parts[0] == "plant" and len(parts) == 2 and parts[1] in PLANT_STRICTER_WHEN:
        return PLANT_STRICTER_WHEN[parts[1]]
    if parts[:2] == ["controller", "bounds"] and len(parts) == 4 and parts[3] in ("0", "1"):
        return +1 if parts[3] == "0" else -1
    raise SpecError("no known direction (stricter when larger or smaller) for this value: sweep a requirement's "
                    "value, plant.delay or controller.bounds.P.0/1", where=where)


@dataclass
class TradeoffPoint:
    """The design at one point of the sweep. ``status``: the design's (``feasible``, ``infeasible`` or
    ``undetermined``), or ``not designed`` when the point's spec or its design raised an error."""

    values: dict[str, float]
    feasible: bool
    objective: float | None
    controller: dict[str, float] | None
    binding: list[str]
    slacks: dict[str, float]
    verdict: str
    seconds: float
    pareto: bool = False
    status: str = ""

    def __post_init__(self) -> None:
        if not self.status:
            self.status = "feasible" if self.feasible else "infeasible"

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class TradeoffResult:
    """Every point of a sweep, the objective's name and sense, and how the run went."""

    spec: str
    sweeps: list[Sweep]
    objective: dict[str, Any]
    points: list[TradeoffPoint]
    scheduler: str
    workers: int
    seconds: float
    extras: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"spec": self.spec, "sweeps": [asdict(s) for s in self.sweeps], "objective": self.objective,
                "scheduler": self.scheduler, "workers": self.workers, "seconds": self.seconds,
                "points": [p.to_dict() for p in self.points], **self.extras}


BINDING_SLACK = 1e-2
"""Slack (Np, 0.09 dB) within which a requirement named at the end of a one-parameter feasible set is listed as
binding a design there: every requirement that presumes a stable loop ends where stability does, but only those
near their own bound bind it."""

ACTIVE_SLACK = 1e-3
"""Slack (Np) within which a requirement binds a design of several parameters."""


def _near(x: float, end: float) -> bool:
    """``x`` at the end of an interval, relative to their size (``kp = 3.6e-6`` is not at an end ``3e-13``)."""
    return abs(x - end) <= 1e-4 * max(abs(x), abs(end))


def _binding(design_result: Any, bounds: dict[str, tuple[float, float]] | None = None) -> list[str]:
    """What holds a point's design where it is: the requirements at their bounds and the parameters at theirs."""
    if not design_result.feasible:
        diag = design_result.extras.get("diagnosis")
        if diag:
            return list(diag.get("conflicting", []))
        gs = design_result.gain_set
        return gs.never_met() + [n for pair in gs.conflicts() for n in pair] if gs is not None else []
    slack = {r.label: r.slack for r in design_result.check.requirements[1:]}
    gs = design_result.gain_set
    if gs is not None:
        x = design_result.controller.parameters[gs.parameter]
        for iv in gs.intervals:
            if iv.lo <= x <= iv.hi:
                ends = (iv.hi_binding if _near(x, iv.hi) else []) + (iv.lo_binding if _near(x, iv.lo) else [])
                return [n for n in ends if slack.get(n, 0.0) <= BINDING_SLACK]
    active = [name for name, s in slack.items() if s <= ACTIVE_SLACK]
    for name, (lo, hi) in (bounds or {}).items():
        x = design_result.controller.parameters.get(name)
        if x is not None and lo < hi:
            if _near(x, lo):
                active.append(f"bounds ({name} >= {lo:.6g})")
            elif _near(x, hi):
                active.append(f"bounds ({name} <= {hi:.6g})")
    return active


def design_point(data: dict[str, Any], sweeps: list[Sweep], values: tuple[float, ...],
                 initial: dict[str, float] | None) -> TradeoffPoint:
    """Design one point (used by workers; module level so it can be pickled)."""
    from synth.design import design

    t0 = time.perf_counter()
    point = _point(data, sweeps, values)
    if initial is not None:
        point["controller"] = {**point["controller"], "initial": initial}
    labels = {sw.path: v for sw, v in zip(sweeps, values)}
    try:
        spec = Spec.model_validate_json(json.dumps(point), strict=True)
        result = design(spec)
    except SynthError as exc:
        return TradeoffPoint(labels, False, None, None, [], {}, f"not designed: {exc}", time.perf_counter() - t0,
                             status="not designed")
    except Exception as exc:
        return TradeoffPoint(labels, False, None, None, [], {}, f"not designed: {exc}".splitlines()[0],
                             time.perf_counter() - t0, status="not designed")
    shown = result.check or result.compromise
    slacks = {r.label: r.slack for r in shown.requirements} if shown else {}
    controller = result.controller.parameters if result.controller else None
    objective = result.objective["value"] if result.objective else None
    return TradeoffPoint(labels, result.feasible, objective, controller, _binding(result, spec.controller.bounds),
                         slacks, result.verdict, time.perf_counter() - t0, status=result.status)


def _point(data: dict[str, Any], sweeps: list[Sweep], values: tuple[float, ...]) -> dict[str, Any]:
    """The spec's data with each swept value set."""
    point = dict(data)
    for sw, v in zip(sweeps, values):
        point = set_value(point, sw.path, v)
    return point


def _validated(data: dict[str, Any], sweeps: list[Sweep], values: tuple[float, ...]) -> None:
    """Raise the spec's own one-line error (:func:`synth.spec.messages.spec_error`) where the point is not a valid
    spec, named by its swept values (``plant.delay: must be >= 0.0, got -0.1``)."""
    from pydantic import ValidationError

    from synth.spec.messages import spec_error

    point = _point(data, sweeps, values)
    try:
        Spec.model_validate_json(json.dumps(point), strict=True)
    except ValidationError as exc:
        label = ", ".join(f"{sw.path}={v:g}" for sw, v in zip(sweeps, values))
        raise spec_error(exc, f"--sweep {label}", None, point) from None


def design_chunk(data: dict[str, Any], sweeps: list[Sweep], chunk: list[tuple[float, ...]]) -> list[TradeoffPoint]:
    """Design a contiguous run of points, each warm-started from the previous feasible design."""
    out = []
    initial = None
    for values in chunk:
        point = design_point(data, sweeps, values, initial)
        if point.feasible and point.controller is not None:
            initial = point.controller
        out.append(point)
    return out


@dataclass(frozen=True)
class _ChunkJob:
    """:func:`design_chunk` of one spec and its sweeps, called with a chunk (a job of :func:`map_jobs`)."""

    data: dict[str, Any]
    sweeps: list[Sweep]

    def __call__(self, chunk: list[tuple[float, ...]]) -> list[TradeoffPoint]:
        return design_chunk(self.data, self.sweeps, chunk)


def _grid(sweeps: list[Sweep]) -> list[tuple[float, ...]]:
    if len(sweeps) == 1:
        return [(v,) for v in sweeps[0].values]
    a, b = sweeps
    rows = []
    for i, va in enumerate(a.values):  # serpentine order keeps neighbours adjacent for warm starts
        vb = b.values if i % 2 == 0 else list(reversed(b.values))
        rows += [(va, x) for x in vb]
    return rows


def _chunks(points: list, n: int) -> list[list]:
    n = max(1, min(n, len(points)))
    return [list(c) for c in np.array_split(np.array(points, dtype=object), n) if len(c)]


def non_dominated(demands: np.ndarray, objective: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """Mask of the points no other point beats: at least as strict on every demand and at least as good on
    the objective, strictly better on one of them (all columns oriented so that larger is stricter/better).

    Objectives within ``tol`` of each other tie (solver noise must not decide the front).

    Parameters
    ----------
    demands : array of shape (n, k)
        The swept values, each multiplied by its direction (+1 stricter when larger, -1 when smaller).
    objective : array of shape (n,)
        The objective, multiplied by +1 (maximize) or -1 (minimize).
    tol : float
        Tie tolerance of the objective.

    Returns
    -------
    numpy.ndarray of bool

    Examples
    --------
    >>> d = np.array([[1.0, 1.0], [2.0, 1.0], [1.0, 2.0], [2.0, 2.0], [3.0, 0.0]])
    >>> non_dominated(d, np.array([5.0, 4.0, 4.0, 1.0, 0.0])).tolist()
    [True, True, True, True, True]
    >>> non_dominated(d, np.array([5.0, 5.0, 4.0, 4.0, 0.0])).tolist()
    [False, True, False, True, True]
    """
    X = np.asarray(demands, float).reshape(len(objective), -1)
    y = np.asarray(objective, float)
    ge = np.all(X[:, None, :] >= X[None, :, :], axis=2) & (y[:, None] >= y[None, :] - tol)  # [q, p]: q >= p
    gt = np.any(X[:, None, :] > X[None, :, :], axis=2) | (y[:, None] > y[None, :] + tol)
    return ~np.any(ge & gt, axis=0)


def mark_pareto(points: list[TradeoffPoint], sweeps: list[Sweep], sense: str,
                sign_x: int | Sequence[int] = +1) -> None:
    """Flag feasible points that no other feasible point beats on the swept demands and the objective.

    With two sweeps the front is the non-dominated set over both swept values and the objective
    (:func:`non_dominated`). ``sign_x`` gives each sweep's direction, +1 when a larger swept value is the
    stricter demand, -1 when a smaller one is (:func:`stricter_when`); one int applies to every sweep.

    Examples
    --------
    >>> pts = [TradeoffPoint({"a": a, "b": b}, True, a + b, None, [], {}, "", 0.0) for a in (1, 2) for b in (1, 2)]
    >>> mark_pareto(pts, [Sweep("a", [1, 2]), Sweep("b", [1, 2])], "maximize", (-1, -1))
    >>> [(p.values["a"], p.values["b"]) for p in pts if p.pareto]
    [(1, 1), (1, 2), (2, 1), (2, 2)]
    >>> mark_pareto(pts, [Sweep("a", [1, 2]), Sweep("b", [1, 2])], "maximize", (+1, +1))
    >>> [(p.values["a"], p.values["b"]) for p in pts if p.pareto]
    [(2, 2)]
    """
    signs = [int(sign_x)] * len(sweeps) if isinstance(sign_x, int) else [int(s) for s in sign_x]
    if len(signs) != len(sweeps):
        raise ValueError(f"{len(signs)} directions for {len(sweeps)} sweeps")
    sign_y = 1.0 if sense == "maximize" else -1.0
    for p in points:
        p.pareto = False
    feas = [p for p in points if p.feasible and p.objective is not None]
    if not feas:
        return
    # the tie tolerance from the finite objectives: an infinite one (no control effort at kp = 0: -inf dB) made it
    # infinite, inf - inf = nan, and no point dominated another (every point was marked)
    scale = max((abs(p.objective) for p in feas if np.isfinite(p.objective)), default=1.0) or 1.0
    demands = np.array([[s * p.values[sw.path] for s, sw in zip(signs, sweeps)] for p in feas], float)
    front = non_dominated(demands, np.array([sign_y * p.objective for p in feas]), 1e-6 * scale)
    for p, on in zip(feas, front):
        p.pareto = bool(on)


def tradeoff(spec: Spec, sweeps: list[Sweep], scheduler: str | Any | None = None, workers: int | None = None,
             progress: Callable[[int, int], None] | None = None) -> TradeoffResult:
    """Design the spec at every point of one or two sweeps.

    Parameters
    ----------
    spec : Spec
    sweeps : list of Sweep
        One or two swept values.
    scheduler : str, dask Client, or None
        A Dask scheduler address (``"tcp://host:8786"``) or client; None runs a local process pool.
    workers : int, optional
        Local processes (default: the number of CPUs); ignored with Dask.
    progress : callable, optional
        Called as ``progress(0, total)`` once the sweep is validated, then ``progress(done, total)`` after every
        finished chunk.

    Returns
    -------
    TradeoffResult

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> r = tradeoff(load_spec("specs/x4_rotor.yaml"), [Sweep.parse("requirements.bandwidth.min=60:80:2")], workers=1)
    >>> [(p.values["requirements.bandwidth.min"], p.feasible) for p in r.points]
    [(60.0, True), (80.0, True)]
    """
    if not 1 <= len(sweeps) <= 2:
        raise SpecError("give one or two sweeps", where="--sweep")
    data = spec.model_dump(mode="json", exclude_none=True)
    for sw in sweeps:  # fail early on a bad path
        set_value(data, sw.path, sw.values[0])
    check_distinct(data, sweeps)
    if len(sweeps) == 1:  # a one-value sweep needs its direction: fail early
        signs = [stricter_when(data, sweeps[0].path)]
    else:
        try:
            signs = [stricter_when(data, sw.path) for sw in sweeps]
        except SpecError:  # a map over any two values still designs; it just has no front
            signs = []
    grid = _grid(sweeps)
    for values in grid:  # a swept value the spec forbids is bad input, said before any design, not a row
        _validated(data, sweeps, values)
    if progress:  # the sweep is valid: the designs start
        progress(0, len(grid))
    t0 = time.perf_counter()
    results: list[TradeoffPoint] = []
    if scheduler is not None:
        client, label, n = _dask_client(scheduler)
        chunks = _chunks(grid, n)
        futures = [client.submit(design_chunk, data, sweeps, c, pure=False) for c in chunks]
        from distributed import as_completed as dask_completed

        done = 0
        for fut in dask_completed(futures):
            results += fut.result()
            done += len(fut.result())
            if progress:
                progress(done, len(grid))
    else:
        n = workers or os.cpu_count() or 1
        chunks = _chunks(grid, n)
        label = f"local process pool ({min(n, len(chunks))} workers)"
        if n == 1 or len(chunks) == 1:
            for c in chunks:
                results += design_chunk(data, sweeps, c)
                if progress:
                    progress(len(results), len(grid))
        else:
            from synth.worker_pool import map_jobs

            # workers that die with this process and stop at once on an interruption (a SIGTERM left the
            # executor's workers running; a Ctrl-C waited for the chunks being designed)
            finished = [0]

            def chunk_done(i: int) -> None:
                finished[0] += len(chunks[i])
                if progress:
                    progress(finished[0], len(grid))

            for part in map_jobs(_ChunkJob(data, sweeps), chunks, min(n, len(chunks)), done=chunk_done):
                results += part
    order = {values: i for i, values in enumerate(grid)}
    results.sort(key=lambda p: order[tuple(p.values[s.path] for s in sweeps)])
    if len(sweeps) == 2:  # back to row-major order for tables
        results.sort(key=lambda p: (p.values[sweeps[0].path], p.values[sweeps[1].path]))
    objective = {"name": spec.objective.name, "sense": spec.objective.sense,
                 "description": spec.objective.describe()} if spec.objective else {
        "name": "default", "sense": "maximize", "description": "no objective in the spec"}
    extras: dict[str, Any] = {}
    if signs:
        mark_pareto(results, sweeps, objective["sense"], signs)
        extras["stricter_when"] = {sw.path: s for sw, s in zip(sweeps, signs)}
    else:
        extras["pareto_note"] = "no Pareto front: a swept value has no known direction (stricter when larger or smaller)"
    return TradeoffResult(spec.name, sweeps, objective, results, label, len(chunks),
                          time.perf_counter() - t0, extras)


def _dask_client(scheduler: Any) -> tuple[Any, str, int]:
    try:
        from distributed import Client
    except ImportError:
        raise SynthError("--scheduler needs dask.distributed: pip install 'synth[dask]'", where="--scheduler") from None
    if isinstance(scheduler, str):
        try:
            client = Client(scheduler, timeout=os.environ.get("SYNTH_DASK_CONNECT_TIMEOUT", "10s"))
        except (OSError, ValueError, TypeError) as exc:  # ValueError: an address without a port
            raise SynthError(f"cannot reach the Dask scheduler: {exc}", where=f"--scheduler {scheduler}") from None
    else:
        client = scheduler
    n = max(1, sum(client.nthreads().values()))
    return client, f"dask cluster at {client.scheduler.address} ({n} threads)", n
