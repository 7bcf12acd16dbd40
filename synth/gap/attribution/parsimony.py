"""Parsimony: which accepted candidate leads, and how much of the excess over noise a model removes.

A model with more free parameters (:func:`free_parameters`) leads a simpler accepted candidate only
when it beats it significantly (:func:`parsimonious_lead`); :func:`share_of_excess` is the part of a
model's held-out excess over the noise floor another one removes.
"""

from __future__ import annotations

from collections.abc import Collection
from typing import Any

import numpy as np

from synth.gap.effects.base import Effect

__all__ = ["fitted_form", "free_parameters", "parsimonious_lead", "share_of_excess"]


def share_of_excess(j_before: float, j: float, floor: float) -> float:
    """Part of a model's held-out excess over the noise floor that a model with held-out ``J = j`` removes.

    The floor is taken as at most ``j``: the noise variance is no larger than the held-out error of
    a model of the record (its expectation is the noise variance plus the model's error), so a model
    that gets below the floor's estimate shows that the estimate is too high there, and removes all
    of the excess that can be measured.

    Parameters
    ----------
    j_before : float
        Held-out ``J`` of the model before (the re-fit, or the model with the accepted effects).
    j : float
        Held-out ``J`` of the model judged.
    floor : float
        Noise floor ``sigma^2`` (robust estimate, see the module text).

    Returns
    -------
    float
        ``(j_before - j) / (j_before - min(floor, j))``; 0 when ``j_before`` is not above that floor.

    Examples
    --------
    >>> round(share_of_excess(2.0, 1.5, 1.0), 3), share_of_excess(0.95, 0.85, 1.0)
    (0.5, 1.0)
    >>> share_of_excess(0.95, 0.97, 1.0)
    0.0
    """
    base = min(floor, j)
    return (j_before - j) / (j_before - base) if j_before > base else 0.0


def free_parameters(effect: Effect, params: dict[str, float]) -> int:
    """Parameters the fit of ``effect`` chose: its grid, factor and basis parameters with a finite value.

    A parameter the effect fixes from the record (a dead zone's center held at the command at rest, the
    static map's center and scale) is not chosen by the fit (a dead zone whose center was fitted counts
    it), and a limit left at infinity (the unused side of a one-sided saturation) is not a parameter of
    the fitted model. An effect that declares no grid, factor or basis parameters counts its
    ``parameter_names``.

    Examples
    --------
    >>> from synth.gap.effects import make_effect
    >>> free_parameters(make_effect("resonance"), {"wn": 80.0, "zeta": 0.3})
    2
    >>> free_parameters(make_effect("saturation"), {"lower": 2.4, "upper": float("inf")})
    1
    >>> free_parameters(make_effect("deadzone"), {"width": 0.1, "center": 2.0})
    1
    >>> free_parameters(make_effect("deadzone").nested_variants()[1], {"width": 0.1, "center": 2.0})
    2
    """
    names = tuple(dict.fromkeys((*effect.grid_names, *effect.factor_names, *effect.basis_names)))
    return sum(1 for name in names or effect.parameter_names if np.isfinite(params.get(name, np.nan)))


def fitted_form(effect: Effect, parameter_ci: Collection[str]) -> Effect:
    """The form of ``effect`` a joint fit kept, read from its intervals (what a verdict pooled over runs has).

    The richer of its :meth:`~synth.gap.effects.base.Effect.nested_variants` when ``parameter_ci`` (the intervals,
    or just their names) holds a parameter only the richer one fits (a dead zone's fitted center), else the simpler
    one (or ``effect`` itself).

    Examples
    --------
    >>> from synth.gap.effects import make_effect
    >>> fitted_form(make_effect("deadzone"), {"width": (0.1, 0.2), "center": (2.9, 3.1)}).center_search
    'fitted'
    >>> fitted_form(make_effect("deadzone"), {"width": (0.1, 0.2)}).center_search
    'rest'
    """
    variants = effect.nested_variants()
    if variants is None:
        return effect
    simpler, richer = variants
    return richer if (set(richer.grid_names) - set(simpler.grid_names)) & set(parameter_ci) else simpler


def parsimonious_lead(candidates: list[tuple[str, np.ndarray]], counts: list[int], advantage_ci: Any,
                       threshold: float) -> tuple[int, dict[str, Any] | None]:
    """Which accepted candidate leads the verdict: the simplest one the best does not beat significantly.

    Parameters
    ----------
    candidates : list of (str, numpy.ndarray)
        The relevant candidates' labels and held-out block sums, lowest held-out ``J`` first.
    counts : list of int
        Their free parameters (:func:`free_parameters`).
    advantage_ci : callable
        ``advantage_ci(s_a, s_b)``: 95 % bootstrap interval of the held-out shrinkage ``1 - J_a / J_b``
        of model ``a`` against model ``b`` (the same segment draws for both).
    threshold : float
        The calibrated shrinkage an effect must exceed against the re-fit (parametric bootstrap).

    Returns
    -------
    int
        Index of the leader in ``candidates``.
    dict or None
        ``{"lead", "lead_parameters", "best", "best_parameters", "advantage_ci", "threshold"}`` when the
        leader is not the lowest-``J`` candidate (``advantage_ci``: the interval of the best's shrinkage
        against the leader), else ``None``.

    Notes
    -----
    A model with more free parameters also fits the training noise better and carries some of that
    to held-out data by chance. It leads a simpler accepted candidate only when its held-out
    shrinkage against that candidate passes the test every effect passes against the re-fit: the
    lower end of its interval above the calibrated threshold. Among the candidates the best does not
    beat so, the one with the fewest parameters leads (ties: the lower held-out ``J``).

    Examples
    --------
    >>> ci = lambda a, b: (1 - a.sum() / b.sum() - 0.01, 1 - a.sum() / b.sum() + 0.01)  # +-0.01 interval
    >>> two, one = ("resonance", np.array([10.0])), ("delay", np.array([10.1]))
    >>> parsimonious_lead([two, one], [2, 1], ci, 0.02)[0]  # 1 % better: not significant, the delay leads
    1
    >>> parsimonious_lead([two, ("delay", np.array([13.0]))], [2, 1], ci, 0.02)  # 23 % better: resonance
    (0, None)
    """
    s_best = candidates[0][1]
    lead = 0
    for i in range(1, len(candidates)):
        if counts[i] < counts[lead] and advantage_ci(s_best, candidates[i][1])[0] <= threshold:
            lead = i
    if lead == 0:
        return 0, None
    return lead, {"lead": candidates[lead][0], "lead_parameters": counts[lead], "best": candidates[0][0],
                  "best_parameters": counts[0], "advantage_ci": list(advantage_ci(s_best, candidates[lead][1])),
                  "threshold": threshold}
