"""Exogenous signals: references, disturbances from a PSD or a measured record, shaped noise.

PSD convention: one-sided, in ``unit^2/(rad/s)``, so that the variance is
``integral_0^inf S(w) dw``. A table of ``(w, S)`` points is interpolated
linearly in log-log coordinates (the seed's "linear trend on a log-log
graph") and is zero outside its frequency range. Signals are synthesized
with random phases on the FFT grid of the record: the record's mean square
equals the sum ``S(w_k) dw`` exactly, whatever the seed.
"""

from __future__ import annotations

import csv
import itertools
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from synth.errors import DataError, ModelError

__all__ = [
    "PsdDisturbance", "RecordDisturbance", "Reference", "StepDisturbance", "psd_signal", "psd_value", "psd_variance",
    "step_reference", "validate_psd",
]

Reference = float | np.ndarray | Callable[[np.ndarray], np.ndarray]
"""A reference: a constant, one value per step, or a function of the time array (:func:`step_reference`)."""


def validate_psd(table: Any, where: str = "psd") -> tuple[tuple[float, float], ...]:
    """Check a PSD table: at least 2 points, increasing ``w > 0``, ``S >= 0``.

    Examples
    --------
    >>> validate_psd([[1, 0.1], [10, 0.01]])
    ((1.0, 0.1), (10.0, 0.01))
    """
    try:
        pts = tuple((float(w), float(s)) for w, s in table)
    except (TypeError, ValueError):
        raise ModelError(f"{where}: expected a list of [w, S] pairs") from None
    if len(pts) < 2:
        raise ModelError(f"{where}: give at least 2 [w, S] points")
    ws = [w for w, _ in pts]
    if any(not np.isfinite(w) or w <= 0 for w in ws) or any(b <= a for a, b in itertools.pairwise(ws)):
        raise ModelError(f"{where}: frequencies must be > 0 rad/s and strictly increasing")
    if any(not np.isfinite(s) or s < 0 for _, s in pts):
        raise ModelError(f"{where}: PSD values must be finite and >= 0")
    return pts


def psd_value(table: tuple[tuple[float, float], ...], w: np.ndarray) -> np.ndarray:
    """The PSD at ``w`` (rad/s): log-log interpolation, 0 outside the table.

    Examples
    --------
    >>> psd_value(((1.0, 1.0), (100.0, 1e-4)), np.array([0.5, 10.0, 200.0])).tolist()
    [0.0, 0.01, 0.0]
    """
    w = np.asarray(w, float)
    ws = np.array([p[0] for p in table])
    ss = np.array([p[1] for p in table])
    out = np.zeros_like(w)
    inside = (w >= ws[0]) & (w <= ws[-1])
    if not np.any(inside):
        return out
    positive = ss > 0
    if np.all(positive):
        out[inside] = np.exp(np.interp(np.log(w[inside]), np.log(ws), np.log(ss)))
    else:  # a zero in the table: interpolate linearly in S on a log-w axis
        out[inside] = np.interp(np.log(w[inside]), np.log(ws), ss)
    return out


