"""A model that integrates, simulated open loop over a record: a warning.

A diagnosis simulates the model from the logged input. With a pole at the origin the output integrates every
error of that input: an offset of 1 % of the input's range, or a friction the model lacks, drifts the output
without bound, and the re-fit and every effect's fit can bend to absorb it (the EMPS position record: a dead zone
"removed 100 % of the gap" with the drive's gain re-fitted 150 times smaller). docs/gap.md diagnoses such drives on
velocity; :func:`integrating_warning` says so where it matters.
"""

from __future__ import annotations

import numpy as np

from synth.data.record import Record
from synth.plant import Plant

__all__ = ["DRIFT_SHARE", "integrating_warning"]

DRIFT_SHARE = 0.5
"""The warning is given when a 1 % input offset would drift the output by this share of its range over the record
(the EMPS position records: 1.5 and 3 times; a pulse train through ``4/(s (s + 2))`` diagnosed right: 0.23)."""


def integrating_warning(plant: Plant, record: Record) -> str | None:
    """Why an integrating model's open-loop simulation over ``record`` is weak evidence, or None.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 20, 0.01); u = np.sign(np.sin(t)); y = 0.01 * np.sin(t)   # a 1 % offset: 0.4 of drift
    >>> integrating_warning(Plant.from_string("1/(s*(s+1))"), record_from_arrays(t, u, y))[:45]
    'the model integrates (a pole at s = 0): simul'
    >>> integrating_warning(Plant.from_string("1/(s+1)"), record_from_arrays(t, u, y)) is None
    True
    """
    den, num = np.trim_zeros(np.asarray(plant.den, float), "f"), np.trim_zeros(np.asarray(plant.num, float), "f")
    if den.size < 2 or den[-1] != 0.0 or num.size == 0 or num[-1] == 0.0:
        return None
    rate = abs(num[-1] / den[-2]) if den[-2] != 0.0 else np.inf   # output rate per unit of constant input
    duration = float(record.t[-1] - record.t[0])
    drift = rate * 0.01 * float(np.ptp(record.u)) * duration
    span = float(np.ptp(record.y))
    if not (span > 0 and drift > DRIFT_SHARE * span):
        return None
    return (f"the model integrates (a pole at s = 0): simulated open loop over {duration:.3g} s, an input offset of 1 % "
            f"of the input's range drifts its output by {drift:.3g}, {drift / span:.2g} times the output's range, and "
            "the re-fit and the effects' fits can bend to absorb such drift; a velocity record (the output "
            "differentiated, the integrator dropped) or a closed-loop record is better evidence")
