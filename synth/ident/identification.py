"""Identify a structure from a record: average a step train, fit, and compare up and down steps.

:func:`identify` is the entry point behind ``synth identify`` and :func:`synth.identify`: a two-level input with
several steps is averaged (:mod:`synth.ident.steps`), the structure is fitted to the average
(:func:`synth.ident.timefit.fit_structure`), and when the train has up and down steps they are also fitted apart and
compared (:mod:`synth.ident.directions`): a difference beyond their uncertainty is reported, and ``by_direction=True``
makes the two fits the result. A clipped output is named in the record's notes (:mod:`synth.ident.clipped_output`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.data.coerce import RecordLike, as_record
from synth.data.record import Record
from synth.errors import DataError, FitError, ModelError
from synth.ident.clipped_output import with_clipping_note
from synth.ident.delay_alias import ambiguity_note, fixed_delay_note, whole_record_start
from synth.ident.directions import DirectionComparison, fit_by_direction, too_unsettled
from synth.ident.edge_check import EDGE_MISFIT, edge_misfit
from synth.ident.fit_failure import NO_RESPONSE
from synth.ident.nyquist import beyond_nyquist
from synth.ident.pair_relocation import relocate_pair
from synth.ident.periodic_start import after_gaps, fit_whole_record, refit_periodic_start, settling_time, start_up_weights
from synth.ident.steps import StepAverage, average_steps, find_steps
from synth.ident.structure import Structure, parse_structure
from synth.ident.timefit import TimeFitResult, fit_structure
from synth.ident.unknown_start import fit_from_unknown_start
from synth.plant import Plant

__all__ = ["IdentifyResult", "identify", "settling_time"]


@dataclass(frozen=True, eq=False)
class IdentifyResult:
    """Identification of a record: the step averaging (if any) and the fit.

    Attributes
    ----------
    record : Record
        The record as given.
    fit : TimeFitResult
        The fit (of the average, or of the whole record; see ``whole_record_note``).
    average : StepAverage or None
        The step averaging, if the input was a step train.
    directions : DirectionComparison or None
        Up-step and down-step fits and their comparison (a train with both directions).
    direction_note : str
        Why the directions were not compared, if they could not be.
    by_direction : bool
        The up and down fits are the result (a direction-dependent model was asked for).
    whole_record_note : str
        Set when the edge windows were too short for the model to settle and the whole record was fitted, or when a
        whole-record fit left out a start state that was not at rest (:mod:`synth.ident.unknown_start`).

    Examples
    --------
    >>> from synth.ident.x4_record import x4_step_train, SENSOR
    >>> clean = x4_step_train(periods=1, noise_std=0.0)  # noise-free, fitted as it is (no averaging)
    >>> res = identify(clean, "k*(s+z)/((s+p1)*(s+p2))", delay="fit", sensor=SENSOR, average="none")
    >>> sorted(round(v, 5) for v in res.fit.parameters.values())
    [0.02, 0.43, 0.54, 9.6, 23.0]
    """

    record: Record
    fit: TimeFitResult
    average: StepAverage | None
    directions: DirectionComparison | None = None
    direction_note: str = ""
    by_direction: bool = False
    whole_record_note: str = ""

    @property
    def plant(self) -> Plant:
        """The identified plant ``F`` (with its delay; with ``by_direction``, the fit of both directions together)."""
        return self.fit.plant

    @property
    def direction_dependent(self) -> bool:
        """Up and down steps differ beyond their uncertainty."""
        return self.directions is not None and self.directions.significant

    def to_dict(self) -> dict[str, Any]:
        """The fit's JSON plus ``record``, ``averaging`` and ``directions`` (up/down fits and their comparison)."""
        return {**self.fit.to_dict(), "record": self.record.to_dict(), "averaging": self.average and self.average.to_dict(),
                "directions": self.directions and self.directions.to_dict(), "direction_note": self.direction_note,
                "by_direction": self.by_direction, "whole_record": self.whole_record_note}


