"""One measured experiment: time, input, output (and extra channels), validated.

Loading is strict and says what it did: NaN or inf, decreasing time,
columns of different length, a missing column, a constant input or an output
that never responds raise a :class:`~synth.errors.DataError` naming the file
and the column; irregular sampling is resampled onto a uniform grid (the
input held between samples, the other columns interpolated linearly) and the
record's ``notes`` say so. Files are read by :mod:`synth.data.readers`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from synth.data.column_checks import check_magnitude, looks_like_time
from synth.data.gaps import find_gaps, hidden_changes
from synth.data.interpolated_noise import interpolation_noise_correlation, interpolation_noise_factor
from synth.data.readers import Table, read_table, table_from_columns, time_scale
from synth.errors import DataError
from synth.plant import Signal

__all__ = [
    "IRREGULAR_TOLERANCE", "REPEATED_LIMIT", "Record", "load_record", "read_columns", "record_from_arrays",
    "record_from_columns", "uniform_columns",
]

#: relative spread of the sample intervals above which a record counts as irregularly sampled
IRREGULAR_TOLERANCE = 1e-3
#: share of samples that may repeat a time stamp (a logger's occasional double row); more (and more than 2) is an error
REPEATED_LIMIT = 0.05


@dataclass(frozen=True, eq=False)
class Record:
    """A uniformly sampled input/output record.

    Parameters
    ----------
    t, u, y : numpy.ndarray
        Time [s], plant input and plant output, same length, ``t`` strictly
        increasing and uniformly spaced.
    input, output : Signal
        Names and units of ``u`` and ``y``.
    aux : dict of str to numpy.ndarray
        Extra logged channels (current, voltage, ...) on the same time base.
    source : str
        Where the record came from (a file path, or ``"arrays"``).
    notes : tuple of str
        What loading did to the data (for example resampling); shown in reports.
    noise_factor : float
        What a fit's white-noise variance estimate is multiplied by for its parameters' uncertainty: 1, unless
        the output was interpolated from uneven time stamps (then adjacent samples share logged samples' noise;
        :func:`synth.data.interpolated_noise.interpolation_noise_factor`).
    noise_correlation : tuple of float
        The autocorrelation at lags 1, 2, ... samples that the output's interpolation from uneven time stamps gives
        white logged noise (:func:`synth.data.interpolated_noise.interpolation_noise_correlation`); ``()`` when the
        output was not interpolated. A fit's test of its residuals' whiteness looks for correlation beyond it.
    gaps : tuple of (float, float)
        Gaps in the logged time stamps (:func:`synth.data.gaps.find_gaps`): the stamps before and after each. The
        samples inside were made up by the resampling; fits weight them 0 and averages leave them out.

    Examples
    --------
    >>> import numpy as np
    >>> r = record_from_arrays(np.arange(5) * 0.1, [0, 1, 1, 1, 1], [0, 0, 0.5, 0.8, 0.9])
    >>> r.dt, r.n, r.duration
    (0.1, 5, 0.4)
    """

    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    input: Signal = field(default_factory=lambda: Signal("u", ""))
    output: Signal = field(default_factory=lambda: Signal("y", ""))
    aux: dict[str, np.ndarray] = field(default_factory=dict)
    source: str = "arrays"
    notes: tuple[str, ...] = ()
    noise_factor: float = 1.0
    gaps: tuple[tuple[float, float], ...] = ()
    noise_correlation: tuple[float, ...] = ()

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.t.size)

    @property
    def dt(self) -> float:
        """Sample interval [s] (the record is uniformly sampled)."""
        return float(round((self.t[-1] - self.t[0]) / (self.t.size - 1), 12))

    @property
    def fs(self) -> float:
        """Sample rate [Hz]."""
        return 1.0 / self.dt

    @property
    def duration(self) -> float:
        """Length of the record [s]."""
        return float(round(self.t[-1] - self.t[0], 12))

    def segment(self, t0: float, t1: float) -> Record:
        """The part of the record with ``t0 <= t <= t1``, time not shifted.

        Examples
        --------
        >>> r = record_from_arrays(np.arange(10.0), np.r_[0, np.ones(9)], np.arange(10.0) ** 0.5)
        >>> r.segment(2, 5).t.tolist()
        [2.0, 3.0, 4.0, 5.0]
        """
        keep = (self.t >= t0) & (self.t <= t1)
        if np.count_nonzero(keep) < 2:
            raise DataError(f"segment [{t0}, {t1}] s holds fewer than 2 samples", where=self.source)
        return Record(self.t[keep], self.u[keep], self.y[keep], self.input, self.output,
                      {k: v[keep] for k, v in self.aux.items()}, self.source, self.notes, self.noise_factor,
                      tuple(g for g in self.gaps if g[1] > t0 and g[0] < t1), self.noise_correlation)

    def require_duration(self, w_min: float) -> None:
        """Raise unless the record is long enough to resolve ``w_min`` [rad/s].

        The lowest frequency a record of length ``T`` resolves is taken as
        ``2 pi / T`` (one full period in the record; a spectral estimate with
        averaging needs more, see :mod:`synth.ident`).

        Examples
        --------
        >>> r = record_from_arrays(np.arange(0, 10, 0.01), np.sin(np.arange(0, 10, 0.01)), np.arange(0, 10, 0.01))
        >>> r.require_duration(0.1)
        Traceback (most recent call last):
        synth.errors.DataError: arrays: record is 9.99 s long; the lowest frequency 0.1 rad/s needs at least 62.8 s ...
        """
        need = 2.0 * np.pi / w_min
        if self.duration < need:
            raise DataError(f"record is {self.duration:.3g} s long; the lowest frequency {w_min:g} rad/s "
                            f"needs at least {need:.3g} s (one period)", where=self.source)

    def to_dict(self) -> dict[str, Any]:
        """Summary for JSON (not the samples).

        Examples
        --------
        >>> record_from_arrays([0, 1, 2], [0, 1, 1], [0, 0.5, 1]).to_dict()["samples"]
        3
        """
        return {"source": self.source, "samples": self.n, "dt": self.dt, "duration": self.duration,
                "input": {"name": self.input.name, "unit": self.input.unit},
                "output": {"name": self.output.name, "unit": self.output.unit},
                "aux": sorted(self.aux), "notes": list(self.notes),
                **({"noise_factor": self.noise_factor} if self.noise_factor != 1.0 else {}),
                **({"gaps": [list(g) for g in self.gaps]} if self.gaps else {})}


def uniform_columns(
    columns: Mapping[str, Sequence[float] | np.ndarray], time: str, source: str = "arrays", min_samples: int = 3,
    held: Sequence[str] = (),
) -> tuple[np.ndarray, dict[str, np.ndarray], tuple[str, ...]]:
    """Check columns of numbers on one time base and put them on a uniform grid.

    Returns the time, the other columns (by name) and notes on what was done.
    Samples sharing a time stamp keep the last of them (at most ``REPEATED_LIMIT`` of
    them: more means a rounded time column). Irregular sampling
    (intervals spread by more than 0.1 %) is resampled onto a uniform grid from
    the first to the last time stamp: the columns in ``held`` (commands) are
    held (zero-order hold, so a step stays a step), each grid interval holding the
    command's mean over it (exactly the level where no edge falls inside it; the
    command's integral is exact at every grid point), the others are interpolated
    linearly. The grid interval is the median
    interval, or the shortest time a held column stays at one value if that is
    shorter (down to a quarter of the median), so that no command level is
    skipped; the notes say what was done.

    Raises
    ------
    DataError
        Values that are not numbers, NaN or inf, different lengths, fewer than
        ``min_samples`` samples, decreasing time, many repeated time stamps; the column is named.

    Examples
    --------
    >>> t, cols, notes = uniform_columns({"t": [0, 0.1, 0.25, 0.3], "x": [0, 1, 2, 3]}, "t")
    >>> t.round(3).tolist(), cols["x"].round(3).tolist(), notes[0].split(":")[0]
    ([0.0, 0.1, 0.2, 0.3], [0.0, 1.0, 1.667, 3.0], 'resampled')
    >>> t, cols, notes = uniform_columns({"t": [0, 0.1, 0.25, 0.3], "u": [0, 1, 2, 3]}, "t", held=["u"])
    >>> t.round(3).tolist(), cols["u"].tolist()
    ([0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3], [0.0, 0.0, 1.0, 1.0, 1.0, 2.0, 3.0])
    """
    arrays: dict[str, np.ndarray] = {}
    for name, values in columns.items():
        try:
            a = np.asarray(values, dtype=float).ravel()
        except (TypeError, ValueError):
            raise DataError(f"column '{name}': values are not numbers", where=source) from None
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise DataError(f"column '{name}': {bad.size} value(s) are NaN or inf (first at sample {bad[0]})",
                            where=source)
        arrays[name] = a
    lengths = {name: a.size for name, a in arrays.items()}
    if len(set(lengths.values())) > 1:
        listed = ", ".join(f"'{k}' {v}" for k, v in lengths.items())
        raise DataError(f"columns have different lengths ({listed})", where=source)
    tt = arrays.pop(time)
    if tt.size < min_samples:
        raise DataError(f"column '{time}': needs at least {min_samples} samples, got {tt.size}", where=source)
    steps = np.diff(tt)
    if np.any(steps < 0):
        k = int(np.flatnonzero(steps < 0)[0]) + 1
        raise DataError(f"column '{time}': time is not strictly increasing at sample {k} (t = {tt[k]:g} s)",
                        where=source)
    notes: tuple[str, ...] = ()
    if np.any(steps == 0):
        keep = np.r_[steps > 0, True]  # the last sample of each run of equal time stamps
        first = int(np.flatnonzero(steps == 0)[0])
        if np.sum(~keep) > max(2.0, REPEATED_LIMIT * tt.size):
            raise DataError(f"column '{time}': {int(np.sum(~keep))} of {tt.size} samples repeat the time stamp "
                            f"before them (first at sample {first + 1}); is the time rounded? give the sample "
                            "interval (dt) instead", where=source)
        notes += (f"repeated time stamps: {int(np.sum(~keep))} sample(s) share a time stamp with the next "
                  f"(first at t = {tt[first]:g} s); kept the last of each",)
        tt, arrays = tt[keep], {k: v[keep] for k, v in arrays.items()}
        if tt.size < min_samples:
            raise DataError(f"column '{time}': needs at least {min_samples} distinct time stamps, got {tt.size}",
                            where=source)
        steps = np.diff(tt)
    spread = (steps.max() - steps.min()) / np.median(steps)
    if spread > IRREGULAR_TOLERANCE:
        notes += hidden_changes(tt, arrays, [h for h in held if h in arrays])
        tt, arrays, note = _resample(tt, arrays, [h for h in held if h in arrays])
        notes += (f"resampled: sample intervals ranged {steps.min():.4g}-{steps.max():.4g} s; {note}",)
    return tt, arrays, notes


def _resample(tt: np.ndarray, arrays: dict[str, np.ndarray], held: list[str]
              ) -> tuple[np.ndarray, dict[str, np.ndarray], str]:
    """Uniform grid from ``tt[0]`` to ``tt[-1]``: ``held`` columns zero-order held, the others linear."""
    median = float(np.median(np.diff(tt)))
    target = median
    for h in held:
        changes = tt[np.flatnonzero(np.diff(arrays[h]) != 0) + 1]
        if changes.size > 1:
            target = min(target, max(float(np.min(np.diff(changes))), median / 4))
    span = float(tt[-1] - tt[0])
    ratio = span / target
    # a regular log with gaps spans a whole number of intervals: that number, not one more for a rounding (a ramp,
    # changing at every stamp, has changes 0.0099999 s apart: 6,000 intervals of 0.0099983 s came out of 5,999 of
    # 0.01 s, and every logged sample an interpolated one)
    n = max(1, round(ratio) if abs(ratio - round(ratio)) <= 1e-6 * ratio else int(np.ceil(ratio)))
    grid = np.linspace(tt[0], tt[-1], n + 1)
    dt = span / n
    # a held value is the command's mean over the interval it holds on the grid, [g, g + dt): the integral of
    # the command as logged (held from each stamp to the next), so a linear model driven by the grid's hold
    # sees the edges where they were, to second order in the interval (an edge inside an interval shows as one
    # sample between the two levels). Taking one value per interval moved every edge to the grid: the value at
    # g (the last stamp before it) half an interval late on average, a lag that biased the fit (K 0.4 % and T
    # 1.2 % low, 30-46 of their reported std, on a first-order plant with 4-6 ms jittered stamps); the value
    # at g + dt/2 by up to half an interval either way, an error 10 times the reported std of the same fit
    first = np.clip(np.searchsorted(tt, grid, side="right") - 1, 0, tt.size - 1)  # the stamp holding g
    last = np.clip(np.searchsorted(tt, grid + dt, side="left") - 1, 0, tt.size - 1)  # the one holding g + dt-
    out = {}
    for k, v in arrays.items():
        if k not in held:
            out[k] = np.interp(grid, tt, v)
            continue
        held_value = v[first].copy()  # one stamp's value over the whole interval: exactly that value
        mixed = np.flatnonzero((v[last] != held_value)[:-1])  # the command changes inside these intervals
        if mixed.size:
            integral = np.concatenate([[0.0], np.cumsum(v[:-1] * np.diff(tt))])  # exact at the stamps, linear between
            at = np.interp(grid, tt, integral)
            mean = (at[mixed + 1] - at[mixed]) / dt
            ends = v[first[mixed]], v[last[mixed]]
            tiny = 1e-9 * np.abs(ends[1] - ends[0])  # an edge within rounding of the grid point: on it
            for end in ends:
                mean = np.where(np.abs(mean - end) <= tiny, end, mean)
            held_value[mixed] = mean
        out[k] = held_value
    note = f"onto a uniform {dt:.4g} s grid ({tt.size} -> {grid.size} samples)"
    for h in held:
        note += (f"; '{h}' held (zero-order hold, each interval at the command's mean over it: an edge inside an "
                 "interval is one sample between the two levels)")
    others = [k for k in out if k not in held]
    if others:
        note += f"; {', '.join(repr(k) for k in others)} linearly interpolated"
    return grid, out, note


def record_from_arrays(
    t: Sequence[float] | np.ndarray,
    u: Sequence[float] | np.ndarray,
    y: Sequence[float] | np.ndarray,
    input: Signal | None = None,
    output: Signal | None = None,
    aux: Mapping[str, Sequence[float] | np.ndarray] | None = None,
    source: str = "arrays",
    names: tuple[str, str, str] = ("time", "input", "output"),
    noise_factor: float | None = None,
    noise_correlation: Sequence[float] | None = None,
) -> Record:
    """Validate arrays and build a :class:`Record` (resampling irregular time explicitly).

    On irregular time the input (a command) is held between samples and the
    output and ``aux`` are interpolated linearly (see :func:`uniform_columns`).

    Parameters
    ----------
    t, u, y : array_like
        Time [s], input and output samples.
    input, output : Signal, optional
        Names and units; default ``u`` and ``y`` without unit.
    aux : mapping, optional
        Extra channels on the same time base.
    source : str
        Named in every error message (a file path).
    names : tuple of str
        Column names of ``t``, ``u``, ``y`` as the user wrote them, for error messages.
    noise_factor : float, optional
        :attr:`Record.noise_factor`; by default 1, or on irregular time what the output's interpolation implies
        (:func:`synth.data.interpolated_noise.interpolation_noise_factor`).
    noise_correlation : sequence of float, optional
        :attr:`Record.noise_correlation`; by default what the output's interpolation implies (``()`` on regular
        time).

    Raises
    ------
    DataError
        NaN or inf, non-increasing time, different lengths, fewer than 3 samples,
        a constant input or an output that never changes.

    Examples
    --------
    >>> r = record_from_arrays([0, 0.1, 0.25, 0.3], [0, 1, 1, 1], [0, 1, 2, 3])
    >>> r.t.round(3).tolist(), r.u.tolist(), r.notes[0].split(":")[0]
    ([0.0, 0.1, 0.2, 0.3], [0.0, 1.0, 1.0, 1.0], 'resampled')
    >>> record_from_arrays([0, 1, 0.5], [0, 1, 2], [0, 1, 2])
    Traceback (most recent call last):
    synth.errors.DataError: arrays: column 'time': time is not strictly increasing at sample 2 (t = 0.5 s)
    """
    input = input or Signal(names[1], "")
    output = output or Signal(names[2], "")
    tt, arrays, notes = uniform_columns({names[0]: t, names[1]: u, names[2]: y, **dict(aux or {})}, names[0], source,
                                        held=(names[1],))
    uu, yy = arrays.pop(names[1]), arrays.pop(names[2])
    for name, x in ((names[1], uu), (names[2], yy)):
        check_magnitude(name, x, source)
    if np.ptp(uu) == 0:
        raise DataError(f"column '{names[1]}': the input is constant ({uu[0]:g}); nothing excites the plant",
                        where=source)
    if np.ptp(yy) == 0:
        raise DataError(f"column '{names[2]}': the output never responds (constant {yy[0]:g})", where=source)
    logged = np.asarray(t, dtype=float).ravel()
    if noise_factor is None:  # exactly 1 unless the grid is not the logged stamps (resampled)
        noise_factor = interpolation_noise_factor(logged, tt)
        if noise_factor != 1.0:
            notes += (f"the interpolated output shares each logged sample's noise between grid samples: a fit's "
                      f"noise variance is taken {noise_factor:.3g} times its residuals' for the parameters' "
                      "uncertainty",)
    if noise_correlation is None:
        noise_correlation = interpolation_noise_correlation(logged, tt)
    gaps = find_gaps(logged)  # none on a uniform grid
    return Record(tt, uu, yy, input, output, arrays, source, notes, float(noise_factor), gaps,
                  tuple(float(r) for r in noise_correlation))


def read_columns(path: str | Path) -> dict[str, np.ndarray]:
    """All numeric columns of a CSV file (header row) or of a MAT file (see :func:`synth.data.readers.read_table`).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "r.csv"
    >>> _ = p.write_text("t,u,y\\n0,0,0\\n1,1,0.5\\n")
    >>> sorted(read_columns(p))
    ['t', 'u', 'y']
    """
    return read_table(path).columns


def load_record(
    path: str | Path,
    time: str | None = None,
    input: str | None = None,
    output: str | None = None,
    aux: Sequence[str] = (),
    input_unit: str = "",
    output_unit: str = "",
    dt: float | None = None,
    columns: Mapping[str, str] | None = None,
) -> Record:
    """Load one record from a CSV (header row) or MAT file.

    Parameters
    ----------
    path : str or Path
        ``.csv`` (any of ``, ; tab space`` as separator, ``#`` comment lines anywhere, units in the
        header such as ``Time (s)`` or ``Voltage [V]``) or ``.mat`` (MATLAB v5: vectors, matrix
        columns ``acc[0]``, ..., struct fields ``s.field``); see :mod:`synth.data.readers`.
    time, input, output : str, optional
        Column names, with or without the header's unit; default the first, second and third column.
        ``time`` may be omitted for a file without a time column if ``dt`` is given. A time column
        in ms (``Time (ms)``) is converted to seconds.
    aux : sequence of str
        Extra channels to carry along (current, voltage, ...).
    input_unit, output_unit : str
        Units of the input and output, carried into reports (default: the header's unit).
    dt : float, optional
        Sample interval [s] when the file has no time column.
    columns : mapping of str to str, optional
        Renames columns before they are picked, e.g. ``{"acc[0]": "accel_x"}``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "r.csv"
    >>> _ = p.write_text("t,pwm,speed (rad/s)\\n0,175,820\\n0.001,225,821\\n0.002,225,825\\n# end\\n")
    >>> r = load_record(p, "t", "pwm", "speed", input_unit="PWM")
    >>> r.input.label(), r.output.label(), r.y.tolist()
    ('pwm [PWM]', 'speed [rad/s]', [820.0, 821.0, 825.0])
    >>> load_record(p, "t", "pwm", "sped")
    Traceback (most recent call last):
    synth.errors.DataError: ...r.csv: output column 'sped' not found; did you mean 'speed (rad/s)'? columns are t, pwm, ...
    """
    path = Path(path)
    return record_from_columns(read_table(path, columns), str(path), time, input, output, aux, input_unit,
                               output_unit, dt)


def _pick(table: Table, name: str | None, role: str, fallback: int) -> str:
    """The column ``name`` means, or without a name the file's column at position ``fallback`` (one that is not
    numbers is then the error it is when named, not skipped for the next one)."""
    if name is None:
        keys = table.names()
        if len(keys) <= fallback:
            raise DataError(f"no {role} column given and the file has only {len(keys)} column(s)",
                            where=table.source)
        return table.find(keys[fallback], role)
    return table.find(name, role)


def record_from_columns(
    columns: Mapping[str, np.ndarray] | Table,
    source: str = "columns",
    time: str | None = None,
    input: str | None = None,
    output: str | None = None,
    aux: Sequence[str] = (),
    input_unit: str = "",
    output_unit: str = "",
    dt: float | None = None,
) -> Record:
    """Build a :class:`Record` from named columns (a file's :class:`~synth.data.readers.Table`, a dict's or a
    DataFrame's).

    Columns not named are taken in order: time, input, output (time may instead come from ``dt``).
    Names are found with or without the unit a header carries (``Time (s)``); that unit becomes the
    signal's unit unless ``input_unit``/``output_unit`` is given.

    Examples
    --------
    >>> cols = {"t": np.arange(5) * 0.1, "cmd": np.array([0, 1, 1, 1, 1.0]), "speed": np.arange(5.0)}
    >>> r = record_from_columns(cols, "lab.csv", input="cmd", output="speed", output_unit="rad/s")
    >>> r.input.name, r.output.label(), r.n
    ('cmd', 'speed [rad/s]', 5)
    >>> record_from_columns(cols, "lab.csv", output="rpm")
    Traceback (most recent call last):
    synth.errors.DataError: lab.csv: output column 'rpm' not found; columns are t, cmd, speed
    """
    table = columns if isinstance(columns, Table) else table_from_columns(columns, source)
    if not table.columns:
        raise DataError("no numeric columns found", where=table.source)
    from_dt = time is None and dt is not None
    if from_dt and not (np.isfinite(dt) and dt > 0):
        raise DataError(f"the sample interval must be a finite number > 0 s, got {dt!r}", where="dt")
    t_name = "time" if from_dt else _pick(table, time, "time", 0)
    shift = 1 if from_dt else 0  # without a time column, input and output default to the first two columns
    u_name = _pick(table, input, "input", 1 - shift)
    y_name = _pick(table, output, "output", 2 - shift)
    for name, given in ((u_name, input), (y_name, output)):
        if from_dt and given is None and looks_like_time(name, table.units.get(name, "")):
            raise DataError(f"column '{name}' looks like a time column, and with a sample interval given (dt) the "
                            "first columns are taken as input and output; drop the sample interval, or name the "
                            "input and output columns", where=table.source)
    aux_cols = {key: table.columns[key] for key in (_pick(table, a, "aux", 0) for a in aux)}
    roles = [("time", t_name)] * (not from_dt) + [("input", u_name), ("output", y_name)] + [("aux", k) for k in aux_cols]
    for i, (role, key) in enumerate(roles):
        other = next((r for r, k in roles[:i] if k == key), None)
        if other is not None:
            raise DataError(f"column '{key}' is given as both the {other} and the {role} column", where=table.source)
    scale = 1.0 if from_dt else time_scale(table.units.get(t_name, ""), t_name, table.source)
    t = np.arange(table.columns[u_name].size) * float(dt or 0) if from_dt else table.columns[t_name] * scale
    scaled = scale != 1.0
    notes = table.notes + ((f"time column '{t_name}' converted from {table.units[t_name]} to s",) if scaled else ())
    record = record_from_arrays(
        t, table.columns[u_name], table.columns[y_name], table.signal(u_name, input_unit),
        table.signal(y_name, output_unit), aux_cols, table.source, (t_name, u_name, y_name),
    )
    return replace(record, notes=notes + record.notes) if notes else record
