"""Disturbance (or noise) records: one measured channel, no input, validated like a record.

A :class:`DisturbanceRecord` is what :func:`synth.ident.psd.analyze_records` takes; every problem
with a file is a one-line :class:`~synth.errors.DataError` naming the file and column.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from synth.data.readers import read_table, time_scale
from synth.data.record import uniform_columns
from synth.errors import DataError

__all__ = ["DisturbanceRecord", "RawColumns", "disturbance_from_arrays", "load_disturbance", "read_disturbance_columns"]


@dataclass(frozen=True, eq=False)
class DisturbanceRecord:
    """One uniformly sampled disturbance (or noise) signal: no input, just a measured channel.

    Examples
    --------
    >>> r = disturbance_from_arrays(np.arange(100) * 0.01, np.sin(np.arange(100)))
    >>> r.dt, r.x.size
    (0.01, 100)
    """

    t: np.ndarray
    x: np.ndarray
    name: str = "y"
    unit: str = ""
    source: str = "arrays"
    notes: tuple[str, ...] = ()
    made_up: float = 0.0
    """Share of the samples made up by linear interpolation across dropped time stamps."""

    @property
    def dt(self) -> float:
        """Sample interval [s]."""
        return float(round((self.t[-1] - self.t[0]) / (self.t.size - 1), 12))

    @property
    def duration(self) -> float:
        """Record length [s]."""
        return float(self.t[-1] - self.t[0])

    def to_dict(self) -> dict[str, Any]:
        """Summary for JSON (not the samples)."""
        return {"source": self.source, "signal": self.name, "unit": self.unit, "samples": int(self.x.size),
                "dt": self.dt, "duration": self.duration, "notes": list(self.notes)}


def disturbance_from_arrays(t: Any, x: Any, name: str = "y", unit: str = "", source: str = "arrays",
                            time_name: str = "time") -> DisturbanceRecord:
    """Validate a time column and a signal column (irregular time is resampled linearly, with a note).

    Raises
    ------
    DataError
        NaN or inf, different lengths, fewer than 16 samples, decreasing time, a constant signal.

    Examples
    --------
    >>> t = np.arange(20.0); t[5] = 3.5
    >>> disturbance_from_arrays(t, np.arange(20.0))
    Traceback (most recent call last):
    synth.errors.DataError: arrays: column 'time': time is not strictly increasing at sample 5 (t = 3.5 s)
    """
    tt, cols, notes = uniform_columns({time_name: t, name: x}, time_name, source, min_samples=16)
    xx = cols[name]
    if np.ptp(xx) == 0:
        raise DataError(f"column '{name}': the signal is constant ({xx[0]:g}); it has no spectrum", where=source)
    return DisturbanceRecord(tt, xx, name, unit, source, notes)


def load_disturbance(path: str | Path, time: str | None, signal: str, unit: str = "",
                     dt: float | None = None, columns: Mapping[str, str] | None = None) -> DisturbanceRecord:
    """Read one disturbance channel from a CSV or MAT file (see :func:`synth.data.readers.read_table`).

    Parameters
    ----------
    path : str or Path
    time : str or None
        Time column [s] (with or without the header's unit; ``Time (ms)`` is converted); ``None``
        with ``dt`` for a file without one.
    signal : str
        The measured channel.
    unit : str
        Its unit (labels and JSON); default the header's.
    dt : float, optional
        Sample interval [s] when there is no time column.
    columns : mapping of str to str, optional
        Renames columns first, e.g. ``{"acc[2]": "accel_z"}``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "d.csv"
    >>> _ = p.write_text("t,speed\\n" + "".join(f"{k * 0.001},{(-1) ** k}\\n" for k in range(20)))
    >>> load_disturbance(p, "t", "sped")
    Traceback (most recent call last):
    synth.errors.DataError: ...d.csv: signal column 'sped' not found; did you mean 'speed'? columns are t, speed
    """
    raw = read_disturbance_columns(path, time, signal, unit, dt, columns)
    record = disturbance_from_arrays(raw.t, raw.x, raw.column, raw.unit, raw.source, raw.time_name)
    return replace(record, name=raw.name, notes=raw.notes + record.notes)


@dataclass(frozen=True)
class RawColumns:
    """A disturbance channel as logged: time stamps [s] and values, before any check or resampling."""

    t: np.ndarray
    x: np.ndarray
    column: str
    name: str
    unit: str
    source: str
    time_name: str
    notes: tuple[str, ...]


def read_disturbance_columns(path: str | Path, time: str | None, signal: str, unit: str = "",
                             dt: float | None = None, columns: Mapping[str, str] | None = None) -> RawColumns:
    """The time and signal columns of a file as logged (parameters as :func:`load_disturbance`, which checks and
    resamples them).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "d.csv"
    >>> _ = p.write_text("t,speed\\n0,1\\n0.0012,2\\n0.002,3\\n")
    >>> read_disturbance_columns(p, "t", "speed").t.tolist()
    [0.0, 0.0012, 0.002]
    """
    path = Path(path)
    table = read_table(path, columns)
    t_key = table.find(time, "time") if time is not None else None
    x_key = table.find(signal, "signal")
    x = table.columns[x_key]
    if t_key is None:
        if dt is None or not (np.isfinite(dt) and dt > 0):
            raise DataError("no time column given: give the sample interval dt > 0 s", where=str(path))
        t = np.arange(x.size) * float(dt)
    else:
        t = table.columns[t_key] * time_scale(table.units.get(t_key, ""), t_key, str(path))
    sig = table.signal(x_key, unit)
    return RawColumns(t, x, x_key, sig.name, sig.unit, str(path), t_key or "time", tuple(table.notes))
