"""A periodic step train that starts before the plant has settled, or soon after a short rest.

The cycle average (:func:`synth.ident.steps.average_steps`) stands for the periodic steady state, and its fit
removes the output's mean. Two things go wrong when the train's modes do not settle within the first period
or the constant start before the train is short:

- *Bias.* The first averaged period starts one period after the train began; within the model's settling
  time the average still holds part of the start-up transient (``2/(0.5 s + 1)`` stepped every 0.5 s after a
  1 s rest: k and tau 13 standard errors off over 20 noise seeds).
- *Lost information.* The transition from the constant start into the train carries the static gain, which
  the average's removed mean does not: on such records the periodic average's standard errors were 2-7
  times the Cramer-Rao bound (``benchmarks/ident_crb.py --rest 0.3``).

:func:`refit_periodic_start` handles both when the constant start is shorter than the model's settling time
(a longer one goes to the whole-record fit from rest in :mod:`synth.ident.identification`). It predicts the
standard errors a whole-record fit would have, from the periodic fit's model (finite-difference sensitivities
of a simulation over the record, the first settling time weighted 0 because the state before the record is
not known); when they are :data:`WHOLE_RECORD_GAIN` times smaller or more for some parameter, it fits the
whole record. Otherwise it drops the periods that start within the settling time and refits the rest.
"""

from __future__ import annotations

import numpy as np

from synth.data.gaps import gap_weights
from synth.data.record import Record
from synth.errors import DataError, FitError, ModelError
from synth.ident.identifiability import WEAK_RELATIVE_STD
from synth.ident.nyquist import beyond_nyquist
from synth.ident.simulate import simulate_plant
from synth.ident.steps import StepAverage, average_steps
from synth.ident.structure import Structure
from synth.ident.timefit import TimeFitResult, fit_structure
from synth.plant import Plant

__all__ = ["WHOLE_RECORD_GAIN", "fit_whole_record", "predicted_whole_record_covariance",
           "refit_periodic_start", "settling_time", "starts_at_rest", "step_settling_time"]

#: fit the whole record when it is predicted to shrink some parameter's standard error by this factor or more
WHOLE_RECORD_GAIN = 1.5
#: e^-5: the share of a step that counts as settled
SETTLED = float(np.exp(-5.0))


def settling_time(plant: Plant, fraction: float = SETTLED) -> float:
    """Time for the slowest mode of ``plant`` to decay to ``fraction`` of its start, plus the delay (inf if not stable).

    Examples
    --------
    >>> round(settling_time(Plant.from_string("1/((s+1)*(s+10))", delay=0.1)), 3)
    5.1
    """
    return plant.settling_time(float(np.log(1.0 / fraction)))


GAP_SETTLED = 1e-3
"""After a gap in the log that may hide a command change, a whole-record fit leaves out the time the model takes to
settle to this fraction: at the usual ``SETTLED`` (0.7 %) an edge shifted by a third of the time constant still
left a mismatch of about 0.4 % of the step after it, which on a record with an edge hidden every period put K 4.3
of its standard errors off."""


def start_up_weights(record: Record, avg: StepAverage | None, fit: TimeFitResult) -> np.ndarray | None:
    """The whole record's weights for a fit from rest after a periodic fit: the constant input before the train
    weighted 0 up to the model's settling time (:func:`after_gaps`); ``None`` without a constant start or a model
    that settles.

    Examples
    --------
    >>> from synth.ident.identification import identify
    >>> t = np.arange(0, 40, 0.01); u = np.where(t < 3, 0.0, ((t - 3) // 2.0) % 2 == 0).astype(float)
    >>> y = simulate_plant(Plant.from_string("2/(0.5*s+1)"), t, u) + 0.02 * np.random.default_rng(0).normal(size=t.size)
    >>> res = identify((t, u, y), "k/(T*s+1)", delay=0.0)
    >>> w = start_up_weights(res.record, res.average, res.fit)
    >>> float(w[:250].max()), float(w[350:].min())  # the first 2.5 s (the model's settling time) weighted 0
    (0.0, 1.0)
    """
    if avg is None:
        return None
    first = float(record.t[avg.steps.index[0]] - record.t[0])
    settle = settling_time(fit.measured)
    if not (first > 0 and np.isfinite(settle)):
        return None
    return after_gaps(record, fit.measured, skip=min(settle, first))


def after_gaps(record: Record, model: Plant, weights: np.ndarray | None = None, skip: float | None = None
               ) -> np.ndarray | None:
    """``weights`` (or, with ``skip``, 0 over the record's first ``skip`` seconds and 1 after) with what the record's
    gaps made up left out, and :data:`GAP_SETTLED` settling of ``model`` after a gap that may hide a change
    (:func:`synth.data.gaps.gap_weights`)."""
    if skip is not None:
        weights = ((record.t - record.t[0]) >= skip).astype(float)
    return gap_weights(record.t, record.u, record.gaps, settling_time(model, GAP_SETTLED), weights)


