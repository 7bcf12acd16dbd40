"""Several runs of one plant as one evaluation timeline, with settling bridges between them.

A diagnosis judged on several held-out runs simulates each model over all of
them. Each run starts at rest at its own first input (as a single record is
assumed to), so the runs are joined by a *bridge*: the next run's first input
held for ``settle`` seconds, long enough for the model to reach that steady
state before the run begins. Bridge samples belong to no run (``run == -1``)
and no cost counts them. Each run keeps its own output offset where the
offset is re-estimated (another run has its own operating point and sensor
zero).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from synth.data.record import Record
from synth.errors import DataError, ModelError
from synth.plant import Plant

__all__ = ["SETTLE_TIME_CONSTANTS", "Stitched", "settle_time", "stitch_runs"]

SETTLE_TIME_CONSTANTS = 20.0
"""Bridge length in time constants of the slowest pole (``exp(-20)`` of the start-up transient is left)."""


@dataclass(frozen=True)
class Stitched:
    """Runs joined by settling bridges on one uniform time grid.

    Attributes
    ----------
    t, u, y : numpy.ndarray
        Time [s] (uniform, from 0), command and output.
    run : numpy.ndarray
        Index of the run each sample belongs to; ``-1`` on a bridge.
    since_start : numpy.ndarray
        Seconds since the start of the sample's run (``nan`` on a bridge).
    """

    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    run: np.ndarray
    since_start: np.ndarray

    @property
    def runs(self) -> int:
        """Number of runs."""
        return int(self.run.max()) + 1


def settle_time(plant: Plant) -> float:
    """Seconds a stable model needs to forget its state: 20 time constants of its slowest pole, plus its delay.

    Raises
    ------
    ModelError
        The model has a pole on or right of the imaginary axis (it never settles, so runs cannot be joined).

    Examples
    --------
    >>> settle_time(Plant.from_string("1/(0.5*s+1)", delay=0.1))
    10.1
    """
    settle = plant.settling_time(SETTLE_TIME_CONSTANTS)
    if not np.isfinite(settle):
        poles = plant.poles()
        raise ModelError("several validation records need a stable model (each run starts at rest); this one "
                         f"has a pole at {poles[np.argmax(poles.real)]:.4g}", where="plant")
    return settle


def stitch_runs(records: Sequence[Record], settle: float) -> Stitched:
    """Join ``records`` on one time grid, each after a bridge holding its first input for ``settle`` seconds.

    Parameters
    ----------
    records : sequence of Record
        Runs with the same sample time and units.
    settle : float
        Bridge length [s] (see :func:`settle_time`); at least one sample.

    Returns
    -------
    Stitched

    Raises
    ------
    DataError
        Sample times or units differ between the runs.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> a = record_from_arrays(np.arange(4) * 0.5, [0.0, 1, 1, 1], [0.0, 0, 1, 2])
    >>> b = record_from_arrays(np.arange(3) * 0.5, [2.0, 3, 3], [5.0, 6, 7])
    >>> s = stitch_runs([a, b], 1.0)
    >>> s.run.tolist(), s.u.tolist()
    ([0, 0, 0, 0, -1, -1, 1, 1, 1], [0.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0])
    """
    if len(records) < 1:
        raise DataError("no runs to join", where="validate")
    dt = records[0].dt
    for i, rec in enumerate(records[1:], start=1):
        if abs(rec.dt - dt) > 1e-9 * dt:
            raise DataError(f"run {i + 1} is sampled every {rec.dt:g} s, the first every {dt:g} s; resample it",
                            where="validate")
        for side in ("input", "output"):
            a, b = getattr(records[0], side).unit, getattr(rec, side).unit
            if a != b:
                raise DataError(f"run {i + 1}: {side} unit {b!r} differs from the first run's {a!r}",
                                where="validate")
    gap = max(1, int(np.ceil(settle / dt - 1e-9)))
    us, ys, runs, since = [], [], [], []
    for i, rec in enumerate(records):
        if i > 0:
            us.append(np.full(gap, rec.u[0]))
            ys.append(np.full(gap, rec.y[0]))
            runs.append(np.full(gap, -1))
            since.append(np.full(gap, np.nan))
        us.append(np.asarray(rec.u, float))
        ys.append(np.asarray(rec.y, float))
        runs.append(np.full(rec.n, i))
        since.append(np.arange(rec.n) * dt)
    u = np.concatenate(us)
    return Stitched(np.arange(u.size) * dt, u, np.concatenate(ys), np.concatenate(runs), np.concatenate(since))
