"""Checks before any fitting: a model the record can drive, and a record long enough for the effects asked for.

:func:`check_model` refuses, in one line and before the localization or any fit, what would otherwise
give numbers without meaning (an unstable ``2/(s-1)`` on a 40 s record "explains" a gap of 10^17 %):

- **the model**: finite coefficients, no pole in the right half-plane (an integrator or an undamped
  pair on the axis is allowed), and its simulation on the record's command finite and not growing
  beyond a million times the measured output's scale;
- **its delay**: shorter than the record;
- **the record, per effect**: at least :meth:`synth.gap.effects.base.Effect.required_samples`
  training samples (10 per free parameter: the nominal coefficients, the effect's own and the output
  constant) and at least :meth:`synth.gap.effects.base.Effect.required_duration` seconds (one time
  constant of the model's slowest mode).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from synth.data.record import Record
from synth.errors import DataError, ModelError
from synth.gap.effects.base import Effect
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["check_model", "nominal_coefficients"]


def nominal_coefficients(plant: Plant) -> int:
    """Number of nonzero coefficients the re-fit frees (numerator, and denominator but its leading one).

    Examples
    --------
    >>> nominal_coefficients(Plant.from_string("2/(0.2*s+1)"))
    2
    """
    num = np.asarray(plant.num, float)
    den = np.asarray(plant.den, float)
    return int(np.count_nonzero(num) + max(np.count_nonzero(den) - 1, 0))


def check_model(plant: Plant, record: Record, effects: Sequence[Effect], train_fraction: float = 0.5,
                validated: bool = False, tail: bool = True) -> None:
    """Raise when ``plant`` cannot be judged on ``record`` for ``effects`` (one line; nothing is fitted).

    Parameters
    ----------
    plant : Plant
        The nominal model.
    record : Record
        The measured record (the fits run on its first ``train_fraction``, or all of it when
        ``validated``).
    effects : sequence of Effect
        The candidates.
    train_fraction : float
    validated : bool
        A validation record is held out (the whole record trains).
    tail : bool
        The record's tail is held out (its head trains): a head with a constant command is an error.

    Raises
    ------
    ModelError
        Non-finite coefficients, an unstable model, a simulation that diverges, a delay longer than the
        record.
    DataError
        A record too short for an effect (the message says what it needs and why).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.effects import make_effect
    >>> t = np.arange(0, 40.01, 0.01); u = (t % 10 >= 5).astype(float)
    >>> rec = record_from_arrays(t, u, u)
    >>> check_model(Plant.from_string("2/(s+1)"), rec, [make_effect("delay")])
    >>> check_model(Plant.from_string("2/(s-1)"), rec, [make_effect("delay")])
    Traceback (most recent call last):
    synth.errors.ModelError: --plant: unstable model: pole at +1 (real part > 0); its simulation of the 40 s ...
    >>> check_model(Plant.from_string("2/(s+1)", delay=50.0), rec, [make_effect("delay")])
    Traceback (most recent call last):
    synth.errors.ModelError: --delay: the model's delay 50 s is not shorter than the record (40 s)
    >>> check_model(Plant.from_string("2/(s+0.01)"), rec, [make_effect("delay")])
    Traceback (most recent call last):
    synth.errors.DataError: --data: the record (40 s) is too short for delay: it needs one time constant ... 100 s
    """
    num, den = np.asarray(plant.num, float), np.asarray(plant.den, float)
    if not (np.all(np.isfinite(num)) and np.all(np.isfinite(den)) and np.isfinite(plant.delay)):
        raise ModelError("the model has non-finite coefficients", where="--plant")
    duration = float(record.t[-1] - record.t[0])
    poles = plant.poles()
    scale = max(1.0, float(np.max(np.abs(poles)))) if poles.size else 1.0
    unstable = poles[poles.real > 1e-9 * scale]
    if unstable.size:
        p = unstable[np.argmax(unstable.real)]
        where = f"{p.real:+.4g}" + (f" {'+' if p.imag >= 0 else '-'} {abs(p.imag):.4g}j" if abs(p.imag) > 0 else "")
        raise ModelError(f"unstable model: pole at {where} (real part > 0); its simulation of the {duration:.4g} s "
                         "record grows without bound, so no gap can be measured: give a stable model", where="--plant")
    if plant.delay >= duration:
        raise ModelError(f"the model's delay {plant.delay:.4g} s is not shorter than the record ({duration:.4g} s)",
                         where="--delay")
    y = simulate_plant(plant, record.t, record.u)
    level = float(np.max(np.abs(record.y - np.mean(record.y)))) + float(np.max(np.abs(record.y)))
    if not np.all(np.isfinite(y)) or float(np.max(np.abs(y - y[0]))) > 1e6 * max(level, 1e-300):
        raise ModelError(f"the model cannot be simulated on the {duration:.4g} s record (its output grows beyond "
                         "10^6 times the measured output): check its gain and units", where="--plant")
    n_train = record.n if validated else round(train_fraction * record.n)
    if tail and not validated and n_train < record.n and np.ptp(record.u[:n_train]) == 0:
        raise DataError(f"the training part (t < {record.t[n_train]:.4g} s, the record's first "
                        f"{100 * train_fraction:.3g} %) holds a constant command ({record.u[0]:.4g}): nothing there "
                        "excites a fit; give --split interleaved, a validation record (--validate), or a record with "
                        "steps in its first part", where="--data")
    n_coef = nominal_coefficients(plant)
    for eff in effects:
        need = eff.required_samples(n_coef)
        if n_train < need:
            raise DataError(f"the record is too short for {eff.label}: the fits get {n_train} samples, and "
                            f"{need} are needed (10 per free parameter: {n_coef} nominal coefficients, "
                            f"{len(eff.parameter_names)} of {eff.label}, the output constant"
                            f"{'; rises and falls each' if need > 10 * (n_coef + len(eff.parameter_names) + 1) else ''})",
                            where="--data")
        seconds = eff.required_duration(plant)
        if duration < seconds:
            raise DataError(f"the record ({duration:.4g} s) is too short for {eff.label}: it needs one time constant "
                            f"of the model's slowest mode, {seconds:.4g} s", where="--data")
