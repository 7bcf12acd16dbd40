"""A fitted model checked against a separate step record (NASA report, model verification in time)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.data import Record
from synth.errors import DataError
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["StepVerification", "verify_step"]


@dataclass(frozen=True)
class StepVerification:
    """A fitted model simulated against a separate step record.

    Attributes
    ----------
    fit_percent : float
        ``100 (1 - NRMSE)``.
    nrmse : float
        ``||y - y_model|| / ||y - mean(y)||``.
    rmse : float
        Root-mean-square error (output units).
    t, u, y, y_model : numpy.ndarray
        The record and the simulated output.
    source : str

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> G = Plant.from_string("2/(s+1)", delay=0.1)
    >>> t = np.arange(0, 8, 0.01); u = np.where(t > 1, 1.0, 0.0)
    >>> v = verify_step(G, record_from_arrays(t, u, 5 + simulate_plant(G, t, u)))
    >>> round(v.fit_percent, 6)
    100.0
    """

    fit_percent: float
    nrmse: float
    rmse: float
    t: np.ndarray = field(repr=False)
    u: np.ndarray = field(repr=False)
    y: np.ndarray = field(repr=False)
    y_model: np.ndarray = field(repr=False)
    source: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (no samples)."""
        return {"fit_percent": self.fit_percent, "nrmse": self.nrmse, "rmse": self.rmse, "source": self.source,
                "samples": int(self.t.size),
                "method": "model driven by the record's input from rest at its first sample; "
                          "fit = 100 (1 - ||y - y_model|| / ||y - mean y||)"}


def verify_step(plant: Plant, record: Record) -> StepVerification:
    """Simulate ``plant`` on a step record's input and compare with its output.

    The model starts at rest at the record's first sample: ``y_model = y0 +
    G * (u - u[0])``, ``y0`` the mean output before the input first moves.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 5, 0.01); u = np.where(t > 1, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("1/(s+1)"), t, u)
    >>> round(verify_step(Plant.from_string("1.1/(s+1)"), record_from_arrays(t, u, y)).fit_percent, 1)
    81.3
    """
    if record.n < 3:
        raise DataError("step record needs at least 3 samples", where=record.source)
    du = record.u - record.u[0]
    moved = np.flatnonzero(np.abs(du) > 1e-12 * max(1.0, np.ptp(record.u)))
    first = int(moved[0]) if moved.size else record.n
    y0 = float(np.mean(record.y[:max(first, 1)]))
    y_model = y0 + simulate_plant(plant, record.t, du, initial="zero")
    err = record.y - y_model
    spread = np.linalg.norm(record.y - record.y.mean())
    if spread == 0:
        raise DataError(f"column '{record.output.name}': the output never changes", where=record.source)
    nrmse = float(np.linalg.norm(err) / spread)
    return StepVerification(100.0 * (1.0 - nrmse), nrmse, float(np.sqrt(np.mean(err ** 2))), record.t, record.u,
                            record.y, y_model, record.source)