def _two_level(u: np.ndarray) -> bool:
    """At least 98 % of the samples near one of the input's two extremes, not counting a lone sample between
    them at a level change (an edge inside a sample interval of a resampled record holds the interval's mean)."""
    lo, hi = float(np.min(u)), float(np.max(u))
    near = (np.abs(u - lo) <= 0.05 * (hi - lo)) | (np.abs(u - hi) <= 0.05 * (hi - lo))
    lone = np.zeros(u.size, dtype=bool)
    lone[1:-1] = ~near[1:-1] & near[:-2] & near[2:]
    return bool(np.mean(near | lone) >= 0.98)


def identify(record: RecordLike, structure: Structure | str, delay: str | float | None = None,
             sensor: Plant | str | None = None, average: str = "auto", by_direction: bool = False,
             compare_directions: bool = True) -> IdentifyResult:
    """Identify a structure from a record: average a step train if there is one, then fit.

    Parameters
    ----------
    record : Record, tuple of arrays, ndarray, mapping, DataFrame, str or Path
        What :func:`synth.data.as_record` accepts: ``(t, u, y)`` arrays, an N x 3 array,
        columns (taken as time, input, output in that order), a CSV/MAT path or a Record.
    structure : Structure or str
    delay : {"fit", float, None}
        See :func:`synth.ident.timefit.fit_structure`.
    sensor : Plant or str, optional
        Known sensor in series.
    average : {"auto", "cycle", "edge", "none"}
        ``"auto"``: a two-level input with at least two steps is averaged
        (:func:`synth.ident.steps.average_steps`), anything else is fitted as it is.
        A periodic train that starts after the input has been constant for longer than the fitted
        model's settling time is refitted on the whole record from the periodic fit (the start-up
        transient from rest carries information that the periodic average drops; the constant
        start, up to one settling time, is weighted 0; ``whole_record_note`` says so). When the
        periodic fit's model settles slower than that and has a weakly identifiable parameter, the
        whole record is fitted all the same and kept if its own model settles within the constant
        start.
        Edge windows assume the plant at rest before each step: when the fitted model's
        settling time (:func:`settling_time`) is longer than a window, the whole record is
        fitted instead, started from the edge fit, with its start-up (one settling time, at most
        a quarter of the record) weighted 0 (``whole_record_note`` says so).
        An averaged train with up and down steps is also fitted per direction and the two
        fits compared (:func:`synth.ident.directions.fit_by_direction`); if that comparison
        cannot be made the reason is in ``direction_note``.
    compare_directions : bool
        ``False`` skips that comparison (two more fits; e.g. in a Monte Carlo study of the fit itself).
    by_direction : bool
        Fit a direction-dependent model: the up-step and down-step fits are the result
        (``directions``); a failure of either is an error. Needs a step train with both.

    Returns
    -------
    IdentifyResult

    Raises
    ------
    DataError
        ``record`` is not a record, or its columns fail the record's checks; ``by_direction``
        on a record without up and down steps.
    FitError
        The fit failed (:func:`synth.ident.fit_failure.fit_failure`).

    Examples
    --------
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 3, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(s+3)"), t, u)
    >>> identify((t, u, y), "k/(s+p)", average="none").plant.to_string(4)
    '2/(s+3)'
    """
    record = with_clipping_note(as_record(record))  # a linear fit reads a clipped output as the plant's
    if average not in ("auto", "cycle", "edge", "none"):
        raise ModelError(f"average must be 'auto', 'cycle', 'edge' or 'none', got {average!r}")
    _check_fixed_delay(delay, record)
    avg = None
    data, periodic, not_averaged = record, False, ""
    if isinstance(structure, str):
        structure = parse_structure(structure)
    integrates = _integrates(structure)
    if average == "auto" and integrates and _two_level(record.u):  # a periodic average needs a steady state
        not_averaged = "not averaged as a step train (the structure integrates: no periodic state): fitted as it is"
    elif average != "none" and _two_level(record.u):
        steps = find_steps(record)
        if steps.count >= 2 or average in ("cycle", "edge"):
            try:
                avg = average_steps(record, steps, "auto" if average == "auto" else average)
                data, periodic = avg.record(), avg.periodic
            except DataError as exc:  # e.g. levels held 3 samples: what was not asked for is not an error
                if average != "auto":
                    raise
                not_averaged = f"not averaged as a step train ({exc.message}): fitted as it is"
    two_ways = avg is not None and bool(np.any(avg.steps.direction > 0) and np.any(avg.steps.direction < 0))
    if by_direction and not two_ways:
        raise DataError("by direction needs a step train with up and down steps (averaged, not average='none')",
                        where=record.source)
    whole = ""
    try:
        fit = fit_structure(data, structure, delay, sensor, periodic, check=True)
        failed = "" if avg is None else _implausible_average_fit(fit, record.dt)
    except FitError as exc:
        if avg is None or average != "auto" or by_direction:
            raise
        failed, fit, error = str(exc), None, exc
    if failed and average == "auto" and not by_direction:
        # the average's fit failed (e.g. IPOPT at its limit on a few short edge windows, or a diverged pole):
        # the whole record, which holds the same steps and assumes less, from its own deterministic start
        def both_failed(whole_error: FitError) -> FitError:
            average_failed = failed.removeprefix("its ") if fit is not None else f"fit failed ({failed})"
            return FitError(f"fit of {structure.formula!r} failed: the {avg.mode} average's {average_failed}, and "
                            f"the whole record's fit failed too ({whole_error}); try another structure, a fixed delay "
                            "or a shorter part of the record", where=record.source)

        try:
            whole_fit = fit_structure(record, structure, delay, sensor, False, check=True)
        except FitError as whole_error:
            if fit is None:
                raise error from None  # both failed: the average's reason is the one to read
            raise both_failed(whole_error) from None
        if not _unstable(whole_fit.measured):
            whole_fit = _other_pair_minima(record, whole_fit, structure, delay, sensor)
            whole_fit = _settle_after_hidden_edges(record, whole_fit, structure, delay, sensor)
            try:  # it too assumes the plant at rest at the first input sample
                whole_fit, from_later = fit_from_unknown_start(record, whole_fit, structure, delay, sensor)
            except FitError as whole_error:
                raise both_failed(whole_error) from None
            return IdentifyResult(record, whole_fit, avg, None, "", False,
                                  f"the fit of the {avg.mode} average failed ({failed}); fitted the whole record "
                                  "instead, " + (from_later or "from rest"))
        if fit is None:
            raise FitError(f"fit of {structure.formula!r} failed: the {avg.mode} average's fit failed ({failed}) "
                           f"and the whole record's model is unstable ({whole_fit.measured.to_string(4)}); try "
                           "another structure, a fixed delay or a shorter part of the record", where=record.source)
    assert fit is not None
    if avg is not None and avg.mode == "edge" and average == "auto":
        fit, whole = _refit_unsettled(record, avg, fit, structure, delay, sensor)
    elif avg is not None and avg.mode == "cycle" and average == "auto":
        fit, whole = _refit_from_rest(record, avg, fit, structure, delay, sensor)
        if not whole:
            fit, avg, whole = refit_periodic_start(record, avg, fit, structure, delay, sensor)
    fit = _other_pair_minima(record, fit, structure, delay, sensor)
    fit = _settle_after_hidden_edges(record, fit, structure, delay, sensor) if avg is None else fit
    if avg is None or whole:  # a whole-record fit's start state, where it matters, is left out (synth.ident.
        fit, later = fit_from_unknown_start(record, fit, structure, delay, sensor)  # unknown_start; session 71: a
        whole = "; ".join(x for x in (whole, later) if x)  # train from a step at t = 0, p1 0.86 +- 0.04 for 0.5)
    directions = None  # holds too short for windows from rest are not fitted by direction (unless asked to)
    note = too_unsettled(record, avg.steps, fit.plant) if two_ways and compare_directions and not by_direction else ""
    if two_ways and (compare_directions or by_direction) and not note:
        try:
            directions = fit_by_direction(record, structure, delay, sensor, avg.steps,  # type: ignore[union-attr]
                                          start=dict(fit.parameters))
        except (DataError, ModelError, RuntimeError, ValueError, np.linalg.LinAlgError) as exc:  # FitError too
            if by_direction:
                raise
            note = str(exc)
    note = note and f"up and down steps not compared: {note}"
    if by_direction and directions is not None:
        _require_settled_windows(directions, record.source)
    periodic_delay = ambiguity_note(fit, avg, None) if fit.periodic else ""  # a fitted delay, up to the period
    given = _aliased_delay(delay, fit, avg) or (fixed_delay_note(record, avg, fit, start_up_weights(record, avg, fit))
                                                if fit.periodic and not fit.delay_fitted else "")  # weights: a simulation
    return IdentifyResult(record, fit, avg, directions, note, by_direction,
                          "; ".join(x for x in (not_averaged, whole, given, periodic_delay) if x))


