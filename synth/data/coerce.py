"""One entry for records in whatever form a user holds them: a Record, arrays, a table or a path."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from synth.data.readers import table_from_columns
from synth.data.record import Record, load_record, record_from_arrays, record_from_columns
from synth.errors import DataError
from synth.plant import Signal

__all__ = ["RecordLike", "as_record"]

RecordLike = Any
"""What :func:`as_record` accepts: a Record, ``(t, u, y)`` arrays, an N x 3 array, a mapping of columns,
a pandas DataFrame, or the path of a CSV/MAT file."""


def _is_table(data: object) -> bool:
    """A pandas (or pandas-like) DataFrame: named columns, each convertible to an array."""
    return hasattr(data, "columns") and hasattr(data, "__getitem__") and not isinstance(data, np.ndarray)


def as_record(
    data: RecordLike,
    *,
    time: str | None = None,
    input: str | None = None,
    output: str | None = None,
    aux: Sequence[str] = (),
    input_unit: str = "",
    output_unit: str = "",
    dt: float | None = None,
    columns: Mapping[str, str] | None = None,
) -> Record:
    """Turn what the user holds into a :class:`Record`, validated as a file would be.

    Parameters
    ----------
    data : Record, tuple of arrays, ndarray, mapping, DataFrame, str or Path
        ``(t, u, y)`` (or ``(u, y)`` with ``dt``); an N x 3 (or 3 x N) array of columns t, u, y, or a
        list of ``[t, u, y]`` rows; named columns
        (a dict or a DataFrame, picked by ``time``/``input``/``output``, else taken in that order; a
        DataFrame's index is the time when ``time`` is ``"index"``; columns that are not numbers are
        left out when time, input and output are named); or a CSV/MAT path.
    time, input, output : str, optional
        Column names, for named columns and files.
    aux : sequence of str
        Extra columns kept on the record.
    input_unit, output_unit : str
        Units of the input and output (kept if ``data`` is a Record).
    dt : float, optional
        Sample time [s] when the data has no time column.
    columns : mapping of str to str, optional
        Renames named columns (a file's, a dict's, a DataFrame's) before they are picked, e.g.
        ``{"acc[0]": "accel_x"}``.

    Raises
    ------
    DataError
        A form that is not a record, or columns that fail the record's checks (one line naming them).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 1, 0.1); u = (t >= 0.2).astype(float); y = np.cumsum(u)
    >>> as_record((t, u, y)).n
    10
    >>> as_record(np.column_stack([t, u, y]), output_unit="rad/s").output.label()
    'output [rad/s]'
    >>> as_record({"time": t, "cmd": u, "speed": y}, input="cmd").input.name
    'cmd'
    >>> float(as_record((u, y), dt=0.1).t[-1].round(3))
    0.9
    >>> as_record(42)
    Traceback (most recent call last):
    synth.errors.DataError: int: not a record; give a Record, (t, u, y) arrays, columns or a CSV/MAT path
    """
    if isinstance(data, Record):
        return data
    if isinstance(data, str | Path):
        return load_record(data, time, input, output, aux, input_unit, output_unit, dt, columns)
    named = [n for n in (time, input, output, *aux) if n is not None]
    explicit = input is not None and output is not None and (time is not None or dt is not None)
    if _is_table(data):
        raw = {str(c): data[c] for c in data.columns}
        if time == "index":
            raw = {"index": data.index, **raw}
        table = table_from_columns(_numeric_columns(raw, "DataFrame", named, explicit), "DataFrame")
        return record_from_columns(table.renamed(columns or {}), "DataFrame", time, input, output, aux, input_unit,
                                   output_unit, dt)
    if isinstance(data, Mapping):
        table = table_from_columns(_numeric_columns({str(k): v for k, v in data.items()}, "columns", named, explicit))
        return record_from_columns(table.renamed(columns or {}), "columns", time, input, output, aux, input_unit,
                                   output_unit, dt)
    arrays = _as_arrays(data)
    if arrays is not None:
        if len(arrays) == 2 and dt is not None:
            arrays = [np.arange(arrays[0].size) * float(dt), *arrays]
        if len(arrays) == 3:
            names = (time or "time", input or "input", output or "output")
            return record_from_arrays(arrays[0], arrays[1], arrays[2], Signal(names[1], input_unit),
                                      Signal(names[2], output_unit), source="arrays", names=names)
        raise DataError(f"got {len(arrays)} arrays; give (t, u, y), or (u, y) with dt", where="arrays")
    raise DataError("not a record; give a Record, (t, u, y) arrays, columns or a CSV/MAT path", where=type(data).__name__)


def _numeric_columns(raw: Mapping[str, Any], where: str, named: Sequence[str], explicit: bool) -> dict[str, np.ndarray]:
    """The numeric columns of ``raw``; a column that is not numeric is left out unless it is needed.

    It is needed when it is named, or when the columns are not all ``explicit`` (time, input and
    output are then taken in column order, which a left-out column would shift).
    """
    out: dict[str, np.ndarray] = {}
    for name, values in raw.items():
        try:
            out[name] = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            if name in named or not explicit:
                raise DataError(f"column '{name}' is not numeric", where=where) from None
    return out


def _as_arrays(data: object) -> list[np.ndarray] | None:
    """``(t, u, y)``, an N x 3 / 3 x N array or a list of ``[t, u, y]`` rows as a list of 1-D arrays, else None."""
    try:
        if isinstance(data, tuple | list) and 2 <= len(data) <= 3 and all(np.ndim(a) == 1 for a in data):
            return [np.asarray(a, dtype=float) for a in data]
        if isinstance(data, tuple | list):
            data = np.asarray(data, dtype=float)
        if isinstance(data, np.ndarray) and data.ndim == 2:
            cols = data if data.shape[0] in (2, 3) and data.shape[1] > 3 else data.T
            return [np.asarray(c, dtype=float) for c in cols]
    except (TypeError, ValueError):  # ragged or not numbers
        return None
    return None
