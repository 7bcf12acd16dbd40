"""Cheap screening of candidate effects before the joint casadi re-fit.

Every candidate is first fitted with the **denominator of the linear model
held fixed** and everything that enters the output linearly solved by least
squares: the numerator coefficients of the (augmented) linear part, the
output constant, the effect's basis parameters (``a2, a3``, ``sag``, drift
terms). For a fixed denominator and fixed non-smooth parameters the output is
linear in those, so each point of the effect's parameter search costs a few
linear simulations (:func:`synth.ident.simulate.simulate_plant`, milliseconds)
instead of an IPOPT solve on the whole record. The search runs the effect's own
grid (:meth:`synth.gap.effects.base.Effect.grid`) plus a golden-section search in the
log of the grid parameter between the best point's neighbours; the extra delay
and a resonance's damping, which the joint fit treats as smooth, get a grid of
their own here. The denominator is tried at two places, the nominal model's and
the re-fit's, since the re-fit alone may have moved its poles to mimic the
effect (a slower plant for a rate limit) and the nominal has not.

The screened training SSR ranks the candidates; :func:`synth.gap.attribution.heldout.diagnose_effects`
re-fits only the best few jointly (nominal coefficients and effect, casadi),
started at the screened parameters. A screened fit is never better than the joint
fit of the same effect could be (it is the same model with fewer free
coefficients), so the ranking errs against an effect only when a pole shift
the screen cannot make is what the effect needs.

A quantizer's step and offset are searched densely and jointly instead
(:func:`synth.gap.effects.quantization.quantizer_grid`): each effect gives its own search points
(:meth:`synth.gap.effects.base.Effect.screen_grid`) and says whether a golden-section search refines
them (``golden_search``). An effect whose grid parameters act together searches them all from the best
point found (:meth:`synth.gap.effects.base.Effect.refine_screen`; the direction effect's four time
parameters, by a pattern search).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.gap.attribution.golden import golden_section, log_bracket
from synth.gap.attribution.tall_lsq import TallLeastSquares
from synth.gap.effects.base import Effect, Params, unit_numerators
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["EffectDesign", "ScreenedFit", "screen_effect"]

_GOLDEN_STEPS = 14


@dataclass(frozen=True, eq=False)
class ScreenedFit:
    """One candidate's screened fit (denominator fixed, linear parameters by least squares).

    Attributes
    ----------
    effect : Effect
    params : dict
        Effect parameters at the best screened point (basis parameters included).
    ssr : float
        Training sum of squared errors there.
    plant : Plant
        The linear model with the least-squares numerator (without the effect's factor).
    offset : float
        Output constant.
    base : str
        Which denominator: ``"nominal"`` or ``"refit"``.
    points : int
        Parameter points evaluated.
    yhat_train, yhat_eval : numpy.ndarray
        Screened model output on the training and the evaluated record.
    ssr_held : float
        Lowest training SSR over the points searched with the base denominator held exactly (no
        Gauss-Newton step). The step's linearization can let every candidate reach the same SSR (a
        large pole change is mimicked by the step's columns, effect or no effect), which hides the one
        effect that needs no step; this SSR does not.
    params_held : dict
        The effect's grid parameters at that point.
    """

    effect: Effect
    params: Params
    ssr: float
    plant: Plant
    offset: float
    base: str
    points: int
    yhat_train: np.ndarray = field(repr=False)
    yhat_eval: np.ndarray = field(repr=False)
    ssr_held: float = np.inf
    params_held: dict = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON summary.

        Examples
        --------
        >>> import numpy as np
        >>> from synth.gap.effects import make_effect
        >>> t = np.arange(0, 4, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
        >>> G = Plant.from_string("2/(0.2*s+1)")
        >>> y = simulate_plant(G.with_delay(0.05), t, u)
        >>> d = screen_effect(make_effect("delay"), [("nominal", G)], t, u, y, t, u).to_dict()
        >>> d["effect"], round(d["parameters"]["delay"], 4), d["base"]
        ('delay', 0.05, 'nominal')
        """
        return {"effect": self.effect.label, "parameters": {k: float(v) for k, v in self.params.items()},
                "ssr": self.ssr, "tf": self.plant.to_string(6), "offset": self.offset, "base": self.base,
                "points": self.points}


def _denominator_directions(plant: Plant) -> list[Plant]:
    """``dG/dd_k = -N s^k / D^2`` for every nonzero non-leading denominator coefficient ``d_k`` of ``G = N/D``.

    With these columns in the least squares, the screen takes one Gauss-Newton step in the
    denominator from the base instead of holding it fixed, so an effect that needs the poles to move
    (a limit that changes how fast the plant looks) is not ranked as if it could not.

    Examples
    --------
    >>> d = _denominator_directions(Plant.from_string("2/(s+3)"))[0]
    >>> d.num.tolist(), d.den.tolist()
    ([-2.0], [1.0, 6.0, 9.0])
    """
    out = []
    deg = plant.den.size - 1
    den2 = np.polymul(plant.den, plant.den)
    for i, c in enumerate(plant.den):
        if i == 0 or c == 0.0:
            continue
        power = np.zeros(deg - i + 1)
        power[0] = 1.0
        out.append(Plant(-np.polymul(plant.num, power), den2, plant.delay, plant.input, plant.output, plant.label))
    return out


class EffectDesign:
    """Least-squares design of one effect on one denominator: columns on the training and evaluated records.

    :meth:`fit` gives the training SSR of the nominal's numerator, the effect's basis and the output constant
    re-fitted with the effect's grid parameters held at ``params`` (what the screen compares across its grid).

    Examples
    --------
    >>> from synth.gap.effects.registry import make_effect
    >>> t = np.arange(0.0, 3.0, 0.01); u = (t > 0.5).astype(float)
    >>> plant = Plant.from_string("2/(s+1)")
    >>> y = simulate_plant(plant, t, np.r_[np.zeros(20), u[:-20]])  # the plant behind a 0.2 s delay
    >>> design = EffectDesign(make_effect("delay"), plant, [(t, u), (t, u)])
    >>> design.fit({"delay": 0.2}, y)[0] < 1e-12 < design.fit({"delay": 0.0}, y)[0]
    True
    """

    def __init__(self, effect: Effect, base: Plant, records: list[tuple[np.ndarray, np.ndarray]],
                 mask: np.ndarray | None = None) -> None:
        self.effect, self.base, self.records, self.mask = effect, base, records, mask
        self.units = unit_numerators(base)
        self.directions = _denominator_directions(base)

    def columns(self, params: Params, t: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, int]:
        eff = self.effect
        dt = float((t[-1] - t[0]) / (t.size - 1))
        p = {**eff.off(), **params}
        v0 = eff.input_map(u, dt, p)
        cols = [simulate_plant(eff.augment_plant(g, p), t, v0) for g in self.units]
        k_num = len(cols)
        g_aug = eff.augment_plant(self.base, p)
        cols += [simulate_plant(g_aug, t, phi) for phi in eff.input_basis(u, dt, p)]
        cols += list(eff.output_basis(t))
        cols += [simulate_plant(eff.augment_plant(g, p), t, v0) for g in self.directions]
        cols.append(np.ones_like(t))
        return np.column_stack(cols), k_num

    def fit(self, params: Params, y: np.ndarray) -> tuple[float, np.ndarray, int, float]:
        """Training SSR, coefficients, numerator columns, and the SSR with the denominator held (no step)."""
        t_tr, u_tr = self.records[0]
        X, k_num = self.columns(params, t_tr, u_tr)
        if self.mask is not None:  # only the fitted samples count
            X, y = X[self.mask], y[self.mask]
        ls = TallLeastSquares(X, y)  # one Gram matrix for both fits
        if not ls.finite:
            return np.inf, np.zeros(X.shape[1]), k_num, np.inf
        coef, ssr = ls.fit()
        n_dir = len(self.directions)
        if not n_dir:
            return ssr, coef, k_num, ssr
        held = np.r_[np.arange(X.shape[1] - 1 - n_dir), X.shape[1] - 1]  # every column but the directions
        return ssr, coef, k_num, ls.fit(held)[1]

    def evaluate(self, params: Params, coef: np.ndarray, t: np.ndarray, u: np.ndarray) -> np.ndarray:
        X, _ = self.columns(params, t, u)
        return X @ coef


def _search_key(effect: Effect, grid: list[Params]) -> str | None:
    for name in ("delay", *effect.grid_names):
        if any(name in g for g in grid):
            return name
    return None


def screen_effect(effect: Effect, bases: list[tuple[str, Plant]], t_tr: np.ndarray, u_tr: np.ndarray,
                  y_tr: np.ndarray, t_ev: np.ndarray, u_ev: np.ndarray, mask: np.ndarray | None = None) -> ScreenedFit:
    """Screen one effect: its parameter search with each base denominator fixed, the rest by least squares.

    Parameters
    ----------
    effect : Effect
    bases : list of (str, Plant)
        Named linear models whose denominators (and delay) are held fixed.
    t_tr, u_tr, y_tr : numpy.ndarray
        Training record (the model starts at rest at its first sample).
    t_ev, u_ev : numpy.ndarray
        Evaluated record (the training record's continuation, or a validation record).
    mask : numpy.ndarray of bool, optional
        Training samples that count in the SSR (default all; the model runs over all of them).

    Returns
    -------
    ScreenedFit

    Raises
    ------
    ModelError
        No point could be evaluated.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.gap.effects import make_effect
    >>> t = np.arange(0, 6, 0.01); u = np.where((t % 3) >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> y = make_effect("rate_limit").apply(G, t, u, {"rate": 4.0})
    >>> s = screen_effect(make_effect("rate_limit"), [("nominal", G)], t, u, y, t, u)
    >>> round(s.params["rate"], 2), s.ssr < 1e-6
    (4.0, True)
    """
    t_tr, u_tr, y_tr = (np.asarray(a, float) for a in (t_tr, u_tr, y_tr))
    best: tuple[float, Params, np.ndarray, int, str, EffectDesign] | None = None
    points = 0
    ssr_held, params_held = np.inf, {}
    for base_name, base in bases:
        design = EffectDesign(effect, base, [(t_tr, u_tr), (t_ev, u_ev)], mask)
        try:
            grid = effect.screen_grid(t_tr, u_tr, y_tr, base, mask)
        except ModelError:
            continue
        tried: dict[tuple[tuple[str, float], ...], tuple[float, np.ndarray, int]] = {}

        def run(g: Params, design: EffectDesign = design, tried: dict = tried) -> float:
            nonlocal ssr_held, params_held
            key = tuple(sorted(g.items()))
            if key not in tried:
                ssr, coef, k_num, held = design.fit(g, y_tr)
                tried[key] = (ssr if np.isfinite(ssr) else np.inf, coef, k_num)
                if np.isfinite(held) and held < ssr_held:
                    ssr_held, params_held = held, {**effect.off(), **g}
            return tried[key][0]

        for g in grid:
            run(g)
        key_name = _search_key(effect, grid) if effect.golden_search else None
        g_best = min(grid, key=lambda g: run(g))
        if key_name is not None:
            g_best = _golden(run, grid, g_best, key_name)
        g_best = effect.refine_screen(run, g_best, t_tr, u_tr, base)
        points += len(tried)
        ssr = run(g_best)
        if best is None or ssr < best[0]:
            _, coef, k_num = tried[tuple(sorted(g_best.items()))]
            best = (ssr, g_best, coef, k_num, base_name, design)
    if best is None or not np.isfinite(best[0]):
        raise ModelError("no screening point could be evaluated", where=f"effect {effect.label}")
    ssr, g, coef, k_num, base_name, design = best
    base = design.base
    params = {**effect.off(), **g}
    n_basis_in = len(effect.input_basis(u_tr, float(t_tr[1] - t_tr[0]), params))
    for j, name in enumerate(effect.basis_names):
        params[name] = float(coef[k_num + j])
    num = np.zeros_like(base.num, dtype=float)
    num[np.flatnonzero(base.num != 0.0)] = coef[:k_num]
    n_dir = len(design.directions)
    den = base.den.astype(float).copy()
    if n_dir:  # the Gauss-Newton step (one direction per nonzero non-leading coefficient)
        den[[i for i, c in enumerate(base.den) if i > 0 and c != 0.0]] += coef[-1 - n_dir:-1]
    plant = Plant(num, den, base.delay, base.input, base.output, "screened")
    if n_basis_in:  # the basis columns ran through the base numerator: express them per unit of the new gain
        gain = float(num @ base.num) / float(base.num @ base.num)  # least-squares ratio of the numerators
        for name in effect.basis_names[:n_basis_in]:
            params[name] = params[name] / gain if gain != 0 else params[name]
    y_train = design.evaluate(g, coef, t_tr, u_tr)
    y_eval = design.evaluate(g, coef, np.asarray(t_ev, float), np.asarray(u_ev, float))
    return ScreenedFit(effect, params, float(ssr), plant, float(coef[-1]), base_name, points, y_train, y_eval,
                       float(ssr_held), params_held)


def _golden(run: Any, grid: list[Params], g_best: Params, key: str) -> Params:
    """Golden-section search in log(key) between the best grid point's neighbours (the other keys fixed)."""
    rest = {k: v for k, v in g_best.items() if k != key}
    vals = sorted({g[key] for g in grid if key in g and np.isfinite(g[key]) and g[key] > 0
                   and {k: v for k, v in g.items() if k != key} == rest})
    bracket = log_bracket(vals, g_best.get(key, np.nan))
    if bracket is None:
        return g_best
    c, d = golden_section(lambda x: run({**rest, key: float(np.exp(x))}), *bracket, _GOLDEN_STEPS)
    cands = [g_best, {**rest, key: float(np.exp(c))}, {**rest, key: float(np.exp(d))}]
    return min(cands, key=run)