def _require_settled_windows(directions: DirectionComparison, source: str) -> None:
    """Raise :class:`FitError` when the per-direction fits, made on windows assumed to start at rest, are likely
    biased by more than their own standard error: by about the share of a step the model had not settled when the
    next step came, times the parameter (a black-box test: the gain 0.75 % low at 0.68 % left, 13 reported std;
    the comparison of the two allows twice that). As the result, such a fit would be a biased number with a small
    std."""
    if directions.unsettled <= 0:
        return
    worst = None  # (share of a step that may be left, direction, parameter, allowance, std)
    for label, fit in (("up", directions.up), ("down", directions.down)):
        for name, value in fit.parameters.items():
            allowance = directions.unsettled * abs(value)
            std = fit.std.get(name, 0.0)
            if np.isfinite(std) and std > 0 and allowance > std:
                share = std / abs(value)
                if worst is None or share < worst[0]:
                    worst = (share, label, name, allowance, std)
    if worst is None:
        return
    share, label, name, allowance, std = worst
    apart = max(settling_time(directions.up.plant, share), settling_time(directions.down.plant, share))
    advice = f"steps at least {apart:.3g} s apart" if np.isfinite(apart) else "steps further apart"
    raise FitError(f"the {label} steps' fit cannot stand as a result: the steps do not settle between one another "
                   f"({100 * directions.unsettled:.2g} % of a step left when the next came), which the per-direction "
                   f"fits take as rest; that moves {name} by about {allowance:.3g}, more than its std ({std:.2g}); "
                   f"use {advice}, or identify without a direction-dependent model", where=source)


