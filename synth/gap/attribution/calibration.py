"""Calibration: the noise floor, and what a perfect model gains over the re-fit by chance.

The noise floor ``sigma^2`` is the robust variance of the re-fit's residual's second difference
(:func:`noise_sigma`). The calibrated threshold is a quantile of the held-out shrinkage a *perfect*
model achieves against the re-fit on records simulated from the re-fit plus white noise
(parametric bootstrap): :func:`linearized_null` takes one Gauss-Newton step per replicate,
:func:`refit_null` repeats the casadi re-fit.
"""

from __future__ import annotations

import numpy as np

from synth.gap.attribution.refit import AugmentedFit, fit_augmented
from synth.ident.noise_floor import noise_sigma
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["demean", "linearized_null", "noise_sigma", "refit_null"]


def demean(x: np.ndarray, groups: np.ndarray | None = None) -> np.ndarray:
    """``x`` (samples along the first axis) less its mean, per group (run) when ``groups`` is given.

    Examples
    --------
    >>> demean(np.array([1.0, 3.0, 10.0, 12.0]), np.array([0, 0, 1, 1])).tolist()
    [-1.0, 1.0, -1.0, 1.0]
    """
    if groups is None:
        return x - x.mean(axis=0)
    out = np.array(x, float, copy=True)
    for g in np.unique(groups):
        sel = groups == g
        out[sel] -= out[sel].mean(axis=0)
    return out


def _sensitivity(plant: Plant, t: np.ndarray, u: np.ndarray) -> np.ndarray:
    """d(simulated output)/d(each nonzero coefficient, monic denominator) and d/d(offset), central differences."""
    cols = []
    for which in ("num", "den"):
        base = getattr(plant, which)
        for i, c in enumerate(base):
            if c == 0.0 or (which == "den" and i == 0):
                continue
            h = 1e-6 * max(abs(c), 1e-8)
            out = []
            for sgn in (1.0, -1.0):
                arr = base.astype(float).copy()
                arr[i] += sgn * h
                num, den = (arr, plant.den) if which == "num" else (plant.num, arr)
                out.append(simulate_plant(Plant(num, den, plant.delay), t, u))
            cols.append((out[0] - out[1]) / (2 * h))
    cols.append(np.ones_like(t))
    return np.column_stack(cols)


def linearized_null(refit: AugmentedFit, t_tr: np.ndarray, u_tr: np.ndarray, t_ev: np.ndarray, u_ev: np.ndarray,
                     held: np.ndarray, split: bool, sigma: float, n_null: int,
                     rng: np.random.Generator, train_mask: np.ndarray | None = None,
                     fit_offset: bool = False, groups: np.ndarray | None = None) -> np.ndarray:
    """Held-out shrinkage of a perfect model against the re-fit, re-fit linearized (Gauss-Newton step).

    ``split``: the training record is the start of the evaluated one; ``train_mask``: the training
    samples that count in the fit's cost (default all); ``fit_offset``: both held-out residuals have
    their mean removed (the offset re-estimated on held-out data), per run with ``groups``.

    Examples
    --------
    >>> from synth.gap.attribution.refit import fit_augmented
    >>> t = np.arange(0, 4, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0); G = Plant.from_string("2/(0.2*s+1)")
    >>> refit = fit_augmented(G, t[:200], u[:200], simulate_plant(G, t[:200], u[:200]))
    >>> null = linearized_null(refit, t[:200], u[:200], t, u, t >= 2, True, 0.01, 50, np.random.default_rng(0))
    >>> null.shape, bool(abs(np.median(null)) < 0.05)  # a perfect model barely beats the re-fit
    ((50,), True)
    """
    J_ev = _sensitivity(refit.plant, t_ev, u_ev)
    J_tr = J_ev[:t_tr.size] if split else _sensitivity(refit.plant, t_tr, u_tr)
    if train_mask is not None:
        J_tr = J_tr[train_mask]
    n_tr = sigma * rng.standard_normal((J_tr.shape[0], n_null))
    scale = np.maximum(np.sqrt(np.sum(J_tr**2, axis=0)), 1e-300)
    delta = np.linalg.lstsq(J_tr / scale, n_tr, rcond=None)[0] / scale[:, None]
    noise = sigma * rng.standard_normal((int(held.sum()), n_null))
    e_fit = noise - J_ev[held] @ delta
    if fit_offset:
        noise, e_fit = demean(noise, groups), demean(e_fit, groups)
    return 1.0 - np.mean(noise**2, axis=0) / np.mean(e_fit**2, axis=0)


def refit_null(refit: AugmentedFit, t_tr: np.ndarray, u_tr: np.ndarray, t_ev: np.ndarray, u_ev: np.ndarray,
                held: np.ndarray, split: bool, sigma: float, n_null: int, rng: np.random.Generator,
                train_mask: np.ndarray | None = None, fit_offset: bool = False,
                groups: np.ndarray | None = None) -> np.ndarray:
    """The same as :func:`linearized_null` with the casadi re-fit repeated on every replicate.

    Examples
    --------
    >>> from synth.gap.attribution.refit import fit_augmented
    >>> t = np.arange(0, 4, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0); G = Plant.from_string("2/(0.2*s+1)")
    >>> refit = fit_augmented(G, t[:200], u[:200], simulate_plant(G, t[:200], u[:200]))
    >>> refit_null(refit, t[:200], u[:200], t, u, t >= 2, True, 0.01, 2, np.random.default_rng(0)).shape
    (2,)
    """
    null = []
    y_ref = refit.predict(t_ev, u_ev)
    y_ref_tr = refit.predict(t_tr, u_tr)
    weights = None if train_mask is None else train_mask.astype(float)
    for _ in range(n_null):
        n_tr = sigma * rng.standard_normal(t_tr.size)
        noise = np.r_[n_tr, sigma * rng.standard_normal(t_ev.size - t_tr.size)] if split else \
            sigma * rng.standard_normal(t_ev.size)
        fit_b = fit_augmented(refit.plant, t_tr, u_tr, y_ref_tr + n_tr, weights=weights)
        e_fit, e_true = (y_ref + noise - fit_b.predict(t_ev, u_ev))[held], noise[held]
        if fit_offset:
            e_fit, e_true = demean(e_fit, groups), demean(e_true, groups)
        j_fit, j_true = float(np.mean(e_fit**2)), float(np.mean(e_true**2))
        null.append(1.0 - j_true / j_fit)
    return np.asarray(null)
