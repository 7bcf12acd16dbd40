"""What is simulated: the sampled closed loop (:class:`NonlinearLoop`), the open-loop chain
(:class:`OpenLoop`) and the operating point their linear plant model is linearized about.

:mod:`synth.sim.simulator` runs them; :mod:`synth.sim.results` holds what a run gives.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.errors import ModelError
from synth.plant import Plant
from synth.sim.blocks import Block, Delay

__all__ = ["NonlinearLoop", "OpenLoop", "OperatingPoint"]


@dataclass(frozen=True)
class OperatingPoint:
    """Trim input and output the linear plant model is linearized about (e.g. 200 PWM, 870 rad/s).

    Examples
    --------
    >>> OperatingPoint(200, 870).to_dict()
    {'input': 200.0, 'output': 870.0}
    """

    input: float = 0.0
    output: float = 0.0

    def __post_init__(self) -> None:
        for name in ("input", "output"):
            v = float(getattr(self, name))
            if not np.isfinite(v):
                raise ModelError(f"operating_point.{name} must be finite, got {v!r}")
            object.__setattr__(self, name, v)

    def to_dict(self) -> dict[str, float]:
        """JSON-ready dict."""
        return {"input": self.input, "output": self.output}


@dataclass(frozen=True, eq=False)
class NonlinearLoop:
    """Everything that defines the sampled closed loop.

    Parameters
    ----------
    plant : Plant
        Linear model about the operating point (deviation input -> deviation output), with its delay.
    controller : Controller
        Acts on ``reference - measured output``; its output is added to the operating-point input.
    actuator, sensor : sequence of Block
        Chains between controller and plant, and between plant and controller.
    dt : float
        Simulation step (s).
    controller_rate : float, optional
        Controller update rate (Hz); ``1/(rate dt)`` must be a whole number. Default ``1/dt``.
    loop_delay : float
        Extra delay inside the loop (s), added to the plant's delay and any delay block.
    operating_point : OperatingPoint
    discretization : str
        Controller discretization: ``tustin``, ``zoh``, ``backward_euler``, ``forward_euler``.
    anti_windup : bool
        Drive the controller's state with the output of the leading rate-limit/saturation/
        quantizer blocks instead of its own output (observer form; needs a biproper controller
        with stable zeros, e.g. PI). Without limits active it changes nothing.
    label : str
        Name in reports.

    Examples
    --------
    >>> from synth.sim.blocks import RateLimit, Saturation
    >>> loop = NonlinearLoop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3}),
    ...                      actuator=[RateLimit(10000), Saturation(0, 255)],
    ...                      operating_point=OperatingPoint(200, 870))
    >>> loop.total_delay, loop.controller_period
    (0.0, 0.001)
    """

    plant: Plant
    controller: Controller
    actuator: tuple[Block, ...] = ()
    sensor: tuple[Block, ...] = ()
    dt: float = 1e-3
    controller_rate: float | None = None
    loop_delay: float = 0.0
    operating_point: OperatingPoint = field(default_factory=OperatingPoint)
    discretization: str = "tustin"
    anti_windup: bool = False
    label: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "actuator", tuple(self.actuator))
        object.__setattr__(self, "sensor", tuple(self.sensor))
        for b in (*self.actuator, *self.sensor):
            if not isinstance(b, Block):
                raise ModelError(f"expected a simulation block, got {b!r}")
        if not (np.isfinite(self.dt) and self.dt > 0):
            raise ModelError(f"dt must be > 0 s, got {self.dt!r}")
        if not (np.isfinite(self.loop_delay) and self.loop_delay >= 0):
            raise ModelError(f"loop_delay must be >= 0 s, got {self.loop_delay!r}")
        if len(self.actuator) > 16 or len(self.sensor) > 15:
            raise ModelError("at most 16 actuator and 15 sensor blocks")
        _ = self.controller_ratio  # validates the rate
        if self.discretization not in ("tustin", "zoh", "backward_euler", "forward_euler"):
            raise ModelError(f"unknown controller discretization {self.discretization!r}; expected tustin, "
                             "zoh, backward_euler or forward_euler")

    # ------------------------------------------------------------------ derived
    @property
    def controller_ratio(self) -> int:
        """Simulation steps per controller update."""
        if self.controller_rate is None:
            return 1
        ratio = 1.0 / (float(self.controller_rate) * self.dt)
        if not (np.isfinite(ratio) and ratio >= 1 - 1e-9 and abs(ratio - round(ratio)) <= 1e-6 * ratio):
            raise ModelError(f"controller_rate {self.controller_rate:g} Hz must be 1/dt divided by a whole "
                             f"number (dt = {self.dt:g} s)")
        return round(ratio)

    @property
    def controller_period(self) -> float:
        """Controller sample period (s)."""
        return self.controller_ratio * self.dt

    @property
    def total_delay(self) -> float:
        """Plant delay + loop delay + delay blocks (s)."""
        blocks = sum(b.delay for b in (*self.actuator, *self.sensor) if isinstance(b, Delay))
        return self.plant.delay + self.loop_delay + blocks

    def replace(self, **changes: Any) -> NonlinearLoop:
        """Copy with fields replaced (e.g. ``controller=...``, ``loop_delay=0.01``).

        Examples
        --------
        >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}))
        >>> loop.replace(loop_delay=0.01).total_delay
        0.01
        """
        return dataclasses.replace(self, **changes)

    def with_gain(self, name: str, value: float) -> NonlinearLoop:
        """Copy with one controller parameter replaced.

        Examples
        --------
        >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}))
        >>> str(loop.with_gain("kp", 4).controller)
        'P(kp=4)'
        """
        return self.replace(controller=self.controller.with_parameters(**{name: value}))

    def without(self, *kinds: str) -> NonlinearLoop:
        """Copy without the blocks of the given types (e.g. ``"rate_limit"``).

        Examples
        --------
        >>> from synth.sim.blocks import RateLimit, Saturation
        >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}),
        ...                      actuator=[RateLimit(1.0), Saturation(-1, 1)])
        >>> [b.kind for b in loop.without("rate_limit").actuator]
        ['saturation']
        """
        return self.replace(actuator=tuple(b for b in self.actuator if b.kind not in kinds),
                            sensor=tuple(b for b in self.sensor if b.kind not in kinds))

    def linear(self) -> NonlinearLoop:
        """Copy with every nonlinear block removed (linear dynamics, delays and sample-holds stay).

        Examples
        --------
        >>> from synth.sim.blocks import Lag, Saturation
        >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}),
        ...                      actuator=[Saturation(-1, 1), Lag(0.01)])
        >>> [b.kind for b in loop.linear().actuator]
        ['lag']
        """
        keep = ("lag", "dynamics", "delay", "sample_hold")
        return self.replace(actuator=tuple(b for b in self.actuator if b.kind in keep),
                            sensor=tuple(b for b in self.sensor if b.kind in keep))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description.

        Examples
        --------
        >>> NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 2})).to_dict()["controller"]
        'P(kp=2)'
        """
        return {
            "plant": self.plant.to_string(6),
            "controller": str(self.controller),
            "dt": self.dt,
            "controller_rate": 1.0 / self.controller_period,
            "controller_discretization": self.discretization,
            "loop_delay": self.loop_delay,
            "total_delay": self.total_delay,
            "operating_point": self.operating_point.to_dict(),
            "actuator": [b.to_dict() for b in self.actuator],
            "sensor": [b.to_dict() for b in self.sensor],
            "anti_windup": self.anti_windup,
            "label": self.label,
        }



@dataclass(frozen=True, eq=False)
class OpenLoop:
    """Open-loop chain ``u -> actuator blocks -> plant (delay) -> sensor blocks -> y``.

    The variant type of :func:`synth.sim.simulator.simulate_open_loop_batch`; fields as in
    :class:`NonlinearLoop` (``loop_delay`` is the extra delay besides the plant's).

    Examples
    --------
    >>> from synth.sim.blocks import Delay
    >>> OpenLoop(Plant.from_string("1/(s+1)"), (Delay(0.002),), loop_delay=0.001).total_delay
    0.003
    """

    plant: Plant
    actuator: tuple[Block, ...] = ()
    sensor: tuple[Block, ...] = ()
    dt: float = 1e-3
    loop_delay: float = 0.0
    operating_point: OperatingPoint = field(default_factory=OperatingPoint)
    label: str = ""

    @property
    def total_delay(self) -> float:
        """Plant delay + extra delay + delay blocks (s)."""
        blocks = sum(b.delay for b in (*self.actuator, *self.sensor) if isinstance(b, Delay))
        return self.plant.delay + self.loop_delay + blocks