def _integrates(structure: Structure) -> bool:
    """Whether the structure has a pole at 0 whatever its parameters (``K/(s*(T*s+1))``).

    Examples
    --------
    >>> _integrates(parse_structure("K/(s*(T*s+1))")), _integrates(parse_structure("K/(T*s+1)"))
    (True, False)
    """
    den = structure.coefficients(np.ones(len(structure.parameters)))[1]
    return bool(den.size > 1 and den[-1] == 0.0)


def _aliased_delay(delay: str | float | None, fit: TimeFitResult, avg: StepAverage | None) -> str:
    """A note when a fixed delay is a period or more of the periodic average that was fitted: the periodic steady
    state cannot tell it from its remainder (4.05 s on a 4 s train fits as 0.05 s does)."""
    if avg is None or not fit.periodic or delay is None or isinstance(delay, bool):
        return ""
    try:
        value = float(delay)  # "fit" is not a number
    except (TypeError, ValueError):
        return ""
    period = float(avg.t[-1] - avg.t[0] + avg.t[1] - avg.t[0])
    if not value >= period:
        return ""
    return (f"the fixed delay {value:.6g} s is not shorter than the averaged train's period ({period:.6g} s): its "
            f"periodic steady state fits {value % period:.6g} s exactly as well, so the record does not confirm the "
            "delay as given")


