"""A whole-record fit whose record does not start at rest: fitted again from where the start state has died out.

:mod:`synth.ident.start_state` tests every whole-record fit for a start state that matters; here such a fit is
repeated with the samples weighted 0 (simulated from rest, not fitted) until the estimated free response has less
energy left than one noise variance, at most a quarter of the samples left per round, from the previous fit's
parameters, and tested again from its first fitted sample, for at most :data:`ROUNDS` refits, leaving out at most
:data:`KEEP` of the record. The refits' covariance carries the state at their first fitted sample as a nuisance
(``fit_structure(..., free_start=True)``): what is left of the start state there is unknown too.

A start state that only *may* matter (:attr:`~synth.ident.start_state.StartState.masked`: significant, but not
against a threshold inflated by residuals that are far from white, which a fit bent into another basin leaves
everywhere) is left out only where the first refit without it is better, on the samples both fit, by more than the
chi-square quantile at :data:`~synth.ident.start_state.ALPHA` with as many degrees of freedom as parameters;
otherwise the fit from rest stands (``solver["start_state_refit"]`` says why).
"""

from __future__ import annotations

import numpy as np

from synth.data.record import Record
from synth.errors import DataError, FitError
from synth.ident.misfit import does_not_explain, times_the_noise
from synth.ident.start_state import ALPHA, StartState
from synth.ident.structure import Structure
from synth.ident.timefit import TimeFitResult, fit_structure
from synth.plant import Plant

__all__ = ["KEEP", "ROUNDS", "fit_from_unknown_start"]

ROUNDS = 4
"""Refits at most; each starts where the previous fit's estimated free response had died out."""

KEEP = 0.75
"""The refits leave out at most this share of the record."""


def fit_from_unknown_start(record: Record, fit: TimeFitResult, structure: Structure, delay: str | float | None,
                           sensor: Plant | str | None) -> tuple[TimeFitResult, str]:
    """``fit`` (of the whole ``record`` from rest) where its start state does not matter
    (``fit.solver["start_state"]``); else the record fitted again without its first samples, as above.
    Returns the fit and a note (``""`` for the fit as given; otherwise also in ``solver["start_state_note"]``).

    Raises
    ------
    FitError
        The start state still matters after :data:`ROUNDS` refits, or more than :data:`KEEP` of the record would be
        left out.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.structure import parse_structure
    >>> from scipy import signal
    >>> t = np.arange(0.0, 30.0, 0.01); rng = np.random.default_rng(1)
    >>> u = np.repeat(rng.normal(size=300), 10)
    >>> sys = signal.StateSpace([[-0.5]], [[1.0]], [[1.0]], [[0.0]])   # k = 1, p = 0.5
    >>> y = signal.lsim(sys, u, t, X0=[4.0], interp=False)[1] + 0.01 * rng.normal(size=t.size)
    >>> record = record_from_arrays(t, u, y)
    >>> first = fit_structure(record, "k/(s+p)")
    >>> round(abs(first.parameters["p"] - 0.5) / first.std["p"])     # the fit from rest: biased
    37
    >>> fit, note = fit_from_unknown_start(record, first, parse_structure("k/(s+p)"), None, None)
    >>> note[:35], bool(abs(fit.parameters["p"] - 0.5) < 3 * fit.std["p"])
    ('the record does not start at rest: ', True)
    """
    test = StartState.from_dict(fit.solver["start_state"]) if "start_state" in fit.solver else None
    if test is None or not (test.matters or test.masked):
        return fit, ""
    from scipy.stats import chi2  # here: importing scipy.stats costs 0.2 s that a record starting at rest need not pay
    first_test, fitted, why, original = test, 0.0, f"after {ROUNDS} refits", fit
    for round_ in range(ROUNDS):
        # the window comes from a fit the start state bent, whose modes may be far too slow: a quarter of what is
        # left at most per round, the next round's fit (less bent) tells the rest
        skip = test.first + min(max(test.window, 2.0 * record.dt), 0.25 * (record.duration - test.first))
        if skip > KEEP * record.duration:
            why = f"and leaving out {skip:.3g} s would keep less than {1 - KEEP:.0%} of the record"
            break
        weights = ((record.t - record.t[0]) >= skip - 1e-9 * record.dt).astype(float)
        if original.weights is not None and original.weights.shape == weights.shape:
            weights = weights * original.weights  # what the fit left out already (e.g. after a gap in the log)
        try:
            fit = _refit(record, structure, delay, sensor, weights, fit, alternative=round_ == 0)
        except (DataError, FitError) as exc:
            if round_ == 0 and first_test.masked:
                return original, ""  # a start that only may matter, and no fit without it to show that it does
            why = exc.message.removeprefix(f"fit of {structure.formula!r} failed: ")
            raise FitError(f"fit of {structure.formula!r} failed: the record does not start at rest (its start state "
                           f"would move {first_test.shifted} by {first_test.shift:.3g} std) and the fit after its first "
                           f"{skip:.3g} s failed: {why}{_misfit(original, first_test)}", where=record.source,
                           status=getattr(exc, "status", None)) from None
        gain = _gain_without_start(original, fit)
        if round_ == 0 and first_test.masked and not gain > float(chi2.isf(ALPHA, len(fit.names))):
            original.solver["start_state_refit"] = (f"without its first {skip:.3g} s the fit is no better on the "
                                                    f"samples both fit ({gain:.3g} noise variances): kept")
            return original, ""
        fitted, test = skip, StartState.from_dict(fit.solver["start_state"])
        if not test.matters:
            masked = "" if not first_test.masked else (
                f" (above the threshold scaled by {first_test.inflation:.3g} for residuals that are not white; the fit "
                f"without the start is better by {gain:.3g} noise variances on the samples both fit)")
            note = (f"the record does not start at rest: the fitted model's free response from an unknown start "
                    f"state takes {first_test.statistic:.3g} noise variances out of the residual (threshold "
                    f"{first_test.threshold / first_test.inflation:.3g}, chi-square with {first_test.dof} degrees of "
                    f"freedom at {ALPHA:g}){masked} and would move {first_test.shifted} by {first_test.shift:.3g} std; "
                    f"fitted from {test.first:.4g} s on, the samples before simulated from rest and weighted 0"
                    f"{_misfit(original, first_test)}")
            fit.solver["start_state_note"] = note
            return fit, note
    raise FitError(f"fit of {structure.formula!r} failed: the record does not start at rest, and its start state "
                   f"still moves {test.shifted} by {test.shift:.3g} std with the first {fitted:.3g} s left out, {why}; "
                   f"cut the record to start at rest, or fit a shorter part of it{_integrating_hint(original, record)}"
                   f"{_misfit(original, first_test)}", where=record.source)