def step_settling_time(plant: Plant, fraction: float = SETTLED) -> float:
    """Time after which the step response of ``plant`` stays within ``fraction`` of its final value [s].

    What a transient leaves in the output: a slow pole that a near zero cancels settles sooner here than by its
    time constant alone (:func:`settling_time`), which this never exceeds (and returns when the static gain is 0
    or infinite).

    Examples
    --------
    >>> round(step_settling_time(Plant.from_string("1/(s+1)")), 2)                  # 5 time constants
    5.0
    >>> p = Plant.from_string("(s+0.5)/((s+0.45)*(s+10))")                          # the slow pole nearly cancelled
    >>> round(settling_time(p), 1), round(step_settling_time(p), 1)
    (11.1, 6.1)
    """
    bound = settling_time(plant, fraction)
    final = plant.dc_gain()
    if not np.isfinite(bound) or not np.isfinite(final) or final == 0.0 or bound <= 0:
        return bound
    grid = np.linspace(0.0, bound, 4001)
    error = np.abs(simulate_plant(plant, grid, np.ones(grid.size), initial="zero") - final)
    outside = np.flatnonzero(error > fraction * abs(final))
    return float(grid[min(outside[-1] + 1, grid.size - 1)]) if outside.size else 0.0


def fit_whole_record(record: Record, structure: Structure, delay: str | float | None, sensor: Plant | str | None,
                     initial: dict[str, float], weights: np.ndarray | None = None) -> TimeFitResult:
    """The whole record fitted from ``initial`` (an average's fit); when that fails, or ends with a pole or zero
    beyond the record's Nyquist frequency, which no sampled record resolves, also from the record's own
    deterministic start: where the first failed, that fit; else the smaller residual unless its standard errors are
    not all finite. (Where the first failed, the own start's fit is kept even at a singular covariance, its
    unidentifiable parameters reported as such: the average's fit the caller would keep instead put the Cramer-Rao
    benchmark's near cancellation 33 at 270 bounds from the truth, the own start at 1.6. The covariances of case
    4 that had looked singular were regular and ill-conditioned: :data:`synth.ident.covariance.SINGULAR`.)
    (CRB case 5, seed 4: the average's fit carried its nearly
    cancelling pair to 5e4 rad/s, and the whole record, started there, stayed: a slow pole 1.58 +- 0.007 against
    1.026, residual std 0.065 where its own start reaches the noise, 0.016.)

    Raises
    ------
    FitError, DataError
        Both fits failed (the first one's error).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 10, 0.01); u = np.where(t > 1, 1.0, 0.0)
    >>> rec = record_from_arrays(t, u, simulate_plant(Plant.from_string("2/(s+1)"), t, u))
    >>> from synth.ident.structure import parse_structure
    >>> fit_whole_record(rec, parse_structure("k/(s+p)"), None, None, {"k": 1.0, "p": 1.5}).plant.to_string(4)
    '2/(s+1)'
    """
    try:
        fit = fit_structure(record, structure, delay, sensor, False, initial=initial, weights=weights, check=True)
    except (DataError, FitError) as exc:
        try:
            return fit_structure(record, structure, delay, sensor, False, weights=weights, check=True)
        except (DataError, FitError):
            raise exc from None
    if not beyond_nyquist(fit.plant, record.dt):
        return fit
    try:
        other = fit_structure(record, structure, delay, sensor, False, weights=weights, check=True)
    except (DataError, FitError):
        return fit
    better = other.residual_std < fit.residual_std and (_finite_errors(other) or not _finite_errors(fit))
    return other if better else fit


def _finite_errors(fit: TimeFitResult) -> bool:
    """Every standard error finite (a singular covariance leaves some infinite)."""
    return bool(np.all(np.isfinite(list(fit.std.values()))))


def starts_at_rest(record: Record, first: float, sigmas: float = 3.0) -> bool:
    """Whether the output is flat over the constant input before the train (the first ``first`` seconds): the
    means of its first and last thirds agree within ``sigmas`` standard errors (noise from the differences of
    consecutive samples). Then the plant was at rest when the record began, and a fit may start from rest.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 10, 0.01); u = np.where(t > 2, 1.0, 0.0); noise = np.random.default_rng(0).normal(size=t.size)
    >>> starts_at_rest(record_from_arrays(t, u, 0.01 * noise), 2.0)
    True
    >>> starts_at_rest(record_from_arrays(t, u, np.exp(-t) + 0.01 * noise), 2.0)     # still decaying
    False
    """
    y = record.y[(record.t - record.t[0]) < first]
    third = y.size // 3
    if third < 5:
        return False
    sigma = float(np.std(np.diff(y)) / np.sqrt(2.0))
    return bool(abs(np.mean(y[:third]) - np.mean(y[-third:])) <= sigmas * sigma * np.sqrt(2.0 / third))