def _check_fixed_delay(delay: str | float | None, record: Record) -> None:
    """Refuse a fixed delay as long as the record or longer: no output sample could answer the input (a delay
    of 100 s on a 40 s record was fitted, 94 % "fit", exit 0). A delay that is not a number is left to the fit's
    own check.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 4, 0.01); rec = record_from_arrays(t, (t > 1) * 1.0, (t > 1.1) * 2.0)
    >>> _check_fixed_delay("fit", rec); _check_fixed_delay(0.5, rec)
    >>> try:
    ...     _check_fixed_delay("100", rec)
    ... except ModelError as error:
    ...     print(error.message[:48])
    the fixed delay 100 s is outside [0, 3.99) s, th
    """
    if delay is None or isinstance(delay, bool) or (isinstance(delay, str) and delay.strip().lower() == "fit"):
        return
    try:
        value = float(delay)
    except (TypeError, ValueError):
        return
    duration = float(record.t[-1] - record.t[0])
    if np.isfinite(value) and value >= duration:
        raise ModelError(f"the fixed delay {value:.6g} s is outside [0, {duration:.6g}) s, the record's length: "
                         "no output sample could answer its input", where=record.source)


def _other_pair_minima(record: Record, fit: TimeFitResult, structure: Structure, delay: str | float | None,
                       sensor: Plant | str | None) -> TimeFitResult:
    """A fit of the whole record from rest, moved out of a nearly cancelling pair's other minima
    (:func:`synth.ident.pair_relocation.relocate_pair`) when it has a weakly identifiable parameter: a pair the
    record pins down is not profiled (the X-4 record's, 26 s on its 420,000 samples). An average's fit as it is."""
    if fit.periodic or fit.t.size != record.t.size or not fit.weak:
        return fit
    return relocate_pair(record, fit, structure, delay, sensor)


GAP_KEPT = 0.25
"""Least share of its samples a whole-record fit keeps after leaving out the settling after gaps that may hide
changes: with less, what is left is tails of responses to edges whose timing the log lost (a train with all but
three edges hidden, refitted on 20 % of it, put K 8 standard errors off, and lower with each refit)."""


def _settle_after_hidden_edges(record: Record, fit: TimeFitResult, structure: Structure, delay: str | float | None,
                               sensor: Plant | str | None) -> TimeFitResult:
    """A fit of the whole record refitted with the model's settling time after each gap in the log that hid a
    command change weighted 0 (:func:`synth.data.gaps.gap_weights`): the edge came at an unknown time inside the
    gap, so the simulated response to it is wrong until it has settled. As it is when there is no such gap or the
    model does not settle; a :class:`FitError` when too little is left, or the refit fails: the fit without it
    would be biased (every edge of a train hidden: K 27 of its standard errors off).

    Raises
    ------
    FitError
        The refit failed, or the gaps' settling leaves too few samples.
    """
    settle = settling_time(fit.measured)
    if not record.gaps or fit.periodic or fit.t.size != record.n or not np.isfinite(settle):
        return fit
    base = fit.weights
    try:
        for _ in range(3):  # the settling comes from a model the hidden edges bent: again from the refit's own
            weights = after_gaps(record, fit.measured, base)
            if weights is None or (fit.weights is not None and np.array_equal(weights, fit.weights)):
                return fit
            if np.sum(weights > 0) < GAP_KEPT * (record.n if base is None else np.sum(base > 0)):
                raise DataError(f"less than {GAP_KEPT:.0%} of the samples is left")
            fit = fit_structure(record, structure, delay, sensor, False, initial={**fit.parameters}, weights=weights,
                                check=True)
        return fit
    except (DataError, FitError) as exc:
        kept = float(np.mean(weights > 0))
        raise FitError(f"fit of {structure.formula!r} failed: gaps in the log hide command changes, and with the "
                       f"model's settling after each left out ({kept:.1%} of the record kept) the fit failed "
                       f"({exc.message if isinstance(exc, DataError) else exc}); the fit with them would be biased: "
                       "cut the record to a part without such gaps", where=record.source) from None


