"""A fit stuck where exchangeable parameters meet: started again with them apart.

In ``k/((s+p1)*(s+p2)*(s+p3))`` the cost is symmetric in the poles: swapping two leaves it unchanged. Where the
deterministic start puts two of them at one value (SRIVC returned a complex pair, whose closest real match is a double
pole), the gradient along their difference is zero by that symmetry and the solver stays on the ridge ``p1 = p3``
though the cost falls away from it: on a record of a three-real-pole plant at 4 kHz the fit ended at 40.14 / 40.14
(infinite variances, ``J^T J`` singular) where the optimum holds 33.67 / 50.98. So when a fit from the deterministic
start ends with exchangeable parameters that met (within ``MET`` of each other, and their difference within the
larger standard error, or an error infinite), the fit is repeated from a start with those values moved apart by
``SPLIT`` of their mean each way, and kept when it fits better (:func:`off_ridge`).
"""

from __future__ import annotations

from dataclasses import replace
from itertools import pairwise
from typing import Any

import numpy as np

from synth.ident.exchangeable import exchangeable_groups

__all__ = ["MET", "SPLIT", "off_ridge", "ridge_split_start"]

MET = 1e-3
"""Exchangeable values this close (a share of the larger) have met, if also within their standard errors."""

SPLIT = 0.1
"""How far apart a restart puts exchangeable values that met: each moves by this fraction of their mean."""


def ridge_split_start(fitted: Any, lower: dict[str, float] | None = None) -> dict[str, float] | None:
    """Start values off the symmetric ridge ``fitted`` (a :class:`~synth.ident.timefit.TimeFitResult`) ended on,
    with its delay; ``None`` where no exchangeable parameters met (or the split start leaves a lower bound).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> from synth.ident.structure import parse_structure
    >>> fit = SimpleNamespace(structure=parse_structure("k/((s+p1)*(s+p2))"), delay=0.0,
    ...                       parameters={"k": 8.0, "p1": 4.0, "p2": 4.0}, std={"k": 0.1, "p1": np.inf, "p2": np.inf})
    >>> ridge_split_start(fit)
    {'k': 8.0, 'p1': 3.6, 'p2': 4.4, 'delay': 0.0}
    >>> fit.parameters, fit.std = {"k": 8.0, "p1": 2.0, "p2": 4.0}, {"k": 0.1, "p1": 0.3, "p2": 0.4}
    >>> ridge_split_start(fit) is None
    True
    """
    start = {name: float(fitted.parameters[name]) for name in fitted.structure.parameters}
    moved = False
    for group in exchangeable_groups(fitted.structure):
        for cluster in _met(group, start, fitted.std):
            mean = float(np.mean([start[name] for name in cluster]))
            for k, name in enumerate(sorted(cluster, key=lambda n: (start[n], group.index(n)))):
                start[name] = mean * (1.0 + SPLIT * (2 * k - (len(cluster) - 1)))
            moved = True
    if not moved or any(start[name] < bound for name, bound in (lower or {}).items() if name in start):
        return None
    return {**start, "delay": float(fitted.delay)}


def _met(group: list[str], values: dict[str, float], std: dict[str, float]) -> list[list[str]]:
    """The clusters of a group's parameters that met: neighbours (by value) within :data:`MET` of each other and
    within the larger of their standard errors (or one of them infinite); a value of 0 never (no scale to split
    it by)."""
    ordered = sorted(group, key=lambda n: values[n])
    clusters: list[list[str]] = [[ordered[0]]]
    for prev, name in pairwise(ordered):
        a, b, sd = values[prev], values[name], max(std.get(prev, np.inf), std.get(name, np.inf))
        if a != 0.0 and b != 0.0 and abs(b - a) <= MET * max(abs(a), abs(b)) and not abs(b - a) > sd:
            clusters[-1].append(name)
        else:
            clusters.append([name])
    return [c for c in clusters if len(c) > 1]


def off_ridge(restarted: Any, fitted: Any) -> Any:
    """The restarted fit where it fits better than the one on the ridge and did not fail, with a note in
    ``solver["ridge_split"]``; else ``fitted``.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> ridge = SimpleNamespace(fit_percent=93.0, solver={}, parameters={"p1": 4.0, "p2": 4.0})
    >>> off_ridge(SimpleNamespace(fit_percent=92.0, solver={}, parameters={}), ridge) is ridge
    True
    """
    if restarted.solver.get("failure") or not restarted.fit_percent > fitted.fit_percent + 1e-9:
        return fitted
    met = ", ".join(f"{k} = {v:.6g}" for k, v in fitted.parameters.items())
    note = (f"restarted off a symmetric ridge: from the deterministic start the fit ended with exchangeable "
            f"parameters the record could not tell apart ({met}; fit {fitted.fit_percent:.6f} %), from a start with "
            f"them moved {SPLIT:.0%} apart at {restarted.fit_percent:.6f} %")
    return replace(restarted, solver={**restarted.solver, "ridge_split": note,
                                      "initialization": fitted.solver.get("initialization", "")
                                      + f"; restarted with exchangeable values moved {SPLIT:.0%} apart"})
