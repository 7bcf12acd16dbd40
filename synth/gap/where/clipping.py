"""Clipping seen directly in a record: a continuous-valued signal that rests on its extreme value.

A measured signal with noise or a continuous controller output almost never takes
the same value twice. When many of its samples sit on exactly one value, and
that value is the signal's maximum (or minimum), something cut the signal
there: a sensor's range, a tank that overflows, an actuator limit applied before
the signal was logged. That is direct evidence of a saturation, independent of
any model, and it also fixes the limit's value.

The test, for each end of the signal:

- at least ``min_samples`` samples equal the extreme value exactly;
- that count is more than ``ratio`` times the largest count of any other
  single value (a quantized signal repeats every value; a clipped one repeats
  only its limit);
- the other samples are continuous-valued: at least ``min_distinct`` of them
  are distinct values (a step command rests on its levels by design and has
  only a few values; it is not tested).

A signal that fails the last condition is reported as not testable rather
than as clean: coarse quantization and clipping cannot be told apart by
counting values.

What a clip means depends on the column. On the output, the model's output
needs the same clip (``saturation(output)``). On the logged command, the limit
acted before the command was logged, so a model driven by the logged command
already sees it: the saturation is in the record, not in the gap; the
controller's unlimited output (if it can be rebuilt) is what would show it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from synth.data.record import Record

__all__ = ["Clipping", "find_clipping", "record_clipping"]


@dataclass(frozen=True)
class Clipping:
    """One end of a signal resting on its extreme value.

    Attributes
    ----------
    column : str
        ``"input"`` or ``"output"`` (the record's side).
    name : str
        The column's name in the record.
    side : str
        ``"upper"`` (the maximum) or ``"lower"`` (the minimum).
    level : float
        The value the samples rest on [column units].
    samples : int
        Samples exactly at ``level``.
    runs : int
        Runs of consecutive samples at ``level``.
    longest : int
        Longest such run [samples].
    other_repeats : int
        Largest count of any other single value in the signal.
    unit : str
        The column's unit.
    record : str
        Which record: ``"record"`` or ``"validate"``.

    Examples
    --------
    >>> c = Clipping("output", "level", "upper", 10.0, 47, 2, 30, 3, "V")
    >>> c.effect
    'saturation(output)'
    >>> c.describe()[:63]
    'the output level rests on its maximum 10 V for 47 samples in 2 '
    """

    column: str
    name: str
    side: str
    level: float
    samples: int
    runs: int
    longest: int
    other_repeats: int
    unit: str = ""
    record: str = "record"

    @property
    def effect(self) -> str:
        """The library effect the clip is evidence of."""
        return "saturation(output)" if self.column == "output" else "saturation"

    def describe(self) -> str:
        """One plain sentence: which signal, which level, how many samples."""
        end = "maximum" if self.side == "upper" else "minimum"
        unit = f" {self.unit}" if self.unit else ""
        where = {"record": "", "validate": " (validation record)"}.get(self.record, f" (validation run {self.record[9:]})")
        name = f" {self.name}" if self.name != self.column else ""  # a record's unnamed columns: "the output"
        text = (f"the {self.column}{name}{where} rests on its {end} {self.level:.4g}{unit} for {self.samples} samples "
                f"in {self.runs} run{'s' if self.runs != 1 else ''} (longest {self.longest}; no other value occurs "
                f"more than {self.other_repeats} time{'s' if self.other_repeats != 1 else ''}): clipped")
        if self.column == "input":
            text += ("; the limit acted before the command was logged, so a model driven by the logged command "
                     "already sees it")
        return text

    def to_dict(self) -> dict[str, Any]:
        """JSON: the attributes, ``effect`` and ``description``."""
        return {**asdict(self), "effect": self.effect, "description": self.describe()}


def _runs(at: np.ndarray) -> tuple[int, int]:
    """Number of runs of ``True`` in ``at`` and the longest one."""
    edges = np.diff(np.r_[0, at.astype(np.int8), 0])
    lengths = np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)
    return int(lengths.size), int(lengths.max()) if lengths.size else 0


def find_clipping(x: np.ndarray, column: str = "output", name: str = "", unit: str = "", *, record: str = "record",
                  min_samples: int = 3, ratio: float = 2.0, min_distinct: float = 0.5,
                  resting: np.ndarray | None = None) -> list[Clipping]:
    """Ends of ``x`` where the signal rests on its extreme value (see the module text).

    Parameters
    ----------
    x : ndarray
        The signal (finite values).
    column : {"input", "output"}
        The record's side the signal is on.
    name, unit : str
        The column's name and unit (for the description).
    record : str
        Which record the signal comes from (``"record"``, ``"validate"``).
    min_samples : int
        Samples at the extreme needed to call it a clip.
    ratio : float
        The extreme's count must exceed ``ratio`` times any other value's count.
    min_distinct : float
        Share of distinct values among the other samples for the signal to be continuous-valued.
    resting : ndarray of bool, optional
        Samples left out of the count: where the plant rests (its command at its initial level), an output
        that holds one value is at rest, not clipped (an encoder reads exactly 0 while the motor stands).

    Returns
    -------
    list of Clipping
        Upper end first; empty when neither end is clipped or the signal is not continuous-valued.

    Examples
    --------
    >>> import numpy as np
    >>> y = np.minimum(np.sin(np.linspace(0, 20, 2000)), 0.8)  # four crests cut at 0.8
    >>> [(c.side, c.level, c.runs) for c in find_clipping(y)]
    [('upper', 0.8, 4)]
    >>> find_clipping(np.repeat([5.0, 15.0], 100), "input")  # a step command rests on its levels by design
    []
    >>> y = np.r_[np.zeros(200), 1 - np.exp(-np.linspace(0.01, 5, 500))]   # at rest, then a step response
    >>> len(find_clipping(y)), find_clipping(y, resting=np.r_[np.ones(200, bool), np.zeros(500, bool)])
    (1, [])
    """
    x = np.asarray(x, float).ravel()
    if resting is not None:
        x = x[~np.asarray(resting, bool).ravel()]
    if column not in ("input", "output"):
        raise ValueError(f"column must be 'input' or 'output', got {column!r}")
    if x.size < 2 * min_samples or not np.all(np.isfinite(x)):
        return []
    values, counts = np.unique(x, return_counts=True)
    if values.size < 3:
        return []
    found: list[Clipping] = []
    for side, k in (("upper", values.size - 1), ("lower", 0)):
        n_at = int(counts[k])
        rest = np.delete(counts, k)
        others = int(rest.max())
        if n_at < min_samples or n_at <= ratio * others:
            continue
        if values.size - 1 < min_distinct * (x.size - n_at):  # step levels or coarse quantization
            continue
        runs, longest = _runs(x == values[k])
        found.append(Clipping(column, name or column, side, float(values[k]), n_at, runs, longest, others, unit, record))
    return found


def record_clipping(record: Record, which: str = "record") -> list[Clipping]:
    """Clipping of a record's command and output (:func:`find_clipping` on each; the output's samples where the
    command sits at its initial level are the plant at rest and left out).

    Parameters
    ----------
    record : Record
    which : str
        ``"record"`` or ``"validate"`` (kept in each :class:`Clipping`).

    Returns
    -------
    list of Clipping
        The input's first, then the output's.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 20, 0.01); u = np.sin(t)
    >>> [c.effect for c in record_clipping(record_from_arrays(t, u, np.minimum(2 * u, 1.5)))]
    ['saturation(output)']
    """
    return [*find_clipping(record.u, "input", record.input.name, record.input.unit, record=which),
            *find_clipping(record.y, "output", record.output.name, record.output.unit, record=which,
                           resting=record.u == record.u[0])]
