"""Where in time the residual lies: energy windows, steps and drift together.

Energy windows: the record is cut into ``n_bins`` bins of equal length; the
residual energy of each bin is compared with the median bin energy (the
typical, noise-only level when most of the record is fitted well). Bins above
``factor`` times that level are kept, neighbours are merged into windows, and
each window is reported as ``[t0, t1, share]`` with its share of the residual
energy of the whole record, largest share first. A residual spread evenly
over the record (noise, or a gain error on a sweep) gives no window.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.errors import DataError
from synth.gap.where.drift import DriftResult, cusum_drift
from synth.gap.where.residual import ModelResidual
from synth.gap.where.steps import StepResult, analyze_steps, phase_shares

__all__ = ["TimeLocalization", "TimeWindow", "energy_windows", "localize_time"]


@dataclass(frozen=True)
class TimeWindow:
    """A stretch of the record holding a large part of the residual energy.

    Examples
    --------
    >>> TimeWindow(1.0, 1.5, 0.42).to_list()
    [1.0, 1.5, 0.42]
    """

    t0: float
    t1: float
    share: float

    def to_list(self) -> list[float]:
        """``[t0, t1, share]`` as in the JSON contract."""
        return [self.t0, self.t1, self.share]


def energy_windows(t: np.ndarray, e: np.ndarray, n_bins: int = 100, factor: float = 4.0,
                   max_windows: int = 20) -> list[TimeWindow]:
    """Windows whose residual energy stands out (see the module text), largest share first.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 10, 0.01)
    >>> e = 0.01 * np.random.default_rng(0).normal(size=t.size) + np.where((t > 4) & (t < 5), 1.0, 0.0)
    >>> w = energy_windows(t, e)
    >>> len(w), round(w[0].t0, 1), round(w[0].t1, 1), round(w[0].share, 2)
    (1, 4.0, 5.0, 1.0)
    """
    t = np.asarray(t, float)
    e2 = np.asarray(e, float) ** 2
    if t.shape != e2.shape:
        raise DataError("time and residual must have the same length", where="residual")
    n = max(1, min(int(n_bins), t.size // 5))
    total = float(np.sum(e2))
    if n < 3 or total == 0.0:
        return []
    bounds = np.linspace(0, t.size, n + 1).astype(int)
    energy = np.add.reduceat(e2, bounds[:-1])
    keep = energy > factor * float(np.median(energy))
    windows: list[TimeWindow] = []
    i = 0
    while i < n:
        if not keep[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and keep[j + 1]:
            j += 1
        k0, k1 = bounds[i], bounds[j + 1]
        windows.append(TimeWindow(float(t[k0]), float(t[min(k1, t.size - 1)]), float(np.sum(e2[k0:k1]) / total)))
        i = j + 1
    windows.sort(key=lambda w: -w.share)
    return windows[:max_windows]


@dataclass(frozen=True)
class TimeLocalization:
    """The time part of the diagnosis.

    Attributes
    ----------
    windows : list of TimeWindow
        Energy windows, largest share first.
    steps : list of StepResult
        Every analysed step of the input.
    phases : dict
        Residual-energy share by direction and phase (``{"up": {"rise": ...}, "down": {...}}``).
    drift : DriftResult

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.where.residual import model_residual
    >>> from synth.plant import Plant
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 6, 0.01)
    >>> u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> rec = record_from_arrays(t, u, simulate_plant(Plant.from_string("1/(0.2*s+1)"), t, u))
    >>> loc = localize_time(model_residual(Plant.from_string("1/(0.05*s+1)"), rec))
    >>> max(loc.phases["up"], key=loc.phases["up"].get), loc.drift.detected
    ('rise', False)
    """

    windows: list[TimeWindow]
    steps: list[StepResult]
    phases: dict[str, dict[str, float]]
    drift: DriftResult

    @property
    def steps_share(self) -> float:
        """Share of the residual energy inside the analysed steps."""
        return float(sum(s.share for s in self.steps))

    def dominant_phase(self) -> tuple[str, str, float] | None:
        """``(direction, phase, share)`` of the largest step-phase share, or ``None`` without steps."""
        if not self.steps:
            return None
        best = max(((d, p, v) for d, ph in self.phases.items() for p, v in ph.items()), key=lambda x: x[2])
        return best

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        return {"time_windows": [w.to_list() for w in self.windows], "steps": [s.to_dict() for s in self.steps],
                "phases": {d: dict(v) for d, v in self.phases.items()}, "steps_share": self.steps_share,
                "drift": self.drift.to_dict()}


def localize_time(residual: ModelResidual, n_bins: int = 100, factor: float = 4.0, min_fraction: float = 0.2,
                  settle_band: float = 0.05, false_alarm: float = 0.05) -> TimeLocalization:
    """Energy windows, per-step phases and CUSUM drift of a model's residual.

    Parameters
    ----------
    residual : ModelResidual
        From :func:`synth.gap.where.residual.model_residual`.
    n_bins, factor : int, float
        Energy-window bins and the factor above the median bin energy.
    min_fraction, settle_band : float
        Step detection and settling band (see :mod:`synth.gap.where.steps`).
    false_alarm : float
        CUSUM false-alarm chance per record (see :mod:`synth.gap.where.drift`).

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.where.residual import model_residual
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 20, 0.01)
    >>> u = np.sin(t)
    >>> r = model_residual(Plant.from_string("1/(0.1*s+1)"), record_from_arrays(t, u, u + 0.01 * np.cos(7 * t)))
    >>> loc = localize_time(r)
    >>> loc.steps, loc.windows
    ([], [])
    """
    windows = energy_windows(residual.t, residual.e, n_bins, factor)
    steps = analyze_steps(residual.t, residual.u, residual.y, residual.y_model, min_fraction=min_fraction,
                          settle_band=settle_band)
    steady = np.ones(residual.t.size, bool)
    for s in steps:
        steady[(residual.t >= s.edge.t) & (residual.t <= s.phase_ends["overshoot"])] = False
    drift = cusum_drift(residual.t, residual.e, false_alarm=false_alarm, mask=steady)
    return TimeLocalization(windows, steps, phase_shares(steps), drift)