def _implausible_average_fit(fit: TimeFitResult, dt: float) -> str:
    """Why the fit of a step average is not a model of the record ('' when it may be): unstable although the
    steps settle, or a pole or zero of the identified plant beyond the record's Nyquist frequency, which no
    record sampled at ``dt`` resolves (a few short windows can be fitted by a fast pair whose product stands in
    for a gain: k = -2.2e5 with poles at 669 and 9,511 rad/s for k = 4.1, poles 0.87 and 3.3, on a 0.7 s edge
    average of a record at 6.7 ms)."""
    if _unstable(fit.measured):
        return f"its model is unstable ({fit.measured.to_string(4)}) although the steps settle"
    if beyond_nyquist(fit.plant, dt):
        return (f"its model {fit.plant.to_string(4)} has a pole or zero beyond the record's Nyquist frequency "
                f"({np.pi / dt:.4g} rad/s)")
    return ""


def _unstable(plant: Plant) -> bool:
    """A pole in the open right half-plane (a step train's average fitted by a diverging model)."""
    den = np.trim_zeros(np.asarray(plant.den, float), "f")
    roots = np.roots(den) if den.size > 1 else np.array([])
    return bool(np.any(roots.real > 1e-9 * np.maximum(np.abs(roots), 1e-12)))


def _refit_unsettled(record: Record, avg: StepAverage, fit: TimeFitResult, structure: Structure,
                     delay: str | float | None, sensor: Plant | str | None) -> tuple[TimeFitResult, str]:
    """Edge windows assume the plant at rest before each step; if the fitted model does not settle within
    a window, fit the whole record instead (from the edge fit, the start-up weighted 0), which assumes nothing."""
    from synth.ident.directions import UNSETTLED_FACTOR, unsettled_fraction

    window = float(avg.t[-1] + record.dt)
    settle = settling_time(fit.measured)
    if not np.isfinite(settle):
        return fit, ""
    left = unsettled_fraction(record, avg.steps, [fit.measured])
    finest = min((fit.std[k] / abs(v) for k, v in fit.parameters.items()
                  if v != 0 and np.isfinite(fit.std.get(k, np.nan)) and fit.std[k] > 0), default=np.inf)
    skip = min(settle, 0.25 * record.duration)
    weights = after_gaps(record, fit.measured, skip=skip)
    unsettled = settle > window or UNSETTLED_FACTOR * left > finest
    misfit = 0.0 if unsettled else edge_misfit(record, fit.measured, weights)
    if not unsettled and not misfit > EDGE_MISFIT:
        return fit, ""
    why = (f"the edge windows ({window:.3g} s) are shorter than the model's settling time ({settle:.3g} s)"
           if settle > window else
           f"the steps left {100 * left:.2g} % of a step unsettled when the next came, a bias of up to "
           f"{100 * UNSETTLED_FACTOR * left:.2g} % in the edge fit, more than its parameters' finest relative "
           f"standard error ({100 * finest:.2g} %)" if UNSETTLED_FACTOR * left > finest else
           f"the edge fit's model misses the whole record by {misfit:.3g} times its noise level (the windows assume "
           "rest before each step and the response within the window: a delay longer than the windows breaks both)")
    # the edge fit is the natural start, unless the average pulled a pole or zero beyond the record's Nyquist
    # frequency, which no sampled record resolves: then the whole record's own deterministic start comes first
    beyond = beyond_nyquist(fit.plant, record.dt)
    starts = [("its own start", None), ("the edge fit", {**fit.parameters})]
    failures, fits = [], []
    for name, initial in starts if beyond else starts[::-1]:
        try:
            fits.append((name, fit_structure(record, structure, delay, sensor, False, initial=initial,
                                             weights=weights, check=True)))
        except (DataError, FitError) as exc:
            failures.append(f"from {name}: {exc}")
    # both starts, the lower residual kept: an edge fit distorted by a right-half-plane zero's undershoot led a
    # refit onto the ridge K -> 0, a -> inf of K(1 - a s)/(...) at 36 % where the own start reaches 95 %; windows
    # shorter than the delay (2.5 s behind steps 1-3 s apart) gave an edge fit whose refit converged at K = -0.71,
    # fit 21 %, where the own start finds the truth at 95.5 % (a black-box test)
    if not fits and all(NO_RESPONSE in f for f in failures):  # the whole record shows no response: a failure
        raise FitError(f"fit of {structure.formula!r} failed: {why}, and over the whole record the model explains no "
                       f"more of the output than noise or its own drift ({failures[0]}); the edge average alone is "
                       "no evidence of a response: check that the output responds to the input", where=record.source)
    if not fits:
        return fit, f"{why}; the whole-record fit failed ({'; '.join(failures)}), so the edge fit is kept (biased)"
    name, whole = min(fits, key=lambda named: named[1].residual_std)
    others = [f"from {other}: fit {f.fit_percent:.4g} %, {f.solver.get('status')}" for other, f in fits if other != name]
    start = f"from {name}" + (f" (it failed {failures[0]})" if failures else "") \
        + (f" (better than the fit {others[0]})" if others else "")
    return whole, (f"{why}: fitted the whole record instead {start}, the first {skip:.3g} s (start-up from an "
                   f"unknown state) weighted 0")


