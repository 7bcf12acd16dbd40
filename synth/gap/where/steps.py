"""Steps in the input, and how the model's and the record's responses to each differ.

An edge is a sample where the input jumps by more than ``min_fraction`` of its
range and by more than eight robust standard deviations of its sample-to-sample
changes (1.4826 times the median absolute deviation of ``diff(u)``); jumps
on neighbouring samples are one edge. A step lasts from its edge to the next
one; steps shorter than ``min_dwell`` samples are not analysed (a random
binary input is not a step train).

For each step, both the record and the model get the classical metrics on
their own initial level (the mean of up to five samples before the edge) and
final level (the mean of the last 20 % of the step): 10-90 % rise time,
overshoot [%] and settling time into a band of ``settle_band`` around the
final level, measured from the edge. The step is cut into three phases,
each ending where the *later* of the two responses (record or model) ends it:

- rise: from the edge to the later 90 % crossing;
- overshoot: from there to the later settling time;
- settle: the rest of the step.

The residual energy ``sum(e^2)`` in each phase is reported as a share of the
residual energy of the whole record.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.errors import DataError

__all__ = ["PHASES", "StepEdge", "StepMetrics", "StepResult", "analyze_steps", "detect_steps", "phase_shares",
           "step_metrics"]

PHASES = ("rise", "overshoot", "settle")


@dataclass(frozen=True)
class StepEdge:
    """A jump of the input.

    Attributes
    ----------
    index : int
        First sample at the new input level.
    t : float
        Its time [s].
    size : float
        New level minus old level (input units).

    Examples
    --------
    >>> StepEdge(10, 0.1, -2.0).direction
    'down'
    """

    index: int
    t: float
    size: float

    @property
    def direction(self) -> str:
        """``"up"`` or ``"down"``."""
        return "up" if self.size > 0 else "down"


def detect_steps(t: np.ndarray, u: np.ndarray, min_fraction: float = 0.2) -> list[StepEdge]:
    """Edges of the input (jumps larger than ``min_fraction`` of its range and than its noise).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 1, 0.01)
    >>> u = np.where((t >= 0.2) & (t < 0.6), 5.0, 1.0)
    >>> [(e.index, e.size) for e in detect_steps(t, u)]
    [(20, 4.0), (60, -4.0)]
    """
    t = np.asarray(t, float)
    u = np.asarray(u, float)
    if t.shape != u.shape or t.size < 3:
        raise DataError("time and input must have the same length (at least 3 samples)", where="input")
    if not 0.0 < min_fraction < 1.0:
        raise DataError(f"must be in (0, 1), got {min_fraction!r}", where="min_fraction")
    du = np.diff(u)
    noise = 1.4826 * float(np.median(np.abs(du - np.median(du))))
    threshold = max(min_fraction * float(np.ptp(u)), 8.0 * noise)
    jumps = np.flatnonzero(np.abs(du) > threshold)
    edges: list[StepEdge] = []
    i = 0
    while i < jumps.size:
        j = i
        while j + 1 < jumps.size and jumps[j + 1] - jumps[j] <= 2:
            j += 1
        k0, k1 = int(jumps[i]), int(jumps[j]) + 1
        edges.append(StepEdge(k0 + 1, float(t[k0 + 1]), float(u[k1] - u[k0])))
        i = j + 1
    return edges


@dataclass(frozen=True)
class StepMetrics:
    """Classical step-response numbers of one response (``None`` where undefined).

    Attributes
    ----------
    initial, final : float
        Levels before the edge and at the end of the step.
    rise_time : float or None
        10-90 % rise time [s].
    t90 : float or None
        Time from the edge to the 90 % crossing [s].
    overshoot_percent : float or None
        Peak beyond the final level, in % of the step.
    settling_time : float or None
        Time from the edge until the response stays within the band [s].

    Examples
    --------
    >>> StepMetrics(0.0, 1.0, 0.2, 0.25, 0.0, 0.3).to_dict()["rise_time"]
    0.2
    """

    initial: float
    final: float
    rise_time: float | None
    t90: float | None
    overshoot_percent: float | None
    settling_time: float | None

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        return {"initial": self.initial, "final": self.final, "rise_time": self.rise_time, "t90": self.t90,
                "overshoot_percent": self.overshoot_percent, "settling_time": self.settling_time}


def _crossing(tt: np.ndarray, z: np.ndarray, level: float) -> float | None:
    """First time the normalized response ``z`` reaches ``level`` (linear interpolation)."""
    above = np.flatnonzero(z >= level)
    if above.size == 0:
        return None
    k = int(above[0])
    if k == 0:
        return float(tt[0])
    z0, z1 = z[k - 1], z[k]
    return float(tt[k - 1] + (level - z0) / (z1 - z0) * (tt[k] - tt[k - 1]))


def step_metrics(tt: np.ndarray, x: np.ndarray, before: np.ndarray, settle_band: float = 0.05) -> StepMetrics:
    """Metrics of the response ``x`` at times ``tt`` (``tt[0]`` is the edge), ``before`` the samples before it.

    Examples
    --------
    >>> import numpy as np
    >>> tt = np.arange(0, 15, 0.001)
    >>> m = step_metrics(tt, 1 - np.exp(-tt), np.zeros(3))
    >>> round(m.rise_time, 3), round(m.settling_time, 2), m.overshoot_percent
    (2.197, 3.0, 0.0)
    """
    x0 = float(np.mean(before))
    tail = x[int(0.8 * x.size):] if x.size >= 15 else x[-3:]
    x1 = float(np.mean(tail))
    span = x1 - x0
    if abs(span) <= 1e-12 * max(1.0, abs(x0), abs(x1)):
        return StepMetrics(x0, x1, None, None, None, None)
    z = (x - x0) / span
    rel = tt - tt[0]
    t10, t90 = _crossing(rel, z, 0.1), _crossing(rel, z, 0.9)
    rise = None if t10 is None or t90 is None else t90 - t10
    overshoot = 100.0 * max(0.0, float(np.max(z)) - 1.0)
    outside = np.flatnonzero(np.abs(z - 1.0) > settle_band)
    if outside.size == 0:
        settling = 0.0
    elif outside[-1] + 1 < z.size:
        settling = float(rel[outside[-1] + 1])
    else:
        settling = None
    return StepMetrics(x0, x1, rise, t90, overshoot, settling)


@dataclass(frozen=True)
class StepResult:
    """One step: metrics of record and model, and where its residual energy lies.

    Attributes
    ----------
    edge : StepEdge
    t_end : float
        End of the step (next edge or end of record) [s].
    record, model : StepMetrics
    phase_ends : dict of str to float
        End time [s] of the rise and overshoot phases.
    shares : dict of str to float
        Residual energy in each phase (``rise``, ``overshoot``, ``settle``) as a share of the whole record's.

    Examples
    --------
    >>> m = StepMetrics(0.0, 1.0, 0.2, 0.25, 0.0, 0.3)
    >>> s = StepResult(StepEdge(5, 0.5, 1.0), 2.0, m, m, {"rise": 0.75, "overshoot": 0.8},
    ...                {"rise": 0.5, "overshoot": 0.1, "settle": 0.1})
    >>> round(s.share, 3), s.to_dict()["direction"]
    (0.7, 'up')
    """

    edge: StepEdge
    t_end: float
    record: StepMetrics
    model: StepMetrics
    phase_ends: dict[str, float]
    shares: dict[str, float]

    @property
    def share(self) -> float:
        """Residual energy of the whole step as a share of the record's."""
        return float(sum(self.shares.values()))

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        return {"t": self.edge.t, "t_end": self.t_end, "size": self.edge.size, "direction": self.edge.direction,
                "record": self.record.to_dict(), "model": self.model.to_dict(), "phase_ends": dict(self.phase_ends),
                "shares": dict(self.shares), "share": self.share}