def _integrating_hint(fit: TimeFitResult, record: Record) -> str:
    """For an integrating model whose record's input is not 0 at its first sample: how that sample is read."""
    if np.isfinite(fit.plant.dc_gain()) or float(record.u[0]) == 0.0:
        return ""
    return (f" (an integrating model is at rest only where its input holds the output still: the first input "
            f"sample, {float(record.u[0]):.4g}, is taken as that trim; a record whose input steps to it at its first "
            "sample from 0 needs the samples before the step)")


def _misfit(fit: TimeFitResult, test: StartState) -> str:
    """A clause for the result: the fit does not explain the record even with its start state free (then the
    structure, not the start, is what the start-state test sees), else ``""``."""
    rows = slice(None) if fit.weights is None else fit.weights > 0
    ratio = does_not_explain(fit.y[rows], test.left_std)
    return (f"; but with its start state free the fit still leaves residuals {times_the_noise(ratio)} the record's "
            "noise: a structure that does not explain the record moves its parameters as a start state would "
            "(another structure, or a gain parameter, may be what it lacks)" if ratio else "")


def _refit(record: Record, structure: Structure, delay: str | float | None, sensor: Plant | str | None,
           weights: np.ndarray, fit: TimeFitResult, alternative: bool) -> TimeFitResult:
    """The record fitted with ``weights`` from ``fit``'s parameters; with ``alternative`` also from the deterministic
    start (a start state may have bent ``fit`` into another basin, which a refit from it keeps), the lower residual
    kept. Raises the first start's error when neither succeeds."""
    options = dict(weights=weights, check=True, free_start=True)
    starts = [{**fit.parameters}, None] if alternative else [{**fit.parameters}]
    fits: list[TimeFitResult] = []
    errors: list[DataError | FitError] = []
    for initial in starts:  # None: the deterministic start
        try:
            fits.append(fit_structure(record, structure, delay, sensor, False, initial=initial, **options))
        except (DataError, FitError) as exc:
            errors.append(exc)
    if not fits:
        raise errors[0]
    return min(fits, key=lambda f: f.residual_std)


def _gain_without_start(original: TimeFitResult, refit: TimeFitResult) -> float:
    """How much lower the refit's residual energy is than the original fit's on the samples the refit fits, in the
    refit's noise variances (chi-square with as many degrees of freedom as parameters where both fit the same)."""
    mask = refit.weights > 0 if refit.weights is not None else np.ones(refit.t.size, dtype=bool)
    before, after = original.residuals[mask], refit.residuals[mask]
    noise = refit.residual_std ** 2
    return float(before @ before - after @ after) / noise if noise > 0 else float("inf")