def _refit_from_rest(record: Record, avg: StepAverage, fit: TimeFitResult, structure: Structure,
                     delay: str | float | None, sensor: Plant | str | None) -> tuple[TimeFitResult, str]:
    """A periodic train entered from rest (constant input for longer than the model's settling time): fit the whole
    record from the periodic fit, its start-up transient included, the constant start weighted 0.

    The periodic average says little about a mode that a near cancellation hides, so its fit may put that mode
    far too slow (and flag it weakly identifiable), and the constant start then looks too short for the plant
    to have been at rest. When the periodic fit has a weakly identifiable parameter, the whole record is fitted
    then too (the constant start weighted 0) and kept when its own model settles within the constant start:
    the rest it assumes holds for the model it gives. Otherwise the periodic fit stays."""
    settle = settling_time(fit.measured)
    first = float(record.t[avg.steps.index[0]] - record.t[0])
    if not np.isfinite(settle) or first <= 0 or (first < settle and not fit.weak):
        return fit, ""
    skip = min(settle, first)
    weights = after_gaps(record, fit.measured, skip=skip)
    start, alias = whole_record_start(record, avg, fit, structure, weights)  # the delay's alias the start-up prefers
    try:
        whole = fit_whole_record(record, structure, delay, sensor, start, weights)
    except (DataError, FitError) as exc:
        return fit, (f"the whole-record fit from rest failed ({exc}), so the periodic fit is kept" if first >= settle
                     else "")
    if first >= settle:
        return whole, "; ".join(x for x in (
            f"the input is constant for {first:.3g} s before the train, longer than the model's settling time "
            f"({settle:.3g} s): fitted the whole record, the start-up transient from rest included, the first "
            f"{settle:.3g} s weighted 0", alias) if x)
    settle_whole = settling_time(whole.measured)
    if not settle_whole <= first:
        return fit, ""
    return whole, "; ".join(x for x in (
        f"the periodic fit's model settles in {settle:.3g} s, longer than the {first:.3g} s of constant input before "
        f"the train, but the whole record's fit (the constant start weighted 0) settles in {settle_whole:.3g} s, "
        "within it: that fit is kept, the start-up transient from rest included", alias) if x)