def _later(a: float | None, b: float | None, default: float) -> float:
    values = [v for v in (a, b) if v is not None]
    return max(values) if values else default


def analyze_steps(t: np.ndarray, u: np.ndarray, y: np.ndarray, y_model: np.ndarray, min_fraction: float = 0.2,
                  min_dwell: int = 10, settle_band: float = 0.05) -> list[StepResult]:
    """Detect the input's steps and compare the record's and the model's response to each.

    Parameters
    ----------
    t, u, y, y_model : numpy.ndarray
        Time [s], input, measured output and model output (offset included).
    min_fraction : float
        Smallest jump counted as a step, as a fraction of the input's range.
    min_dwell : int
        Steps shorter than this many samples are skipped.
    settle_band : float
        Settling band as a fraction of the step (0.05: within 5 %).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 2, 0.01)
    >>> u = np.where(t >= 0.5, 1.0, 0.0)
    >>> ym = u * (1 - np.exp(-np.clip(t - 0.5, 0, None) / 0.05))
    >>> y = u * (1 - np.exp(-np.clip(t - 0.5, 0, None) / 0.1))
    >>> s = analyze_steps(t, u, y, ym)[0]
    >>> s.edge.direction, round(s.record.rise_time / s.model.rise_time, 1), max(s.shares, key=s.shares.get)
    ('up', 2.0, 'rise')
    """
    t, u, y, y_model = (np.asarray(a, float) for a in (t, u, y, y_model))
    e = y - y_model
    total = float(np.sum(e**2))
    edges = detect_steps(t, u, min_fraction)
    results: list[StepResult] = []
    for n, edge in enumerate(edges):
        k0 = edge.index
        k1 = edges[n + 1].index if n + 1 < len(edges) else t.size
        if k1 - k0 < min_dwell:
            continue
        lo = max(0, k0 - 4, edges[n - 1].index if n > 0 else 0)
        before = slice(lo, k0 + 1) if k0 > lo else slice(k0, k0 + 1)
        tt = t[k0:k1]
        rec = step_metrics(tt, y[k0:k1], y[before], settle_band)
        mod = step_metrics(tt, y_model[k0:k1], y_model[before], settle_band)
        t_last = float(t[k1 - 1])
        rise_end = min(edge.t + _later(rec.t90, mod.t90, t_last - edge.t), t_last)
        over_end = min(max(edge.t + _later(rec.settling_time, mod.settling_time, t_last - edge.t), rise_end), t_last)
        seg_t, seg_e2 = tt, e[k0:k1] ** 2
        masks = {"rise": seg_t <= rise_end, "overshoot": (seg_t > rise_end) & (seg_t <= over_end),
                 "settle": seg_t > over_end}
        shares = {p: (float(np.sum(seg_e2[m])) / total if total > 0 else 0.0) for p, m in masks.items()}
        end = float(t[k1]) if k1 < t.size else t_last
        results.append(StepResult(edge, end, rec, mod, {"rise": rise_end, "overshoot": over_end}, shares))
    return results


def phase_shares(steps: list[StepResult]) -> dict[str, dict[str, float]]:
    """Residual-energy shares summed by direction (``up``/``down``) and phase.

    Examples
    --------
    >>> m = StepMetrics(0.0, 1.0, 0.2, 0.25, 0.0, 0.3)
    >>> s = StepResult(StepEdge(5, 0.5, 1.0), 2.0, m, m, {}, {"rise": 0.5, "overshoot": 0.1, "settle": 0.1})
    >>> phase_shares([s, s])["up"]["rise"]
    1.0
    """
    out = {d: dict.fromkeys(PHASES, 0.0) for d in ("up", "down")}
    for s in steps:
        for p in PHASES:
            out[s.edge.direction][p] += s.shares[p]
    return out