def predicted_whole_record_covariance(record: Record, fit: TimeFitResult, structure: Structure, noise_std: float,
                                      weights: np.ndarray) -> tuple[list[str], np.ndarray]:
    """The fitted parameters' names and the covariance a whole-record fit would have at ``fit``'s parameters.

    ``sigma^2 (J^T W J)^-1`` with ``J`` the central-difference sensitivities of the model's output (sensor
    included, simulated from rest at the record's first sample) to each fitted parameter and to an output
    offset (a nuisance parameter, dropped from the result), ``W`` the 0/1 ``weights``, ``sigma`` the
    per-sample ``noise_std``; infinite when ``J`` is singular.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.timefit import fit_structure
    >>> t = np.arange(0, 20, 0.01); u = np.where(t > 1, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(s+1)"), t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> rec = record_from_arrays(t, u, y); fit = fit_structure(rec, "k/(s+p)")
    >>> names, cov = predicted_whole_record_covariance(rec, fit, fit.structure, 0.01, np.ones(t.size))
    >>> names, bool(abs(np.sqrt(cov[0, 0]) / fit.std["k"] - 1) < 0.1)     # the fit's own, on the same record
    (['k', 'p'], True)
    """
    names = [k for k in fit.parameters if fit.std.get(k, 0.0) > 0.0]
    base = dict(fit.parameters)
    delay_name = "delay" if "delay" in base else structure.delay_parameter

    def output(params: dict[str, float]) -> np.ndarray:
        plant = structure.plant(params, delay=params.get(delay_name) if delay_name else None)
        if fit.sensor is not None:
            plant = plant.series(fit.sensor).with_delay(plant.delay)
        return simulate_plant(plant, record.t, record.u)

    keep = np.asarray(weights, float) > 0
    columns = []
    for name in names:
        h = 1e-5 * max(abs(base[name]), 1e-3)
        up, down = {**base, name: base[name] + h}, {**base, name: base[name] - h}
        columns.append(((output(up) - output(down)) / (2.0 * h))[keep])
    J = np.column_stack([*columns, np.ones(int(keep.sum()))])
    try:
        cov = np.linalg.inv(J.T @ J) * noise_std ** 2
    except np.linalg.LinAlgError:
        cov = np.full((J.shape[1], J.shape[1]), np.inf)
    return names, cov[:-1, :-1]


def refit_periodic_start(record: Record, avg: StepAverage, fit: TimeFitResult, structure: Structure,
                         delay: str | float | None, sensor: Plant | str | None
                         ) -> tuple[TimeFitResult, StepAverage, str]:
    """The whole record, or the periods free of the start-up transient, instead of the plain periodic fit.

    Only for a constant start shorter than the model's settling time (module text), after the whole-record
    fit from rest of :mod:`synth.ident.identification` has declined; a periodic fit with a weakly identifiable
    parameter is replaced only when the whole record is predicted to know every parameter to a quarter of its
    value. Returns the fit, its average and a note (empty: nothing changed).

    Examples
    --------
    >>> from synth.ident.identification import identify
    >>> t = np.arange(0, 12, 0.01); u = np.where(t < 1, 0.0, (((t - 1) // 0.5) % 2 == 0).astype(float))
    >>> y = simulate_plant(Plant.from_string("2/(0.5*s+1)"), t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> identify((t, u, y), "k/(tau*s+1)").whole_record_note[:58]
    'the whole record, from rest (the output is flat over the c'
    """
    train = float(record.t[avg.steps.index[0]])
    first = train - float(record.t[0])
    slowest = settling_time(fit.measured)
    if first >= slowest:
        return fit, avg, ""   # the whole-record fit from rest in synth.ident.identification had its chance
    settle = step_settling_time(fit.measured)
    if not np.isfinite(settle):
        return fit, avg, ""
    at_rest = starts_at_rest(record, first)
    skip = 0.0 if at_rest else min(slowest, 0.25 * record.duration)
    weights = after_gaps(record, fit.measured, skip=skip)
    try:
        names, cov = predicted_whole_record_covariance(record, fit, structure, avg.noise_std_before, weights)
    except (ModelError, ValueError):
        names, cov = [], np.zeros((0, 0))
    predicted = {name: float(np.sqrt(max(cov[i, i], 0.0))) for i, name in enumerate(names)}
    if fit.weak and (not names or _weak(names, fit, cov, record.dt)):
        # the whole record would leave a parameter loose too (a near cancellation): both covariances are
        # linearizations at a point the record does not fix, and their ratio says nothing; the periodic fit
        # stays, flagged weak
        return fit, avg, ""
    gains = {k: fit.std[k] / v for k, v in predicted.items() if v > 0}
    best = max(gains, key=lambda k: gains[k]) if gains else None
    if best is not None and gains[best] >= WHOLE_RECORD_GAIN:
        from synth.ident.delay_alias import whole_record_start

        initial, alias = whole_record_start(record, avg, fit, structure, weights)  # the delay's alias it prefers
        try:
            whole = fit_whole_record(record, structure, delay, sensor, initial, weights)
        except (DataError, FitError) as exc:
            note = f"the whole-record fit, predicted {gains[best]:.3g} times as precise in {best}, failed ({exc})"
            trimmed, avg, why = _drop_transient_periods(record, avg, fit, structure, delay, sensor, settle, train)
            return trimmed, avg, f"{note}; {why}" if why else note
        start = ("from rest (the output is flat over the constant start)" if at_rest else
                 f"its first {skip:.3g} s weighted 0 (the output drifts over the constant start: the state before "
                 "the record is not known)")
        return whole, avg, (f"the whole record, {start}, is predicted {gains[best]:.3g} times as precise in {best} "
                            f"as the periodic average, whose mean is removed, because the {first:.3g} s of constant "
                            "input before the train and the transition into it carry the static gain: fitted it "
                            "instead" + (f"; {alias}" if alias else ""))
    return _drop_transient_periods(record, avg, fit, structure, delay, sensor, settle, train)


