"""Every candidate's fit: screened, the best few confirmed by the joint re-fit (possibly on several processes).

:func:`candidate_fits` screens each candidate (:mod:`synth.gap.attribution.screen`) and re-fits the
best ``confirm`` jointly (:func:`synth.gap.attribution.refit.fit_augmented`), started on the grid
:func:`seeded_grid` builds around the screened point; :func:`confirmed_candidates` says which. A confirmed fit
that is not the effect it names (:func:`synth.gap.attribution.physical.wrong_sign`) gives its place to the next
screened candidate.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from synth.data.record import Record
from synth.errors import ModelError
from synth.gap.attribution.physical import wrong_sign
from synth.gap.attribution.refit import AugmentedFit, fit_augmented
from synth.gap.attribution.screen import ScreenedFit, screen_effect
from synth.gap.effects.base import Effect, Params
from synth.plant import Plant
from synth.worker_pool import map_jobs, watch_parent

__all__ = ["advance", "candidate_fits", "confirmed_candidates", "joint_fit", "map_jobs", "screened_coefficients",
           "seeded_grid", "watch_parent"]


def advance(progress: dict[str, Any] | None, step: str) -> None:
    """Count one finished step of a diagnosis in ``progress`` (``"done"``, and ``"step"`` its name), if given.

    A progress bar reads ``progress["done"]`` against ``progress["total"]`` (see ``synth diagnose``).

    Examples
    --------
    >>> p = {"total": 3}
    >>> advance(p, "re-fit"); advance(p, "screen delay"); p["done"], p["step"]
    (2, 'screen delay')
    """
    if progress is not None:
        progress["done"] = int(progress.get("done", 0)) + 1
        progress["step"] = step


def seeded_grid(effect: Effect, screened: ScreenedFit, u_train: np.ndarray | None = None) -> list[Params]:
    """The joint fit's search grid around a screened fit (:meth:`synth.gap.effects.base.Effect.seed_grid`).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> from synth.gap.effects import make_effect
    >>> screened = SimpleNamespace(params={"tau": 0.5, "sag": 0.1})
    >>> [round(g["tau"], 4) for g in seeded_grid(make_effect("supply_sag"), screened)]
    [0.4348, 0.5, 0.575]
    """
    point = {k: v for k, v in screened.params.items() if k not in effect.basis_names}
    return effect.seed_grid(point, u_train)


def candidate_fits(plant: Plant, effects: list[Effect], refit: AugmentedFit, train: Record, evaluated: Record,
                   confirm: int | None, train_mask: np.ndarray | None = None, workers: int = 1,
                   progress: dict[str, Any] | None = None,
                   ) -> list[tuple[Effect, AugmentedFit | ScreenedFit, np.ndarray, np.ndarray]]:
    """Every candidate's fit on ``train``: joint for all (``confirm=None``) or screened, the best ``confirm`` then joint.

    Each fit is also simulated on ``evaluated`` (the held-out side). Each screen and each joint fit
    counts one step in ``progress`` (:func:`advance`).

    Effects the screen cannot represent (``Effect.screenable`` false: friction, output-side clipping) are
    always fitted jointly.

    Returns
    -------
    list of (Effect, AugmentedFit or ScreenedFit, numpy.ndarray, numpy.ndarray)
        Each fitted candidate, its fit, and its output on the training and on the evaluated record.

    Examples
    --------
    >>> from synth.gap.attribution.refit import fit_augmented
    >>> from synth.gap.effects import make_effect
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 4, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0); G = Plant.from_string("2/(0.2*s+1)")
    >>> y = simulate_plant(G.with_delay(0.05), t, u)
    >>> from synth.data import record_from_arrays
    >>> rec = record_from_arrays(t, u, y)
    >>> fits = candidate_fits(G, [make_effect("delay")], fit_augmented(G, t, u, y), rec, rec, confirm=1)
    >>> [(e.label, type(f).__name__, round(f.params["delay"], 3)) for e, f, _, _ in fits]
    [('delay', 'AugmentedFit', 0.05)]
    """
    t_tr, u_tr, y_tr, t_ev, u_ev = train.t, train.u, train.y, evaluated.t, evaluated.u
    out: list[tuple[Effect, AugmentedFit | ScreenedFit, np.ndarray, np.ndarray]] = []
    weights = None if train_mask is None else train_mask.astype(float)
    if confirm is None:
        for eff in effects:
            try:
                fit = fit_augmented(plant, t_tr, u_tr, y_tr, eff, start=refit.plant, weights=weights)
            except ModelError:
                continue
            finally:
                advance(progress, f"joint fit {eff.label}")
            out.append((eff, fit, fit.predict(t_tr, u_tr), fit.predict(t_ev, u_ev)))
        return out
    bases = [("nominal", plant), ("refit", refit.plant)]
    screened: list[tuple[Effect, ScreenedFit]] = []
    for eff in effects:
        if not eff.screenable:  # the screen holds the input fixed and has no output map: fit these jointly
            try:
                fit = fit_augmented(plant, t_tr, u_tr, y_tr, eff, start=refit.plant, weights=weights)
            except ModelError:
                continue
            finally:
                advance(progress, f"joint fit {eff.label}")
            out.append((eff, fit, fit.predict(t_tr, u_tr), fit.predict(t_ev, u_ev)))
            continue
        try:
            screened.append((eff, screen_effect(eff, bases, t_tr, u_tr, y_tr, t_ev, u_ev, train_mask)))
        except ModelError:
            continue
        finally:
            advance(progress, f"screen {eff.label}")
    screened.sort(key=lambda es: es[1].ssr)
    chosen = confirmed_candidates(screened, confirm)

    def job(i: int) -> tuple[Any, ...]:
        eff, sc = screened[i]
        if i >= (confirm or 0) and sc.params_held:  # confirmed for its held-denominator fit: start there
            sc = replace(sc, params=sc.params_held)
        return plant, t_tr, u_tr, y_tr, eff, refit.plant, weights, seeded_grid(eff, sc, u_tr)

    def confirm_jointly(which: list[int], counted: int) -> dict[int, AugmentedFit | None]:
        if progress is not None:  # `counted` of them were in the total already
            progress["total"] = int(progress.get("total", 0)) + len(which) - counted
        return dict(zip(which, map_jobs(joint_fit, [job(i) for i in which], workers,
                                        lambda k: advance(progress, f"joint fit {screened[which[k]][0].label}"))))

    joints = confirm_jointly(chosen, confirm or 0)  # the diagnosis counted `confirm` joint fits
    # a confirmed fit that is not the effect it names (a resonance without a peak) cannot be the verdict: its place
    # goes to the next screened candidate
    lost = sum(1 for i, f in joints.items() if f is not None and wrong_sign(screened[i][0], f.params, t_tr, u_tr, plant))
    spare = [i for i in range(len(screened)) if i not in joints][:lost]
    if spare:
        joints.update(confirm_jointly(spare, 0))
    for rank, (eff, sc) in enumerate(screened):
        fit: AugmentedFit | ScreenedFit = sc
        joint = joints.get(rank)
        if joint is not None and np.isfinite(joint.ssr):  # the exact model (the screen's SSR is linearized)
            fit = joint
        if isinstance(fit, AugmentedFit):
            out.append((eff, fit, fit.predict(t_tr, u_tr), fit.predict(t_ev, u_ev)))
        else:
            out.append((eff, fit, sc.yhat_train, sc.yhat_eval))
    return out


def confirmed_candidates(screened: list[tuple[Effect, ScreenedFit]], confirm: int) -> list[int]:
    """Which screened candidates (sorted by screened SSR) are re-fitted jointly: the best ``confirm``,
    and the best with the denominator held exactly if it is not among them.

    The screen's Gauss-Newton step in the denominator is linearized: when the gap is large it lets
    every candidate reach about the same SSR, effect or no effect, and the ranking among them is
    noise. With the denominator held, only an effect that explains the gap gets far; it is
    confirmed too (one more joint fit at most).

    Examples
    --------
    >>> from types import SimpleNamespace as S
    >>> sc = [(None, S(ssr=1.0, ssr_held=9.0)), (None, S(ssr=1.1, ssr_held=8.0)), (None, S(ssr=1.2, ssr_held=2.0))]
    >>> confirmed_candidates(sc, 2), confirmed_candidates(sc, 3), confirmed_candidates(sc, 1)
    ([0, 1, 2], [0, 1, 2], [0, 2])
    """
    chosen = list(range(min(confirm, len(screened))))
    held = [i for i in range(len(screened)) if np.isfinite(screened[i][1].ssr_held)]
    if held:
        best = min(held, key=lambda i: screened[i][1].ssr_held)
        if best not in chosen:
            chosen.append(best)
    return chosen


def joint_fit(job: tuple[Any, ...]) -> AugmentedFit | None:
    """One confirmation: the joint re-fit of an effect on its seeded grid (``None`` if no point could be fitted).

    ``job`` is ``(plant, t, u, y, effect, start, weights, grid)`` (a tuple, to be sent to a worker process).

    Examples
    --------
    >>> from synth.gap.effects import make_effect
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 4, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0); G = Plant.from_string("2/(0.2*s+1)")
    >>> y = simulate_plant(G.with_delay(0.05), t, u)
    >>> round(joint_fit((G, t, u, y, make_effect("delay"), G, None, [{"delay": 0.04}])).params["delay"], 3)
    0.05
    """
    plant, t, u, y, eff, start, weights, grid = job
    try:
        return fit_augmented(plant, t, u, y, eff, start=start, weights=weights, grid=grid)
    except ModelError:
        return None


def screened_coefficients(plant: Plant) -> dict[str, float]:
    """The nominal coefficients of a screened fit's linear model, named as the joint fit names them, and its delay.

    Examples
    --------
    >>> sorted(screened_coefficients(Plant.from_string("2/(0.2*s+1)")))
    ['d0', 'delay', 'n0']
    """
    from synth.gap.attribution.nominal import nominal_structure

    return nominal_structure(plant)[1] | {"delay": plant.delay}
