"""Forward selection: a further effect fitted on top of the accepted one, judged on held-out data.

Every other candidate is screened on top of the accepted effect
(:class:`synth.gap.attribution.composite.NestedEffect`, the accepted effect's parameters fixed; an
effect that ``folds_into_plant``, the extra delay, is folded into the linear model instead), the best
two are re-fitted jointly with the nominal coefficients, and the better one is judged against the
model before it, or against its own fit with the further effect switched off where that is better: an effect
gets no credit for what the re-fit of the nominal coefficients alone gains.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from synth.data.record import Record
from synth.errors import ModelError
from synth.gap.attribution.candidates import joint_fit, map_jobs, seeded_grid
from synth.gap.attribution.parsimony import share_of_excess
from synth.gap.attribution.physical import wrong_sign
from synth.gap.attribution.refit import AugmentedFit
from synth.gap.attribution.screen import ScreenedFit, screen_effect
from synth.gap.attribution.verdict import EffectResult
from synth.gap.effects.base import Effect
from synth.plant import Plant

__all__ = ["ForwardSelection"]


@dataclass(frozen=True)
class _Folded:
    """``first`` (an extra delay) folded into the linear model, ``second`` fitted alone on top of it."""

    first: Effect
    second: Effect

    @property
    def label(self) -> str:
        return f"{self.first.label}+{self.second.label}"


class ForwardSelection:
    """Forward selection: the best further effect on top of the accepted ones, judged on held-out data.

    Built by :func:`synth.gap.attribution.heldout.diagnose_effects` with the training and evaluated
    records, the held-out segment sums ``sums(yhat)``, the bootstrap interval ``ratio_ci(s_a, s_b)`` and
    the acceptance rule (calibrated ``threshold``, ``min_share`` of the excess over the noise ``floor``).
    :meth:`next` returns ``(nested effect, fit, EffectResult, held-out output, segment sums)`` of the best
    further effect, or ``None`` when none can be fitted.

    Examples
    --------
    >>> from synth.gap.attribution.refit import fit_augmented
    >>> from synth.gap.effects import make_effect
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 4, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0); G = Plant.from_string("2/(0.2*s+1)")
    >>> y = simulate_plant(G.with_delay(0.05), t, u)
    >>> from synth.data import record_from_arrays
    >>> rec = record_from_arrays(t, u, y)
    >>> fs = ForwardSelection(G, rec, rec, None, None, lambda yh: np.array([np.sum((y - yh) ** 2)]),
    ...                       lambda a, b: (0.0, 0.0), 0.1, 0.25, 1e-6, t.size)
    >>> fs.next(make_effect("delay"), fit_augmented(G, t, u, y, make_effect("delay")), np.array([1.0]), []) is None
    True
    """

    def __init__(self, plant: Plant, train: Record, evaluated: Record, weights: np.ndarray | None,
                 train_mask: np.ndarray | None, sums: Any, ratio_ci: Any, threshold: float, min_share: float,
                 floor: float, n_held: int, workers: int = 1) -> None:
        self.plant, self.t_tr, self.u_tr, self.y_tr = plant, train.t, train.u, train.y
        self.t_ev, self.u_ev = evaluated.t, evaluated.u
        self.weights, self.train_mask, self.sums, self.ratio_ci = weights, train_mask, sums, ratio_ci
        self.threshold, self.min_share, self.floor, self.n_held = threshold, min_share, floor, n_held
        self.workers = workers

    def next(self, eff_a: Effect, fit_a: AugmentedFit, s_a: np.ndarray, pool: list[Effect],
             keep: int = 2) -> tuple[Effect, AugmentedFit, EffectResult, np.ndarray, np.ndarray] | None:
        """Screen every effect of ``pool`` on top of ``eff_a``, re-fit the best ``keep`` jointly, judge the best."""
        from synth.gap.attribution.composite import NestedEffect

        fixed = {k: float(v) for k, v in fit_a.params.items()}
        base_plant = fit_a.plant
        folded = eff_a.folds_into_plant  # an extra delay folds into the linear model: B alone on top of it
        if folded:
            base_plant = fit_a.plant.with_delay(fit_a.plant.delay + fixed.get("delay", 0.0))
        screened: list[tuple[Effect, ScreenedFit | None]] = []
        for eff_b in pool:
            try:
                nested = _Folded(eff_a, eff_b) if folded else NestedEffect(eff_a, fixed, eff_b)
                bases = [("accepted", base_plant)]
                model = nested.second if folded else nested
                sc = screen_effect(model, bases, self.t_tr, self.u_tr, self.y_tr, self.t_ev, self.u_ev,
                                   self.train_mask) if model.screenable else None
            except ModelError:
                continue
            screened.append((nested, sc))
        screened.sort(key=lambda es: es[1].ssr if es[1] is not None else -np.inf)
        best: tuple[Effect, AugmentedFit, np.ndarray, np.ndarray] | None = None
        jobs = []
        for nested, sc in screened[:keep]:
            model = nested.second if folded else nested
            grid = seeded_grid(model, sc, self.u_tr) if sc is not None else None
            jobs.append((base_plant if folded else self.plant, self.t_tr, self.u_tr, self.y_tr, model, base_plant,
                         self.weights, grid))
        for (nested, _), fit in zip(screened[:keep], map_jobs(joint_fit, jobs, self.workers)):
            if fit is None:
                continue
            yhat = fit.predict(self.t_ev, self.u_ev)
            s = self.sums(yhat)
            if np.isfinite(s.sum()) and (best is None or s.sum() < best[3].sum()):
                best = (nested, fit, yhat, s)
        if best is None:
            return None
        nested, fit, yhat, s = best
        second = nested.second
        # the joint fit re-fits the nominal coefficients too: what that alone gains over the accepted model (the
        # fit with the second effect switched off) is not the second effect's credit
        alone = self.sums(replace(fit, params={**fit.params, **second.off()}).predict(self.t_ev, self.u_ev))
        if np.isfinite(alone.sum()) and alone.sum() < s_a.sum():
            s_a = alone
        j_a, j = float(s_a.sum() / self.n_held), float(s.sum() / self.n_held)
        ci = self.ratio_ci(s, s_a)
        share = share_of_excess(j_a, j, self.floor)
        significant = bool(ci[0] > self.threshold)
        params = {k: float(fit.params[k]) for k in second.parameter_names}
        unphysical = wrong_sign(second, params, self.t_tr, self.u_tr, self.plant)
        accepted = bool(significant and share >= self.min_share and not unphysical)
        res = EffectResult(nested.label, params, dict(fit.parameter_ci), 1.0 - j / j_a if j_a > 0 else 0.0, ci,
                           significant, float(share), accepted, j, dict(fit.nominal), "joint", unphysical)
        return nested, fit, res, yhat, s
