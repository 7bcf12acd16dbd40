"""The report's feasibility map: for two free parameters, where in their plane each requirement holds.

The plane's grid is zoomed on the design; stability at each point is exact (the D-decomposition of each column);
the requirements are evaluated in bulk, and one without a vectorized form (a delayed step limit) one point at a
time, refined near its boundary (:func:`column_refined_slack`). The report computes the grid in parts, by plant or
by column, on both cores, and puts them together (:func:`combine_grids`, :func:`join_columns`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from synth.figure_files import save_figure
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.report.figures import COLORS
from synth.requirements.margins import UNSTABLE_SLACK

__all__ = ["MAP_GRID", "MAP_GRID_SCALAR", "NEAR_BOUNDARY", "column_refined_slack", "column_root_counts",
           "combine_grids", "feasibility_grid", "feasibility_map", "join_columns", "map_grid_size"]


MAP_GRID = 45
"""Points per parameter of the report's feasibility map."""

MAP_GRID_SCALAR = 21
"""Points per parameter when a requirement has no vectorized form (a step-response limit: one simulation per
stable point, about 10 ms each with a delay)."""


def map_grid_size(spec: Any) -> int:
    """The feasibility map's points per parameter: :data:`MAP_GRID`, or :data:`MAP_GRID_SCALAR` when a
    requirement is evaluated one loop at a time.

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> map_grid_size(load_spec("specs/x4_rotor_pi.yaml"))
    45
    """
    return MAP_GRID if all(r.vectorized_on(spec.plants()) for r in spec.requirements) else MAP_GRID_SCALAR


def feasibility_grid(spec: Any, design_controller: Any, n: int | None = None, plants: list[int] | None = None,
                     columns: slice | None = None) -> tuple[str, str, np.ndarray, np.ndarray, np.ndarray] | None:
    """The data of :func:`feasibility_map`: ``(xa, xb, A, B, slack)`` with ``slack[0, j, i]`` +1/-1 for a
    stable/unstable loop at ``(A[i], B[j])`` on every plant and ``slack[k + 1, j, i]`` requirement ``k``'s
    worst slack over the plants (None unless the spec has two free parameters). ``plants`` (indices into
    ``spec.plants()``) restricts it to some plants; the grids of a partition of the plants combine into
    the whole one by :func:`combine_grids` (the report computes one plant per job). ``columns`` (a slice)
    computes only the first parameter's values ``A[columns]`` (each column is computed on its own, so the
    parts of a partition of the columns put together by :func:`join_columns` are the whole grid; the report
    splits a one-plant grid of simulated requirements in two jobs, the even and the odd columns: larger gains
    simulate longer, so halves would not balance). ``n`` points per parameter (default :func:`map_grid_size`).

    Stability is exact: along each column the stabilizing set of the second parameter comes from the
    D-decomposition (:func:`synth.synthesis.gainset.stability_set`). The requirements are evaluated for
    the whole grid at once (:meth:`~synth.requirements.base.Requirement.batch_slack`, 20 points per
    decade, peaks and crossings refined); a requirement without a vectorized form only where the loop is stable
    on that plant (elsewhere its slack is what the check gives an unstable loop), at every other value of the
    second parameter and in between only near its boundary (:func:`column_refined_slack`).

    Examples
    --------
    >>> from synth.spec import load_spec; from synth.controllers import Controller
    >>> xa, xb, A, B, slack = feasibility_grid(load_spec("specs/x4_rotor_pi.yaml"),
    ...                                        Controller("PI", {"kp": 4.0, "ki": 40.0}), n=5)
    >>> xa, xb, slack.shape, int((slack[0] < 0).sum()), float(slack[0, 0, 0])  # kp = ki = 0: the pole at s = 0 stays
    ('kp', 'ki', (6, 5, 5), 1, -1.0)
    """
    from synth.controllers import Controller
    from synth.synthesis.gainset import ScalarFamily

    free = spec.controller.free_parameters()
    if len(free) != 2 or design_controller is None:
        return None
    n = map_grid_size(spec) if n is None else n
    bounds = spec.controller.all_bounds()
    (xa, (xa_lo, xa_hi)), (xb, (xb_lo, xb_hi)) = [(p, bounds[p]) for p in free]
    # zoom to the neighbourhood of the design (at most the bounds)
    xa_hi = min(xa_hi, max(2.5 * abs(design_controller.parameters[xa]), xa_lo + 1e-9))
    xb_hi = min(xb_hi, max(2.5 * abs(design_controller.parameters[xb]), xb_lo + 1e-9))
    A = np.linspace(xa_lo, xa_hi, n)
    B = np.linspace(xb_lo, xb_hi, n)
    if columns is not None:
        A = A[columns]
    requirements = list(spec.requirements)
    slack = np.full((len(requirements) + 1, n, A.size), np.nan)
    base = dict(design_controller.parameters)
    every = spec.plants()
    plants = every if plants is None else [every[k] for k in plants]
    counts = np.zeros((len(plants), n, A.size), dtype=int)  # [plant, j, i]
    for i, a in enumerate(A):
        counts[:, :, i] = column_root_counts(ScalarFamily(design_controller.type, xb, {**base, xa: float(a)}),
                                              plants, B)
    slack[0] = np.where(np.all(counts == 0, axis=0), 1.0, -1.0)
    aa, bb = np.meshgrid(A, B)  # [j, i]: b = B[j], a = A[i]
    controllers = [Controller(design_controller.type, {**base, xa: float(a), xb: float(b)})
                   for a, b in zip(aa.ravel(), bb.ravel())]
    first = LoopBatch(plants[0], controllers)
    batches = [(first if k == 0 else first.with_plant(p)).with_root_counts(counts[k].ravel())
               for k, p in enumerate(plants)]
    for k, req in enumerate(requirements):
        worst = np.min([_grid_slack(req, b, counts[i]) for i, b in enumerate(batches)], axis=0)
        slack[k + 1] = worst
    return xa, xb, A, B, slack


