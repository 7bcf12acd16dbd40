"""Checks on a record's columns by name and size: a column named like time, values too large for a fit's sums."""

from __future__ import annotations

import numpy as np

from synth.data.readers import TIME_UNITS, split_unit
from synth.errors import DataError

__all__ = ["HUGE", "TIME_NAMES", "check_magnitude", "looks_like_time"]

HUGE = 1e150
"""Largest magnitude of a signal: its square summed over a record stays finite."""

TIME_NAMES = frozenset({"t", "time", "times", "timestamp", "zeit", "sec", "seconds"})
"""Column names that are read as time (any case)."""


def looks_like_time(name: str, unit: str = "") -> bool:
    """Whether a column is named or unit-tagged like a time column.

    Examples
    --------
    >>> looks_like_time("Time (s)"), looks_like_time("t"), looks_like_time("speed", "rad/s")
    (True, True, False)
    """
    bare, header_unit = split_unit(name)
    return bare.strip().lower() in TIME_NAMES or (unit or header_unit).strip().lower() in TIME_UNITS


def check_magnitude(name: str, x: np.ndarray, source: str) -> None:
    """A one-line :class:`DataError` for values whose squares overflow in a fit's sums (above :data:`HUGE`).

    Examples
    --------
    >>> check_magnitude("u", np.array([1e200]), "run.csv")
    Traceback (most recent call last):
    synth.errors.DataError: run.csv: column 'u': values up to 1e+200 overflow double precision ...
    """
    if x.size and float(np.max(np.abs(x))) > HUGE:
        raise DataError(f"column '{name}': values up to {float(np.max(np.abs(x))):.3g} overflow double precision "
                        "in the sums of squares a fit takes; rescale the signal (other units)", where=source)
