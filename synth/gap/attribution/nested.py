"""An effect fitted in a simpler and a richer form, the richer kept only when the record demands it.

A dead zone's band either sits around where the command rests (its center fixed by the record) or somewhere else
(its center a second fitted parameter). The richer form always fits the training record at least as well; it is kept
when its training SSR is lower by more than ``critical`` noise variances ``SSR/N`` (the likelihood-ratio test of one
extra parameter at 95 %: :data:`~synth.gap.effects.base.NESTED_CRITICAL`), so that a parameter the data do not ask
for is neither reported nor counted against the effect (:func:`synth.gap.attribution.parsimony.free_parameters`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import NESTED_CRITICAL, Effect, Params
from synth.plant import Plant

__all__ = ["fit_nested", "split_grid"]


def split_grid(simpler: Effect, grid: list[Params], own: list[Params]) -> tuple[list[Params], list[Params]]:
    """The points of ``grid`` that are the simpler form's (its fixed parameters as in its ``own`` grid), and the rest.

    Examples
    --------
    >>> from synth.gap.effects import DeadzoneEffect
    >>> rest = DeadzoneEffect(center_search="rest")
    >>> split_grid(rest, [{"width": 0.1, "center": 2.0}, {"width": 0.2, "center": 5.0}], [{"width": 1.0, "center": 2.0}])
    ([{'width': 0.1, 'center': 2.0}], [{'width': 0.2, 'center': 5.0}])
    """
    fixed = {k: v for k, v in own[0].items() if k not in simpler.grid_names} if own else {}
    mine = [g for g in grid if all(g.get(k) == v for k, v in fixed.items())]
    return mine, [g for g in grid if g not in mine]


def fit_nested(fit: Callable[..., Any], simpler: Effect, richer: Effect, plant: Plant, t: np.ndarray, u: np.ndarray,
               y: np.ndarray, grid: list[Params] | None, critical: float = NESTED_CRITICAL, **options: Any) -> Any:
    """Fit both forms and keep the richer one only when its training SSR is lower by ``critical`` noise variances
    and its parameters are admissible (:meth:`synth.gap.effects.base.Effect.admissible`).

    Parameters
    ----------
    fit : callable
        :func:`synth.gap.attribution.refit.fit_augmented`.
    simpler, richer : Effect
        The two forms (:meth:`synth.gap.effects.base.Effect.nested_variants`).
    plant : Plant
        Nominal model.
    t, u, y : numpy.ndarray
        Training record.
    grid : list of dict or None
        Starting points (a screened point and its neighbours): those of the simpler form start it (else its own
        grid), the others the richer one. The richer form is fitted only from points that are not the simpler
        one's, or from its own grid when no points are given: a screen whose best point was the simpler form found
        no sign of the richer one.
    critical : float
        Noise variances of training SSR the richer form must gain.
    **options
        Passed to ``fit`` (``start``, ``weights``, ``early_stop``).

    Returns
    -------
    AugmentedFit
        The kept form's fit (its ``effect`` says which).

    Examples
    --------
    >>> from synth.gap.attribution.refit import fit_augmented
    >>> from synth.gap.effects import DeadzoneEffect
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 20, 0.01); u = 5 + 4 * np.sin(0.6 * t); G = Plant.from_string("2/(0.3*s+1)")
    >>> y = DeadzoneEffect().apply(G, t, u, {"width": 0.8, "center": 3.0})
    >>> f = fit_nested(fit_augmented, *DeadzoneEffect().nested_variants(), G, t, u, y, None)
    >>> f.effect.center_search, round(f.params["center"], 2), round(f.params["width"], 2)
    ('fitted', 3.0, 0.8)
    """
    own = simpler.data_grid(t, u, y, plant)
    mine, others = split_grid(simpler, grid, own) if grid is not None else (own, richer.data_grid(t, u, y, plant))
    base = fit(plant, t, u, y, simpler, grid=mine or own, **options)
    if not others:  # the screen's best was the simpler form, or the richer one has no admissible start here
        return base
    try:
        rich = fit(plant, t, u, y, richer, grid=others, **options)
    except ModelError:  # no point of the richer form could be fitted: the simpler one's answer stands
        return base
    better = rich.ssr < base.ssr - critical * rich.ssr / max(rich.samples, 1)
    return rich if better and richer.admissible(rich.params, np.asarray(u, float)) else base
