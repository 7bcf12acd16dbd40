"""Phase delay at a stated frequency ``w1`` (seed 2, sec. 6.2, eq. 2-3).

The sweep report defines ``tau_p = -(phi_1 + 180 deg) / (57.3 w1)``, ``phi_1`` the phase at ``w1 > w180``
(eq. 2): if the phase rolls off beyond ``w180`` only through a time delay, ``phi_1 = -180 deg - tau w1``
(eq. 3), so ``tau_p`` estimates that delay. The specification evaluates it at ``w1 = 2 w180``
(:mod:`synth.ident.hq_metrics`); the report's own example (eq. 4, ``e^(-0.1 s)/(s^2 + s + 1)``) shows that
near ``w180`` the lower-order dynamics still bend the phase: at ``w1 = 20 rad/s`` ``tau_p`` is close to
the 0.1 s delay, at ``2 w180`` (6.5 rad/s) it is 0.077 s. Values are comparable only at the same ``w1``.

From a model the phase at ``w1`` is exact (:func:`synth.ident.model_phase.continuous_phase`); from a
measured response it is interpolated on a log frequency axis, or read from the least-squares phase line
when the metrics used one (rough phase, seed 2 fig. 15) and ``w1`` lies inside the line's band or beyond
the data.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.errors import DataError
from synth.ident.hq_metrics import DEG, HQMetrics
from synth.ident.model_phase import continuous_phase, low_frequency_form
from synth.plant import Plant

__all__ = ["PhaseDelayAt", "phase_delay_at", "phase_delay_from_phase"]


def phase_delay_from_phase(w1: float, phase_deg: float) -> float:
    """Eq. 2 of the sweep report: ``tau_p = -(phi_1 + 180) / (57.3 w1)`` [s], ``phi_1`` in degrees.

    Examples
    --------
    >>> round(phase_delay_from_phase(20.0, -180.0 - 0.1 * 20.0 * 180 / math.pi), 6)  # a pure 0.1 s roll-off
    0.1
    """
    return -(float(phase_deg) + 180.0) / (DEG * float(w1))


@dataclass(frozen=True)
class PhaseDelayAt:
    """The phase delay at a stated ``w1`` and how it was read.

    Attributes
    ----------
    w1 : float
        Evaluation frequency [rad/s].
    phase_deg : float
        Phase at ``w1`` [deg].
    phase_delay : float
        ``tau_p`` at ``w1`` [s].
    w180 : float or None
        Neutral-stability frequency of the same response [rad/s].
    phase_delay_2w180 : float or None
        The specification's ``tau_p`` at ``2 w180``, for comparison [s].
    method : str
        ``"exact"`` (model), ``"raw"`` (measured phase interpolated) or ``"line"`` (least-squares phase line).
    notes : tuple of str
    """

    w1: float
    phase_deg: float
    phase_delay: float
    w180: float | None
    phase_delay_2w180: float | None
    method: str
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form with units.

        Examples
        --------
        >>> PhaseDelayAt(20.0, -291.7, 0.0975, 3.26, 0.0761, "exact").to_dict()["units"]["phase_delay"]
        's'
        """
        return {"w1": self.w1, "phase_deg": self.phase_deg, "phase_delay": self.phase_delay, "w180": self.w180,
                "w1_over_w180": self.w1 / self.w180 if self.w180 else None,
                "phase_delay_2w180": self.phase_delay_2w180, "method": self.method, "notes": list(self.notes),
                "units": {"w1": "rad/s", "phase_deg": "deg", "phase_delay": "s", "w180": "rad/s",
                          "phase_delay_2w180": "s"}}


def _measured_phase(metrics: HQMetrics, w1: float, notes: list[str]) -> tuple[float, str]:
    w, phase = metrics.w, metrics.phase_deg
    if w is None or phase is None or w.size < 2:
        raise DataError("the metrics carry no phase curve", where="--w1")
    line = metrics.phase_line
    if line is not None and (line.band[0] <= w1 <= line.band[1] or w1 > w[-1]):
        if w1 > line.band[1]:
            notes.append(f"w1 = {w1:.4g} rad/s lies beyond the data (up to {w[-1]:.4g} rad/s): phase from the "
                         f"least-squares line on {line.band[0]:.4g}-{line.band[1]:.4g} rad/s, extrapolated")
        return float(line.value(w1)), "line"
    if not w[0] <= w1 <= w[-1]:
        raise DataError(f"w1 = {w1:.4g} rad/s lies outside the measured response ({w[0]:.4g}-{w[-1]:.4g} rad/s)",
                        where="--w1")
    return float(np.interp(np.log(w1), np.log(w), phase)), "raw"


def phase_delay_at(metrics: HQMetrics, w1: float, plant: Plant | None = None) -> PhaseDelayAt:
    """Phase delay ``tau_p`` at a stated ``w1`` (eq. 2), beside the specification's value at ``2 w180``.

    Parameters
    ----------
    metrics : HQMetrics
        From :func:`synth.ident.hq.hq_from_plant` or :func:`synth.ident.hq.hq_from_frd`.
    w1 : float
        Evaluation frequency [rad/s], > 0; eq. 3 assumes ``w1 > w180``.
    plant : Plant, optional
        The model behind ``metrics`` (``source == "model"``): the phase at ``w1`` is then exact.

    Returns
    -------
    PhaseDelayAt

    Raises
    ------
    DataError
        ``w1`` not a positive number, or outside a measured response without a phase line.

    Examples
    --------
    The sweep report's example, eq. 4 (``w180`` = 3.26 rad/s):

    >>> from synth.ident.hq import hq_from_plant
    >>> G = Plant.from_string("1/(s^2+s+1)", delay=0.1)
    >>> m = hq_from_plant(G)
    >>> round(phase_delay_at(m, 20.0, G).phase_delay, 4), round(phase_delay_at(m, 6.6, G).phase_delay, 4)
    (0.0975, 0.0768)
    """
    if not (isinstance(w1, (int, float)) and math.isfinite(w1) and w1 > 0):
        raise DataError(f"w1 must be a positive frequency in rad/s, got {w1!r}", where="--w1")
    w1 = float(w1)
    notes: list[str] = []
    if metrics.source == "model":
        if plant is None:
            raise DataError("a model's phase delay at w1 needs the model (plant=)", where="--w1")
        if low_frequency_form(plant)[1] < 0:
            plant = plant.scaled(-1.0)  # as hq_from_plant: the metrics are those of -G
        phase, method = float(continuous_phase(plant, [w1])[0]), "exact"
    else:
        phase, method = _measured_phase(metrics, w1, notes)
    w180 = metrics.w180
    if w180 is None:
        notes.append("no w180: eq. 2 assumes w1 beyond the -180 deg frequency, which this response never reaches")
    elif w1 <= w180:
        notes.append(f"w1 = {w1:.4g} rad/s is not above w180 = {w180:.4g} rad/s: eq. 3 (phase roll-off by a "
                     "delay alone) does not hold there")
    elif w180 and metrics.phase_delay is not None and not math.isclose(w1, 2 * w180, rel_tol=1e-3):
        notes.append(f"the specification evaluates tau_p at 2 w180 = {2 * w180:.4g} rad/s "
                     f"({metrics.phase_delay:.4g} s); compare values only at the same w1")
    return PhaseDelayAt(w1, phase, phase_delay_from_phase(w1, phase), w180, metrics.phase_delay, method,
                        tuple(notes))