def _grid_slack(req: Any, batch: Any, counts: np.ndarray) -> np.ndarray:
    """``req``'s slack on every loop of ``batch`` (the grid's ``[j, i]`` order, ``counts`` of that shape);
    without a vectorized form, one loop at a time by :func:`column_refined_slack`."""
    if req.vectorized_on([batch.plant]):
        return req.batch_slack(batch, 20).reshape(counts.shape)
    loops = batch.loops()
    columns = counts.shape[1]
    # called only where the loop is stable (counts == 0, from the D-decomposition): not counted again
    return column_refined_slack(lambda j, i: req.stable_slack(loops[j * columns + i], 20), counts)[0]


NEAR_BOUNDARY = 0.1
"""A simulated slack smaller than this in magnitude (a log ratio: the value within about 10 % of its bound) marks
a point near the requirement's boundary: :func:`column_refined_slack` simulates its neighbours in the column
too. A settling time jumps where a peak of the response leaves the band (7.5 s to 19.8 s between two rows of a
PI's map whose neighbours' slacks are 0.07 and 0.06), so a slack may change sign between two neighbours that
agree. With 0.1 the maps of tests/test_feasibility_map_scalar.py and of a PI behind 20 ms with an overshoot
limit have the full grid's signs everywhere (0.05 and 0 missed one and three points) and simulate 65 % and
68 % of their stable points. Checked afterwards on four delayed PI maps of the step-design benchmark's seed 3,
not used to choose it (#1, #9, #14, #19, delays 0.07-2.8 s): the full grid's signs everywhere, 70-83 % of the
stable points simulated."""


