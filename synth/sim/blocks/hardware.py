"""Blocks of the electronics around the loop: a battery that sags (:class:`SupplySag`) and a
sensor that samples (:class:`SampleHold`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from synth.errors import ModelError
from synth.sim.blocks.chain import Block, checked_positive, padded
from synth.sim.layout import P_MAX, S_MAX, SAMPLE_HOLD, SUPPLY_SAG

__all__ = ["SampleHold", "SupplySag"]


@dataclass(frozen=True)
class SupplySag(Block):
    """Battery voltage sag and brown-out reset (seed 1, section 4B).

    The drive's gain is proportional to the battery's terminal voltage, which falls with the
    current drawn through the internal resistance; below ``v_reset`` (the 5 V regulator of the
    seed) the microprocessor resets and the drive output is ``output_in_reset`` for
    ``reset_time`` seconds:

    ``I = max(0, i_static x + i_dynamic (x - x_f))`` with ``tau x_f' + x_f = x`` (the back-EMF
    catches up with the command at the mechanical time constant ``tau``),
    ``V = v_open - r_internal I``, ``y = x V / v_nominal``.

    The current is computed from the block's input (the commanded throttle), which avoids an
    algebraic loop. ``v_nominal`` defaults to the steady voltage at the operating-point input,
    so the block's gain is 1 there (the plant model was identified at that voltage).

    Parameters
    ----------
    v_open : float
        Open-circuit battery voltage (V).
    r_internal : float
        Internal resistance (ohm).
    i_static : float
        Steady current per input unit (A/unit).
    i_dynamic : float
        Extra current per unit of ``x - x_f`` (A/unit): the inrush of a step command.
    tau : float
        Time constant of ``x_f`` (s).
    v_reset : float
        Brown-out voltage (V); the seed's 5 V.
    reset_time : float
        Time the drive stays off after a brown-out (s).
    v_nominal : float, optional
        Voltage at which the block's gain is 1.
    output_in_reset : float
        Drive output while in reset (input units; 0 = motor off).

    Examples
    --------
    >>> sag = SupplySag(v_open=16.8, r_internal=0.1, i_static=0.0, i_dynamic=2.0, tau=0.1)
    >>> y = sag.apply([100.0, 100.0, 160.0, 160.0], dt=0.001)
    >>> y.round(2).tolist()  # a 60-unit step draws 120 A: 12 V drop, brown-out (output 0)
    [100.0, 100.0, 0.0, 0.0]
    """

    v_open: float
    r_internal: float
    i_static: float = 0.0
    i_dynamic: float = 0.0
    tau: float = 0.1
    v_reset: float = 5.0
    reset_time: float = 0.05
    v_nominal: float | None = None
    output_in_reset: float = 0.0
    kind: ClassVar[str] = "supply_sag"
    code: ClassVar[int] = SUPPLY_SAG
    flag: ClassVar[str | None] = "brown_out"

    def __post_init__(self) -> None:
        for name in ("v_open", "tau"):
            object.__setattr__(self, name, checked_positive(name, getattr(self, name), self.kind))
        for name in ("r_internal", "i_static", "i_dynamic", "v_reset", "reset_time"):
            object.__setattr__(self, name, checked_positive(name, getattr(self, name), self.kind, allow_zero=True))
        if self.v_nominal is not None:
            object.__setattr__(self, "v_nominal", checked_positive("v_nominal", self.v_nominal, self.kind))

    def nominal_voltage(self, operating_input: float) -> float:
        """``v_nominal``, or the steady terminal voltage at ``operating_input``.

        Examples
        --------
        >>> round(SupplySag(v_open=16.8, r_internal=0.1, i_static=0.04).nominal_voltage(200), 6)
        16.0
        """
        if self.v_nominal is not None:
            return self.v_nominal
        v = self.v_open - self.r_internal * max(0.0, self.i_static * operating_input)
        if v <= 0:
            raise ModelError(f"supply_sag: the battery voltage at the operating point is {v:g} V (<= 0)")
        return v

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        a = float(np.exp(-dt / self.tau))
        reset_steps = max(1.0, float(np.round(self.reset_time / dt)))
        return padded([self.v_open, self.nominal_voltage(operating_input), self.r_internal, self.i_static,
                     self.i_dynamic, a, self.v_reset, reset_steps, self.output_in_reset], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        return padded([x, 0.0], S_MAX)


@dataclass(frozen=True)
class SampleHold(Block):
    """Sample-and-hold at ``rate`` Hz (e.g. the 400 Hz speed-sensor refresh of seed 1).

    Samples are taken at ``phase + j/rate`` seconds; each is read at the first simulation
    step at or after its instant (exact when ``1/rate`` is a multiple of ``dt``; otherwise the
    sampling instants are late by less than ``dt``) and held until the next.

    Examples
    --------
    >>> SampleHold(rate=0.5).apply([0, 1, 2, 3, 4], dt=1.0).tolist()
    [0.0, 0.0, 2.0, 2.0, 4.0]
    """

    rate: float
    phase: float = 0.0
    kind: ClassVar[str] = "sample_hold"
    code: ClassVar[int] = SAMPLE_HOLD

    def __post_init__(self) -> None:
        object.__setattr__(self, "rate", checked_positive("rate", self.rate, self.kind))
        object.__setattr__(self, "phase", checked_positive("phase", self.phase, self.kind, allow_zero=True))

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return padded([1.0 / (self.rate * dt), self.phase / dt], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        return padded([x, self.phase / dt], S_MAX)
