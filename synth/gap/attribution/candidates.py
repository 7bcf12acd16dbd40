"""Every candidate's fit: screened, the best few confirmed by the joint re-fit (possibly on several processes).

:func:`candidate_fits` screens each candidate (:mod:`synth.gap.attribution.screen`) and re-fits the
best ``confirm`` jointly (:func:`synth.gap.attribution.refit.fit_augmented`), started on the grid
:func:`seeded_grid` builds around the screened point; :func:`confirmed_candidates` says which.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from synth.data.record import Record
from synth.errors import ModelError
from synth.gap.attribution.refit import AugmentedFit, fit_augmented
from synth.gap.attribution.screen import ScreenedFit, screen_effect
from synth.gap.effects.base import Effect, Params
from synth.plant import Plant

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
    jobs = []
    for i in chosen:
        eff, sc = screened[i]
        if i >= (confirm or 0) and sc.params_held:  # confirmed for its held-denominator fit: start there
            sc = replace(sc, params=sc.params_held)
        jobs.append((plant, t_tr, u_tr, y_tr, eff, refit.plant, weights, seeded_grid(eff, sc, u_tr)))
    if progress is not None:  # the joint fits were counted as `confirm` steps; there may be one more
        progress["total"] = int(progress.get("total", 0)) + len(chosen) - (confirm or 0)
    joints = dict(zip(chosen, map_jobs(joint_fit, jobs, workers,
                                       lambda i: advance(progress, f"joint fit {screened[chosen[i]][0].label}"))))
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


def watch_parent(parent: int) -> None:
    """Make this (worker) process die with its parent ``parent``; leave signals to the parent.

    On Linux the kernel sends SIGKILL when the parent dies (``prctl(PR_SET_PDEATHSIG)``, even when the
    parent is killed by SIGKILL); elsewhere a daemon thread checks the parent's pid every second. SIGINT
    is ignored (a Ctrl-C reaches the whole process group: the parent handles it and terminates the
    workers) and SIGTERM has its default action.

    Examples
    --------
    It runs first in every worker of :func:`map_jobs`:

    >>> map_jobs(abs, [-1, -2], workers=2)
    [1, 2]
    """
    import os
    import signal
    import sys
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    armed = False
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(1, int(signal.SIGKILL), 0, 0, 0) == 0  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):
            armed = False
    if os.getppid() != parent:  # the parent died before the watch was set
        os._exit(1)
    if armed:
        return

    def check() -> None:
        import time

        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=check, daemon=True).start()


def map_jobs(fn: Any, jobs: list[Any], workers: int, done: Any = None) -> list[Any]:
    """``[fn(j) for j in jobs]``, on ``workers`` processes when there are several jobs.

    ``done(i)``, if given, is called in this process as job ``i`` finishes (in order).

    The workers die with this process (:func:`watch_parent`: a SIGKILL of the parent leaves none
    behind), and any exception here, a KeyboardInterrupt or the exception a signal handler raises
    included, terminates them before it propagates.

    Examples
    --------
    >>> map_jobs(abs, [-1, 2, -3], workers=1)
    [1, 2, 3]
    """
    if workers <= 1 or len(jobs) <= 1:
        out = []
        for i, j in enumerate(jobs):
            out.append(fn(j))
            if done is not None:
                done(i)
        return out
    import multiprocessing
    import os

    forked = "fork" in multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if forked else None)
    if forked:  # the workers inherit the jobs: only their indices go through the task pipe (see _inherited_job)
        _INHERITED[:] = [fn, jobs]
        fn, jobs = _inherited_job, list(range(len(jobs)))
    pool = context.Pool(min(workers, len(jobs)), initializer=watch_parent, initargs=(os.getpid(),))
    try:
        out = []
        for i, res in enumerate(pool.imap(fn, jobs, chunksize=1)):
            out.append(res)
            if done is not None:
                done(i)
        pool.close()
        return out
    except BaseException:
        pool.terminate()
        raise
    finally:
        pool.join()
        _INHERITED.clear()


_INHERITED: list[Any] = []  # the function and jobs of the running map_jobs, inherited by its forked workers


def _inherited_job(index: int) -> Any:
    """Run job ``index`` of the :func:`map_jobs` call that forked this worker.

    Sending the jobs themselves (records of hundreds of thousands of samples) through the pool's task pipe
    filled it: the pool's task thread then blocked on a write that no terminated worker would read, and
    ``Pool.terminate`` waited for that thread forever (a SIGTERM during the attribution hung ``synth
    diagnose``). An index never fills the pipe.

    Examples
    --------
    >>> _INHERITED[:] = [abs, [-4]]
    >>> _inherited_job(0)
    4
    >>> _INHERITED.clear()
    """
    fn, jobs = _INHERITED
    return fn(jobs[index])


def screened_coefficients(plant: Plant) -> dict[str, float]:
    """The nominal coefficients of a screened fit's linear model, named as the joint fit names them, and its delay.

    Examples
    --------
    >>> sorted(screened_coefficients(Plant.from_string("2/(0.2*s+1)")))
    ['d0', 'delay', 'n0']
    """
    from synth.gap.attribution.nominal import nominal_structure

    return nominal_structure(plant)[1] | {"delay": plant.delay}