def column_refined_slack(slack_at: Any, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A requirement's slack on a grid ``[j, i]`` (rows: the second parameter) where each point costs a
    simulation: ``slack_at(j, i)`` at every other row of each column (the first and last rows included) and,
    between two such rows, only where their signs differ, one of them is unstable or near the boundary
    (:data:`NEAR_BOUNDARY`); elsewhere the mean of the two, which has their sign, so the map's zero contour and
    shading are those of the full grid unless a region thinner than two rows lies between two points well
    inside or well outside. Unstable points (``counts > 0``) get what the check says of
    an unstable loop and cost nothing. Returns the slack and where it was computed.

    Examples
    --------
    >>> counts = np.zeros((5, 1), dtype=int)
    >>> slack, computed = column_refined_slack(lambda j, i: 2.5 - j, counts)  # the sign changes between rows 2 and 4
    >>> slack[:, 0].tolist(), computed[:, 0].tolist()
    ([2.5, 1.5, 0.5, -0.5, -1.5], [True, False, True, True, True])
    """
    rows, columns = counts.shape
    out = UNSTABLE_SLACK * np.maximum(counts, 1).astype(float)  # as the check says of an unstable loop
    computed = np.zeros(counts.shape, dtype=bool)
    stable = counts == 0
    coarse = sorted({*range(0, rows, 2), rows - 1})
    for i in range(columns):
        for j in coarse:
            if stable[j, i]:
                out[j, i], computed[j, i] = slack_at(j, i), True
        for j in range(1, rows - 1, 2):
            if not stable[j, i]:
                continue
            below, above = out[j - 1, i], out[j + 1, i]
            if computed[j - 1, i] and computed[j + 1, i] and np.isfinite(below) and np.isfinite(above) \
                    and (below >= 0) == (above >= 0) and min(abs(below), abs(above)) >= NEAR_BOUNDARY:
                out[j, i] = 0.5 * (below + above)
            else:
                out[j, i], computed[j, i] = slack_at(j, i), True
    return out, computed


def column_root_counts(family: Any, plants: list[Any], values: np.ndarray) -> np.ndarray:
    """Closed-loop right-half-plane roots, ``(len(plants), len(values))``, at each of ``values`` (sorted) of
    the family's parameter, as :meth:`synth.loop.Loop.stability` counts them (stability floor included).

    Exact: the counts come from the D-decomposition of ``C = C0 + rho C1``
    (:func:`synth.stability_sets.affine_root_counts`, each part with its common factors ``s`` cancelled, so
    that ``PI`` over ``ki`` is ``kp + ki (1/s)``); a family not affine in its parameter is counted point by point.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.synthesis.gainset import ScalarFamily
    >>> G = Plant.from_string("10/((s-1)*(s+5))")
    >>> column_root_counts(ScalarFamily("PI", "kp", {"kp": 1.0, "ki": 0.0}), [G], np.array([0.2, 0.4, 2.0])).tolist()
    [[1, 1, 0]]
    """
    from synth.stability import stability_floor
    from synth.stability_sets import affine_root_counts

    hi = float(values[-1])
    inner = values[values > 0] if np.any(values > 0) else values
    parts = family.affine_parts(float(inner[0]), hi) if hi > float(inner[0]) else None
    if parts is None:
        return np.array([[Loop(p, family.controller(float(v))).stability().unstable_poles for v in values]
                         for p in plants], dtype=int)
    c0, c1 = parts  # each with its common factors s cancelled
    return np.array([affine_root_counts(c0 if np.any(c0[0]) else None, c1, p.num, p.den, p.delay, values,
                                        stability_floor(p.num, p.den, p.delay)) for p in plants], dtype=int)


def combine_grids(parts: list[tuple[str, str, np.ndarray, np.ndarray, np.ndarray]],
                  ) -> tuple[str, str, np.ndarray, np.ndarray, np.ndarray]:
    """One :func:`feasibility_grid` from the grids of disjoint sets of plants (the worst slack of each).

    Examples
    --------
    >>> from synth.spec import load_spec; from synth.controllers import Controller
    >>> spec, c = load_spec("specs/x4_rotor_robust.yaml"), Controller("PI", {"kp": 4.0, "ki": 40.0})
    >>> whole = feasibility_grid(spec, c, n=5)
    >>> parts = [feasibility_grid(spec, c, n=5, plants=[k]) for k in range(len(spec.plants()))]
    >>> bool(np.array_equal(combine_grids(parts)[4], whole[4]))
    True
    """
    xa, xb, A, B, _ = parts[0]
    return xa, xb, A, B, np.min([p[4] for p in parts], axis=0)


def join_columns(parts: list[tuple[str, str, np.ndarray, np.ndarray, np.ndarray]],
                 ) -> tuple[str, str, np.ndarray, np.ndarray, np.ndarray]:
    """One :func:`feasibility_grid` from the grids of a partition of its columns (in the first parameter's order).

    Examples
    --------
    >>> from synth.spec import load_spec; from synth.controllers import Controller
    >>> spec, c = load_spec("specs/x4_rotor_pi.yaml"), Controller("PI", {"kp": 4.0, "ki": 40.0})
    >>> whole = feasibility_grid(spec, c, n=5)
    >>> parts = [feasibility_grid(spec, c, n=5, columns=slice(k, None, 2)) for k in (0, 1)]
    >>> bool(np.allclose(join_columns(parts)[4], whole[4], rtol=0, atol=1e-12, equal_nan=True))  # to rounding
    True
    """
    xa, xb, _, B, _ = parts[0]
    A = np.concatenate([p[2] for p in parts])
    order = np.argsort(A, kind="stable")
    return xa, xb, A[order], B, np.concatenate([p[4] for p in parts], axis=2)[:, :, order]


def feasibility_map(spec: Any, design_controller: Any, path: Path, n: int | None = None,
                    reference: Any | None = None,
                    grid: tuple[str, str, np.ndarray, np.ndarray, np.ndarray] | None = None) -> Path | None:
    """For two free parameters: where in the parameter plane each requirement holds (on a grid), the
    feasible region shaded, the design marked (data from :func:`feasibility_grid`, unless ``grid`` gives it)."""
    grid = feasibility_grid(spec, design_controller, n) if grid is None else grid
    if grid is None:
        return None
    xa, xb, A, B, slack = grid
    names = [r.name() for r in spec.requirements]
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    ok = np.all(slack >= 0, axis=0)
    ax.contourf(A, B, ok.astype(float), levels=[0.5, 1.5], colors=["#2e8b57"], alpha=0.18)
    unstable = slack[0] < 0
    if np.any(unstable):
        ax.contourf(A, B, unstable.astype(float), levels=[0.5, 1.5], colors=["#555555"], alpha=0.25)
        ax.plot([], [], color="#555555", lw=6, alpha=0.4, label="closed loop unstable")
    for k, name in enumerate(names):
        s = np.nan_to_num(slack[k + 1], nan=-10, posinf=10, neginf=-10)
        if np.nanmin(s) < 0 < np.nanmax(s):
            cs = ax.contour(A, B, s, levels=[0.0], colors=[COLORS[k % len(COLORS)]], linewidths=1.8)
            ax.plot([], [], color=COLORS[k % len(COLORS)], label=f"{name} boundary")
            del cs
    ax.plot(design_controller.parameters[xa], design_controller.parameters[xb], "k*", ms=14, label="design")
    if reference is not None and reference.type == design_controller.type:
        ax.plot(reference.parameters[xa], reference.parameters[xb], "ko", mfc="none", ms=10, label="reference")
    ax.set_xlabel(xa)
    ax.set_ylabel(xb)
    title = f"Feasible parameters (shaded), exact check on a {A.size} x {B.size} grid"
    simulated = [r.name() for r in spec.requirements if not r.vectorized_on(spec.plants())]
    if simulated:  # column_refined_slack
        title += (f"\n{', '.join(simulated)}: simulated at every other {xb}, and between them near its "
                  "boundary or an unstable point")
    ax.set_title(title, **({"fontsize": 10} if simulated else {}))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return save_figure(fig, path)
