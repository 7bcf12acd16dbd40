"""Nonlinear blocks: rate limit, saturation, dead zone, quantizer, backlash and a static table.

Each is a frozen dataclass (:class:`~synth.sim.blocks.chain.Block`) with one equation per step;
the equations themselves are the compiled functions of ``synth.sim._steps``.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.sim.blocks.chain import Block, checked_positive, padded
from synth.sim.layout import BACKLASH, DEAD_ZONE, MAX_TABLE, P_MAX, QUANTIZER, RATE_LIMIT, S_MAX, SATURATION, STATIC

__all__ = ["Backlash", "DeadZone", "Quantizer", "RateLimit", "Saturation", "Static"]


@dataclass(frozen=True)
class RateLimit(Block):
    """Slew-rate limiter: the output moves at most ``rate`` units/s up and ``falling`` down.

    ``y_k = y_{k-1} + clip(x_k - y_{k-1}, -falling dt, rate dt)``. The seed's B = 10 PWM/ms is
    ``RateLimit(rate=10000)``.

    Parameters
    ----------
    rate : float
        Largest rising rate (units/s, > 0).
    falling : float, optional
        Largest falling rate (default ``rate``).

    Examples
    --------
    >>> RateLimit(rate=2.0).apply([0, 10, 10, 10, -10], dt=1.0).tolist()
    [0.0, 2.0, 4.0, 6.0, 4.0]
    """

    rate: float
    falling: float | None = None
    kind: ClassVar[str] = "rate_limit"
    code: ClassVar[int] = RATE_LIMIT
    command_side: ClassVar[bool] = True
    flag: ClassVar[str | None] = "rate_limited"

    def __post_init__(self) -> None:
        if not (float(self.rate) > 0):
            raise ModelError(f"rate_limit: rate must be > 0 units/s, got {self.rate:g}")
        object.__setattr__(self, "rate", float(self.rate))
        if self.falling is not None:
            object.__setattr__(self, "falling", checked_positive("falling", self.falling, self.kind))

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        fall = self.rate if self.falling is None else self.falling
        return padded([self.rate * dt, fall * dt], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        return padded([x], S_MAX)


@dataclass(frozen=True)
class Saturation(Block):
    """Amplitude limits: ``y = clip(x, min, max)`` (e.g. the 0-255 PWM range).

    Examples
    --------
    >>> Saturation(0, 255).apply([-5, 100, 300], dt=0.001).tolist()
    [0.0, 100.0, 255.0]
    """

    min: float
    max: float
    kind: ClassVar[str] = "saturation"
    code: ClassVar[int] = SATURATION
    command_side: ClassVar[bool] = True
    flag: ClassVar[str | None] = "saturated"

    def __post_init__(self) -> None:
        lo, hi = float(self.min), float(self.max)
        if np.isnan(lo) or np.isnan(hi) or lo >= hi:
            raise ModelError(f"saturation: min ({lo:g}) must be below max ({hi:g})")
        object.__setattr__(self, "min", lo)
        object.__setattr__(self, "max", hi)

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return padded([self.min, self.max], P_MAX)


@dataclass(frozen=True)
class DeadZone(Block):
    """Dead zone of half-width ``width`` around ``center``: no output change inside it.

    ``y = c`` for ``|x - c| <= w``, ``y = x - w`` above, ``y = x + w`` below.

    Examples
    --------
    >>> DeadZone(width=1.0).apply([-3, -0.5, 0.5, 3], dt=1.0).tolist()
    [-2.0, 0.0, 0.0, 2.0]
    """

    width: float
    center: float = 0.0
    kind: ClassVar[str] = "dead_zone"
    code: ClassVar[int] = DEAD_ZONE
    flag: ClassVar[str | None] = "in_dead_zone"

    def __post_init__(self) -> None:
        object.__setattr__(self, "width", checked_positive("width", self.width, self.kind, allow_zero=True))
        object.__setattr__(self, "center", float(self.center))

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return padded([self.center, self.width], P_MAX)


@dataclass(frozen=True)
class Quantizer(Block):
    """Resolution ``step``: ``y = offset + step round((x - offset)/step)`` (``mode: floor`` truncates).

    The 255-step PWM is ``Quantizer(1)``; the seed's speed sensor resolves 1.2 rad/s.

    Examples
    --------
    >>> Quantizer(1.2).apply([0.5, 0.7, 2.0], dt=1.0).round(6).tolist()
    [0.0, 1.2, 2.4]
    """

    step: float
    offset: float = 0.0
    mode: str = "round"
    kind: ClassVar[str] = "quantizer"
    code: ClassVar[int] = QUANTIZER
    command_side: ClassVar[bool] = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "step", checked_positive("step", self.step, self.kind))
        if self.mode not in ("round", "floor"):
            raise ModelError(f"quantizer: mode must be 'round' or 'floor', got {self.mode!r}")

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return padded([self.step, float(self.offset), 0.0 if self.mode == "round" else 1.0], P_MAX)


@dataclass(frozen=True)
class Backlash(Block):
    """Backlash (play) of total width ``width``: the output follows only once the input has
    crossed the gap, ``y_k = clip(y_{k-1}, x_k - width/2, x_k + width/2)``.

    Examples
    --------
    >>> Backlash(width=2.0).apply([0, 0.5, 2, 1.5, 0], dt=1.0).tolist()
    [0.0, 0.0, 1.0, 1.0, 1.0]
    """

    width: float
    kind: ClassVar[str] = "backlash"
    code: ClassVar[int] = BACKLASH
    flag: ClassVar[str | None] = "in_backlash"

    def __post_init__(self) -> None:
        object.__setattr__(self, "width", checked_positive("width", self.width, self.kind, allow_zero=True))

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        return padded([self.width / 2.0], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        return padded([x], S_MAX)


@dataclass(frozen=True)
class Static(Block):
    """Static (memoryless) nonlinearity ``y = f(x)`` given as a table of points, linear in between
    and extrapolated along the end segments (a smooth curve: give enough points).

    Parameters
    ----------
    table : list of (x, y)
        2 to 16 points with strictly increasing ``x``.

    Examples
    --------
    >>> Static([(0, 0), (1, 2), (2, 3)]).apply([-1, 0.5, 1.5, 3], dt=1.0).tolist()
    [-2.0, 1.0, 2.5, 4.0]
    """

    table: tuple[tuple[float, float], ...]
    kind: ClassVar[str] = "static"
    code: ClassVar[int] = STATIC

    def __post_init__(self) -> None:
        pts = tuple((float(a), float(b)) for a, b in self.table)
        if not 2 <= len(pts) <= MAX_TABLE:
            raise ModelError(f"static: table needs 2 to {MAX_TABLE} points, got {len(pts)}")
        xs = [a for a, _ in pts]
        if not all(np.isfinite(v) for p in pts for v in p):
            raise ModelError("static: table values must be finite")
        if any(b <= a for a, b in itertools.pairwise(xs)):
            raise ModelError("static: table x values must be strictly increasing")
        object.__setattr__(self, "table", pts)

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        xs = [a for a, _ in self.table]
        ys = [b for _, b in self.table]
        return padded([len(xs)] + xs + [0.0] * (MAX_TABLE - len(xs)) + ys, P_MAX)

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.kind, "table": [list(p) for p in self.table]}
