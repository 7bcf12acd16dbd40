"""Parameters of a structure that play the same role: swapping their values leaves the model unchanged.

In ``k/((s+p1)*(s+p2))`` the fit may return the slow pole as ``p1`` in one record and as ``p2`` in another;
comparing fits parameter by parameter then compares a slow pole with a fast one. :func:`exchangeable_groups`
finds such groups by evaluating the structure's coefficients with pairs of values swapped (at random values,
so a coincidence is not taken for a symmetry), and :func:`align_labels` relabels one fit's values within each
group to match a reference fit.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import permutations
from typing import Any

import numpy as np

from synth.ident.structure import Structure

__all__ = ["align_labels", "exchangeable_groups", "relabel_fit"]


def exchangeable_groups(structure: Structure) -> list[list[str]]:
    """Groups of two or more parameters whose values can be permuted without changing the model.

    Examples
    --------
    >>> from synth.ident.structure import parse_structure
    >>> exchangeable_groups(parse_structure("k/((s+p1)*(s+p2))"))
    [['p1', 'p2']]
    >>> exchangeable_groups(parse_structure("k*(s+z)/((s+p1)*(s+p2))"))
    [['p1', 'p2']]
    >>> exchangeable_groups(parse_structure("K/(T*s+1)"))
    []
    """
    names = list(structure.parameters)
    theta = np.random.default_rng(20261204).uniform(0.5, 2.0, len(names))
    base = structure.normalized_coefficients(theta)
    parent = list(range(len(names)))

    def root(i: int) -> int:
        while parent[i] != i:
            i = parent[i]
        return i

    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            swapped = theta.copy()
            swapped[[i, j]] = swapped[[j, i]]
            if np.allclose(structure.normalized_coefficients(swapped), base, rtol=1e-10, atol=1e-12):
                parent[root(j)] = root(i)
    groups: dict[int, list[str]] = {}
    for i, name in enumerate(names):
        groups.setdefault(root(i), []).append(name)
    return [g for g in groups.values() if len(g) > 1]


def align_labels(values: dict[str, float], stds: dict[str, float], reference: dict[str, float],
                 groups: list[list[str]]) -> tuple[dict[str, float], dict[str, float]]:
    """``values`` and ``stds`` with each exchangeable group permuted to lie closest to ``reference`` (the sum of
    squared differences in units of the stds, over the group).

    Examples
    --------
    >>> align_labels({"p1": 10.0, "p2": 1.0}, {"p1": 0.3, "p2": 0.01}, {"p1": 1.1, "p2": 9.8}, [["p1", "p2"]])
    ({'p1': 1.0, 'p2': 10.0}, {'p1': 0.01, 'p2': 0.3})
    """
    out_v, out_s = dict(values), dict(stds)
    for dst, src in _closest_labels(values, stds, reference, groups).items():
        out_v[dst], out_s[dst] = values[src], stds.get(src, np.nan)
    return out_v, out_s


def relabel_fit(fit: Any, reference: dict[str, float]) -> Any:
    """``fit`` (a :class:`~synth.ident.timefit.TimeFitResult`, whose module imports this one through
    :mod:`synth.ident.symmetric_ridge`) with the values of each exchangeable group of its structure permuted to lie
    closest to ``reference`` (as :func:`align_labels`), with their standard errors, intervals, covariance and
    starts: the same model, labelled as the reference (two fits compared name by name then compare like with like).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.ident.timefit import fit_structure
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 6, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/((s+1)*(s+2))"), t, u)
    >>> start = {"k": 2.0, "p1": 2.0, "p2": 1.0}
    >>> fit = fit_structure(record_from_arrays(t, u, y), "k/((s+p1)*(s+p2))", initial=start)
    >>> [round(fit.parameters[k], 4) for k in ("p1", "p2")]
    [2.0, 1.0]
    >>> again = relabel_fit(fit, {"k": 2.0, "p1": 1.0, "p2": 2.0})
    >>> [round(again.parameters[k], 4) for k in ("p1", "p2")], again.plant.to_string(4) == fit.plant.to_string(4)
    ([1.0, 2.0], True)
    """
    source = _closest_labels(fit.parameters, fit.std, reference, exchangeable_groups(fit.structure))
    source = {dst: src for dst, src in source.items() if dst != src}
    if not source:
        return fit

    def moved(d: dict) -> dict:
        return {k: d[source.get(k, k)] for k in d}

    order = [fit.names.index(source.get(k, k)) for k in fit.names]
    return replace(fit, parameters=moved(fit.parameters), std=moved(fit.std), ci95=moved(fit.ci95),
                   covariance=fit.covariance[np.ix_(order, order)], initial=moved(fit.initial))


def _closest_labels(values: dict[str, float], stds: dict[str, float], reference: dict[str, float],
                    groups: list[list[str]]) -> dict[str, str]:
    """For each name of the groups, the name whose value it takes (the permutation closest to ``reference``)."""
    source: dict[str, str] = {}
    for group in groups:
        if not all(k in values and k in reference for k in group):
            continue

        def cost(order: tuple[str, ...], group: list[str] = group) -> float:
            return float(sum(((values[src] - reference[dst]) / max(stds.get(src, 1.0), 1e-300)) ** 2
                             for src, dst in zip(order, group)))

        best = min(permutations(group), key=cost)
        source.update(zip(group, best))
    return source
