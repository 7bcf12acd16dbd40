"""Parameters of a structure that play the same role: swapping their values leaves the model unchanged.

In ``k/((s+p1)*(s+p2))`` the fit may return the slow pole as ``p1`` in one record and as ``p2`` in another;
comparing fits parameter by parameter then compares a slow pole with a fast one. :func:`exchangeable_groups`
finds such groups by evaluating the structure's coefficients with pairs of values swapped (at random values,
so a coincidence is not taken for a symmetry), and :func:`align_labels` relabels one fit's values within each
group to match a reference fit.
"""

from __future__ import annotations

from itertools import permutations

import numpy as np

from synth.ident.structure import Structure

__all__ = ["align_labels", "exchangeable_groups"]


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

    def normalized(values: np.ndarray) -> np.ndarray:
        num, den = structure.coefficients(values)
        scale = den[np.flatnonzero(den)[0]] if np.any(den) else 1.0
        return np.r_[np.asarray(num, float), np.asarray(den, float)] / scale

    base = normalized(theta)
    parent = list(range(len(names)))

    def root(i: int) -> int:
        while parent[i] != i:
            i = parent[i]
        return i

    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            swapped = theta.copy()
            swapped[[i, j]] = swapped[[j, i]]
            if np.allclose(normalized(swapped), base, rtol=1e-10, atol=1e-12):
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
    for group in groups:
        if not all(k in values and k in reference for k in group):
            continue

        def cost(order: tuple[str, ...], group: list[str] = group) -> float:
            return float(sum(((values[src] - reference[dst]) / max(stds.get(src, 1.0), 1e-300)) ** 2
                             for src, dst in zip(order, group)))

        best = min(permutations(group), key=cost)
        for src, dst in zip(best, group):
            out_v[dst], out_s[dst] = values[src], stds.get(src, np.nan)
    return out_v, out_s