def _weak(names: list[str], fit: TimeFitResult, cov: np.ndarray, dt: float) -> bool:
    """Whether the predicted whole-record covariance leaves some parameter's standard error above
    :data:`~synth.ident.identifiability.WEAK_RELATIVE_STD` of its value (the delay against ``max(|delay|, dt)``).
    Strong correlations alone do not count: a train whose average lost the static gain has k and the slow pole
    tied, and the whole record then reaches the bound (CRB case 1)."""
    if not np.all(np.isfinite(cov)):
        return True
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    scale = [max(abs(fit.parameters[n]), dt) if n == "delay" else abs(fit.parameters[n]) for n in names]
    return bool(np.any(sd > WEAK_RELATIVE_STD * np.asarray(scale)))


def _drop_transient_periods(record: Record, avg: StepAverage, fit: TimeFitResult, structure: Structure,
                            delay: str | float | None, sensor: Plant | str | None, settle: float, train: float
                            ) -> tuple[TimeFitResult, StepAverage, str]:
    """Drop the periods that start within the settling time after the train began and refit the rest, until the
    model's settling time agrees (at most three rounds); with no period left, or when their fit fails, the whole
    record, its first settling time weighted 0."""
    dropped = 0
    for _ in range(3):
        lead = float(record.t[avg.first_window]) - train
        if not np.isfinite(settle) or lead >= settle:
            break
        try:
            later = average_steps(record, avg.steps, "cycle", settle=settle)
        except DataError:
            return _refit_transient(record, avg, fit, structure, delay, sensor, settle, lead,
                                    "no later period is left")
        try:
            fit = fit_structure(later.record(), structure, delay, sensor, True, initial={**fit.parameters},
                                check=True)
        except FitError as exc:
            return _refit_transient(record, avg, fit, structure, delay, sensor, settle, lead,
                                    f"the fit of the later periods failed ({exc})")
        dropped += later.dropped - avg.dropped
        avg, settle = later, step_settling_time(fit.measured)
    if not dropped:
        return fit, avg, ""
    return fit, avg, (f"dropped {dropped} more period(s) from the average: they start within the model's settling "
                      f"time ({settle:.3g} s) after the train began, so they hold part of the start-up transient")


def _refit_transient(record: Record, avg: StepAverage, fit: TimeFitResult, structure: Structure,
                     delay: str | float | None, sensor: Plant | str | None, settle: float, lead: float,
                     reason: str) -> tuple[TimeFitResult, StepAverage, str]:
    """No averaged period free of the start-up transient can be fitted (``reason``): the whole record, its first
    settling time (at most half the record) weighted 0, from the periodic fit."""
    skip = min(settle, 0.5 * record.duration)
    weights = after_gaps(record, fit.measured, skip=skip)
    why = (f"the averaged periods begin {lead:.3g} s into the train, within the model's settling time "
           f"({settle:.3g} s), so the average holds part of the start-up transient, and {reason}")
    try:
        whole = fit_whole_record(record, structure, delay, sensor, {**fit.parameters}, weights)
    except (DataError, FitError) as exc:
        return fit, avg, f"{why}; the whole-record fit failed ({exc}), so the periodic fit is kept (biased)"
    short = (f"; the record is too short for the state at its start to settle before the fitted part ({skip:.3g} "
             f"of the {settle:.3g} s it needs): the estimates may be biased" if skip < settle else "")
    return whole, avg, f"{why}: fitted the whole record instead, the first {skip:.3g} s weighted 0{short}"