def psd_signal(table: tuple[tuple[float, float], ...], n: int, dt: float, rng: np.random.Generator) -> np.ndarray:
    """``n`` samples (step ``dt``) of a zero-mean signal with the one-sided PSD ``table``.

    Each FFT bin ``w_k = 2 pi k/(n dt)`` gets amplitude ``sqrt(2 S(w_k) dw)`` and a uniform
    random phase; the mean square of the record is ``sum S(w_k) dw``.

    Examples
    --------
    >>> x = psd_signal(((1.0, 0.02), (1000.0, 0.02)), 20000, 0.001, np.random.default_rng(0))
    >>> round(float(np.mean(x**2)), 2)  # 0.02 * (1000 - 1) rad/s
    19.98
    """
    if n <= 0:
        return np.zeros(0)
    dw = 2 * np.pi / (n * dt)
    k = np.arange(n // 2 + 1)
    w = k * dw
    amp = np.sqrt(2.0 * psd_value(table, w) * dw)
    amp[0] = 0.0
    if n % 2 == 0:
        amp[-1] = 0.0  # the Nyquist bin has no phase freedom; leave it out
    phase = rng.uniform(0.0, 2 * np.pi, size=k.size)
    spectrum = amp * np.exp(1j * phase) * (n / 2.0)
    return np.fft.irfft(spectrum, n)


def psd_variance(table: tuple[tuple[float, float], ...], n: int, dt: float) -> float:
    """Mean square :func:`psd_signal` produces for these ``n`` and ``dt`` (its exact value).

    Examples
    --------
    >>> round(psd_variance(((1.0, 0.02), (1000.0, 0.02)), 20000, 0.001), 2)
    19.98
    """
    dw = 2 * np.pi / (n * dt)
    k = np.arange(1, (n - 1) // 2 + 1)
    return float(np.sum(psd_value(table, k * dw)) * dw)


@dataclass(frozen=True)
class PsdDisturbance:
    """A random disturbance with a one-sided PSD, added at the plant ``input`` or ``output``.

    Examples
    --------
    >>> d = PsdDisturbance(((1.0, 1.0), (100.0, 0.01)), at="output")
    >>> d.signal(np.arange(1000) * 0.001, np.random.default_rng(0)).shape
    (1000,)
    """

    psd: tuple[tuple[float, float], ...]
    at: str = "output"

    def __post_init__(self) -> None:
        object.__setattr__(self, "psd", validate_psd(self.psd))
        _check_at(self.at)

    def signal(self, t: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Samples at the uniformly spaced times ``t``."""
        dt = float(t[1] - t[0]) if t.size > 1 else 1.0
        return psd_signal(self.psd, t.size, dt, rng)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"type": "psd", "at": self.at, "psd": [list(p) for p in self.psd]}


@dataclass(frozen=True)
class RecordDisturbance:
    """A disturbance given as samples ``(time, value)`` (e.g. a measured record), linearly
    interpolated onto the simulation grid; the record must cover the simulated time.

    Examples
    --------
    >>> d = RecordDisturbance((0.0, 1.0, 2.0), (0.0, 2.0, 0.0), at="input")
    >>> d.signal(np.array([0.5, 1.5]), np.random.default_rng(0)).tolist()
    [1.0, 1.0]
    """

    time: tuple[float, ...]
    value: tuple[float, ...]
    at: str = "output"
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        _check_at(self.at)
        t = np.asarray(self.time, float)
        v = np.asarray(self.value, float)
        where = self.source or "disturbance record"
        if t.size < 2 or t.size != v.size:
            raise DataError("needs at least 2 samples with one time each", where=where)
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise DataError("has missing or non-finite values", where=where)
        if np.any(np.diff(t) <= 0):
            i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
            raise DataError(f"time is not strictly increasing at row {i + 1} (t = {t[i]:g} s)", where=where)
        object.__setattr__(self, "time", tuple(float(x) for x in t))
        object.__setattr__(self, "value", tuple(float(x) for x in v))

    def signal(self, t: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """The record at times ``t`` (record time 0 = simulation time 0)."""
        t0, t1 = self.time[0], self.time[-1]
        if t.size and (t[0] < t0 - 1e-12 or t[-1] > t1 + 1e-9):
            raise DataError(f"covers {t0:g} to {t1:g} s; the simulation needs {t[0]:g} to {t[-1]:g} s "
                            "(shorten the horizon)", where=self.source or "disturbance record")
        return np.interp(t, self.time, self.value)

    @classmethod
    def from_csv(cls, path: str | Path, time: str, value: str, at: str = "output",
                 scale: float = 1.0, start: float | None = None) -> RecordDisturbance:
        """Read columns ``time`` and ``value`` of a CSV file with a header row.

        ``start`` shifts the record so that this record time is simulation time 0 (default:
        its first time); ``scale`` multiplies the values.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> p = pathlib.Path(tempfile.mkdtemp()) / "d.csv"
        >>> _ = p.write_text("t,load\\n1.0,0\\n2.0,4\\n")
        >>> RecordDisturbance.from_csv(p, "t", "load", scale=0.5).value
        (0.0, 2.0)
        """
        path = Path(path)
        if not path.exists():
            raise DataError("file not found", where=str(path))
        with path.open(newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            fields = reader.fieldnames or []
            for col in (time, value):
                if col not in fields:
                    raise DataError(f"no column {col!r}; columns are: {', '.join(fields)}", where=str(path))
            ts, vs = [], []
            for i, row in enumerate(reader, start=2):
                try:
                    ts.append(float(row[time]))
                    vs.append(float(row[value]))
                except (TypeError, ValueError):
                    raise DataError(f"line {i}: expected numbers in {time!r} and {value!r}, got "
                                    f"{row.get(time)!r}, {row.get(value)!r}", where=str(path)) from None
        t = np.asarray(ts)
        offset = (t[0] if t.size else 0.0) if start is None else float(start)
        return cls(tuple(t - offset), tuple(np.asarray(vs) * scale), at, str(path))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (not the samples)."""
        return {"type": "record", "at": self.at, "source": self.source, "samples": len(self.time),
                "span": [self.time[0], self.time[-1]]}


@dataclass(frozen=True)
class StepDisturbance:
    """A step of ``size`` at time ``at_time``, at the plant ``input`` or ``output`` (a load change).

    Examples
    --------
    >>> StepDisturbance(2.0, at_time=0.5).signal(np.array([0.0, 0.5, 1.0]), None).tolist()
    [0.0, 2.0, 2.0]
    """

    size: float
    at_time: float = 0.0
    at: str = "output"

    def __post_init__(self) -> None:
        _check_at(self.at)

    def signal(self, t: np.ndarray, rng: np.random.Generator | None) -> np.ndarray:
        """Samples at times ``t``."""
        return np.where(t >= self.at_time - 1e-12, float(self.size), 0.0)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"type": "step", "at": self.at, "size": self.size, "time": self.at_time}


def _check_at(at: str) -> None:
    if at not in ("input", "output"):
        raise ModelError(f"a disturbance acts at 'input' or 'output', got {at!r}")


def step_reference(start: float, end: float, t_step: float = 0.0):
    """A reference that steps from ``start`` to ``end`` at ``t_step`` (a callable of time).

    Its ``initial`` attribute (``start``) is the reference the loop rests at before ``t = 0``,
    so a step at ``t_step = 0`` starts from rest at ``start``.

    Examples
    --------
    >>> r = step_reference(820, 920, 0.1)
    >>> r(np.array([0.0, 0.1, 0.2])).tolist(), r.initial
    ([820.0, 920.0, 920.0], 820.0)
    """
    def r(t: np.ndarray) -> np.ndarray:
        return np.where(np.asarray(t) >= t_step - 1e-12, float(end), float(start))

    r.initial = float(start)  # type: ignore[attr-defined]
    return r
