"""The spec file's ``simulation:`` block (pydantic models) and how it builds a :class:`NonlinearLoop`.

Example (the X-4 rotor loop of seed 1)::

    simulation:
      dt: 0.001
      operating_point: {input: 200, output: 870}
      actuator: [{type: rate_limit, rate: 10000}, {type: saturation, min: 0, max: 255}]
      loop_delay: 0.0
      sensor: [{type: sample_hold, rate: 400}, {type: quantizer, step: 1.2}]
      step: [820, 920]

Every block has a ``type`` and the parameters of its class in
:mod:`synth.sim.blocks`; see ``docs/simulation.md``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, NonNegativeFloat, PositiveFloat, model_validator

from synth.errors import ModelError, SynthError
from synth.sim.signals import PsdDisturbance, RecordDisturbance, StepDisturbance

if TYPE_CHECKING:
    from synth.sim.blocks import Block

__all__ = [
    "BLOCK_SPECS", "BLOCK_TAGS", "DISTURBANCE_TAGS", "MAX_DELAY_SAMPLES", "MAX_RUN_SAMPLES", "SIMULATION_TAGS",
    "BacklashSpec", "BlockEntry", "DeadZoneSpec",
    "DelaySpec", "DisturbanceEntry", "DynamicsSpec", "LagSpec", "LimitCycleSpec", "NoiseSpec", "OnsetSpec",
    "OperatingPointSpec", "PsdDisturbanceSpec", "PublishedSimSpec", "QuantizerSpec", "RateLimitSpec",
    "RecordDisturbanceSpec", "SampleHoldSpec", "SaturationSpec", "SimulationSpec", "StaticSpec", "StepDisturbanceSpec",
    "SupplySagSpec",
]


def _blocks() -> Any:
    """The blocks module, imported on first use (it loads numba; ``import synth`` stays fast)."""
    from synth.sim import blocks

    return blocks


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class _BlockSpec(_Model):
    """A block entry; ``build()`` gives the :class:`~synth.sim.blocks.Block`."""

    type: str

    def build(self) -> Block:  # pragma: no cover - overridden
        raise NotImplementedError

    @model_validator(mode="after")
    def _builds(self) -> _BlockSpec:
        try:
            self.build()
        except ModelError as exc:
            raise ValueError(exc.message.removeprefix(f"{self.type}: ")) from None  # type: ignore[attr-defined]
        return self


class RateLimitSpec(_BlockSpec):
    """``{type: rate_limit, rate: R, falling: F}`` (units/s)."""

    type: Literal["rate_limit"]
    rate: PositiveFloat
    falling: PositiveFloat | None = None

    def build(self) -> Block:
        return _blocks().RateLimit(self.rate, self.falling)


class SaturationSpec(_BlockSpec):
    """``{type: saturation, min: lo, max: hi}``."""

    type: Literal["saturation"]
    min: float
    max: float

    def build(self) -> Block:
        return _blocks().Saturation(self.min, self.max)


class DeadZoneSpec(_BlockSpec):
    """``{type: dead_zone, width: w, center: c}`` (half-width)."""

    type: Literal["dead_zone"]
    width: NonNegativeFloat
    center: float = 0.0

    def build(self) -> Block:
        return _blocks().DeadZone(self.width, self.center)


class QuantizerSpec(_BlockSpec):
    """``{type: quantizer, step: q, offset: o, mode: round|floor}``."""

    type: Literal["quantizer"]
    step: PositiveFloat
    offset: float = 0.0
    mode: Literal["round", "floor"] = "round"

    def build(self) -> Block:
        return _blocks().Quantizer(self.step, self.offset, self.mode)


class BacklashSpec(_BlockSpec):
    """``{type: backlash, width: total play}``."""

    type: Literal["backlash"]
    width: NonNegativeFloat

    def build(self) -> Block:
        return _blocks().Backlash(self.width)


class StaticSpec(_BlockSpec):
    """``{type: static, table: [[x, y], ...]}`` (piecewise linear)."""

    type: Literal["static"]
    table: list[tuple[float, float]]

    def build(self) -> Block:
        return _blocks().Static(tuple(self.table))


class LagSpec(_BlockSpec):
    """``{type: lag, tau: s, gain: k}``."""

    type: Literal["lag"]
    tau: PositiveFloat
    gain: float = 1.0

    def build(self) -> Block:
        return _blocks().Lag(self.tau, self.gain)


class DynamicsSpec(_BlockSpec):
    """``{type: dynamics, tf: "442/((s+45)*(s+9.7))"}``."""

    type: Literal["dynamics"]
    tf: str

    def build(self) -> Block:
        return _blocks().Dynamics.from_string(self.tf)


class SupplySagSpec(_BlockSpec):
    """``{type: supply_sag, v_open, r_internal, i_static, i_dynamic, tau, v_reset, reset_time, ...}``."""

    type: Literal["supply_sag"]
    v_open: PositiveFloat
    r_internal: NonNegativeFloat
    i_static: NonNegativeFloat = 0.0
    i_dynamic: NonNegativeFloat = 0.0
    tau: PositiveFloat = 0.1
    v_reset: NonNegativeFloat = 5.0
    reset_time: NonNegativeFloat = 0.05
    v_nominal: PositiveFloat | None = None
    output_in_reset: float = 0.0

    def build(self) -> Block:
        return _blocks().SupplySag(self.v_open, self.r_internal, self.i_static, self.i_dynamic, self.tau,
                                   self.v_reset, self.reset_time, self.v_nominal, self.output_in_reset)


class SampleHoldSpec(_BlockSpec):
    """``{type: sample_hold, rate: Hz, phase: s}``."""

    type: Literal["sample_hold"]
    rate: PositiveFloat
    phase: NonNegativeFloat = 0.0

    def build(self) -> Block:
        return _blocks().SampleHold(self.rate, self.phase)


class NoiseSpec(_BlockSpec):
    """``{type: noise, std: sigma}`` or ``{type: noise, psd: [[w, S], ...]}``."""

    type: Literal["noise"]
    std: NonNegativeFloat = 0.0
    psd: list[tuple[float, float]] | None = None

    def build(self) -> Block:
        return _blocks().Noise(self.std, tuple(self.psd) if self.psd is not None else None)


class DelaySpec(_BlockSpec):
    """``{type: delay, delay: s}``."""

    type: Literal["delay"]
    delay: NonNegativeFloat

    def build(self) -> Block:
        return _blocks().Delay(self.delay)


MAX_RUN_SAMPLES = 10_000_000
"""Most samples of one simulated run a spec may ask for (``horizon / dt``)."""
MAX_DELAY_SAMPLES = 1_000_000
"""Most samples of in-loop delay (``loop_delay`` and delay blocks over ``dt``)."""

BLOCK_SPECS = (RateLimitSpec, SaturationSpec, DeadZoneSpec, QuantizerSpec, BacklashSpec, StaticSpec, LagSpec,
               DynamicsSpec, SupplySagSpec, SampleHoldSpec, NoiseSpec, DelaySpec)
BlockEntry = Annotated[Union[BLOCK_SPECS], Field(discriminator="type")]  # type: ignore[valid-type]


class PsdDisturbanceSpec(_Model):
    """``{type: psd, at: input|output, psd: [[w, S], ...]}`` (S in unit^2/(rad/s), one-sided)."""

    type: Literal["psd"]
    at: Literal["input", "output"] = "output"
    psd: list[tuple[float, float]]

    @model_validator(mode="after")
    def _valid(self) -> PsdDisturbanceSpec:
        try:
            self.build()
        except ModelError as exc:
            raise ValueError(exc.message.removeprefix("psd: ")) from None
        return self

    def build(self) -> PsdDisturbance:
        return PsdDisturbance(tuple(self.psd), self.at)


class RecordDisturbanceSpec(_Model):
    """``{type: record, at, file, time, value, scale, start}``: columns of a CSV file (path
    relative to the working directory), interpolated onto the simulation grid."""

    type: Literal["record"]
    at: Literal["input", "output"] = "output"
    file: str
    time: str = "time"
    value: str
    scale: float = 1.0
    start: float | None = None

    def build(self) -> RecordDisturbance:
        return RecordDisturbance.from_csv(Path(self.file), self.time, self.value, self.at, self.scale, self.start)


class StepDisturbanceSpec(_Model):
    """``{type: step, at, size, time}``: a load step."""

    type: Literal["step"]
    at: Literal["input", "output"] = "output"
    size: float
    time: NonNegativeFloat = 0.0

    def build(self) -> StepDisturbance:
        return StepDisturbance(self.size, self.time, self.at)


DisturbanceEntry = Annotated[Union[PsdDisturbanceSpec, RecordDisturbanceSpec, StepDisturbanceSpec],
                             Field(discriminator="type")]

BLOCK_TAGS = tuple(m.model_fields["type"].annotation.__args__[0] for m in BLOCK_SPECS)
"""The ``type`` names of blocks."""
DISTURBANCE_TAGS = ("psd", "record", "step")
"""The ``type`` names of disturbances."""
SIMULATION_TAGS = (*BLOCK_TAGS, *DISTURBANCE_TAGS)
"""Every tag of the ``simulation:`` block's tagged lists."""


class OperatingPointSpec(_Model):
    """Trim ``{input, output}`` in absolute units."""

    input: float = 0.0
    output: float = 0.0


class LimitCycleSpec(_Model):
    """How a sustained oscillation is recognised: smallest half peak-to-peak amplitude (output
    units) and the seconds at the end of a run examined (default: the last half)."""

    min_amplitude: NonNegativeFloat = 0.0
    window: PositiveFloat | None = None


class OnsetSpec(_Model):
    """Gain at which oscillation starts, against the in-loop delay and the rate limit (P control)."""

    delays: list[NonNegativeFloat] = Field(default_factory=lambda: [0.0, 0.005, 0.01, 0.015, 0.02])
    rate_limits: list[PositiveFloat] = Field(default_factory=list)
    gains: tuple[PositiveFloat, PositiveFloat] = (0.5, 20.0)
    horizon: PositiveFloat = 3.0

    @model_validator(mode="after")
    def _ordered(self) -> OnsetSpec:
        if self.gains[0] >= self.gains[1]:
            raise ValueError(f"gains: lower end {self.gains[0]:g} must be below the upper end {self.gains[1]:g}")
        return self


class PublishedSimSpec(_Model):
    """Published nonlinear observations to place on the simulation's results."""

    oscillation_onset_gain: PositiveFloat | None = None
    open_loop_rise_time: PositiveFloat | None = None
    closed_loop_rise_time: PositiveFloat | None = None
    gain: PositiveFloat | None = None
    notes: list[str] = Field(default_factory=list)


class SimulationSpec(_Model):
    """The ``simulation:`` block: the sampled nonlinear loop used by ``synth simulate`` and by the
    nonlinear step check of ``synth design``.

    Examples
    --------
    >>> sim = SimulationSpec.model_validate({"operating_point": {"input": 200, "output": 870},
    ...     "actuator": [{"type": "rate_limit", "rate": 10000}, {"type": "saturation", "min": 0, "max": 255}]})
    >>> [b.kind for b in sim.actuator_blocks()]
    ['rate_limit', 'saturation']
    """

    dt: PositiveFloat = 0.001
    controller_rate: PositiveFloat | None = None
    controller_discretization: Literal["tustin", "zoh", "backward_euler", "forward_euler"] = "tustin"
    operating_point: OperatingPointSpec = OperatingPointSpec()
    actuator: list[BlockEntry] = Field(default_factory=list)  # type: ignore[valid-type]
    loop_delay: NonNegativeFloat = 0.0
    sensor: list[BlockEntry] = Field(default_factory=list)  # type: ignore[valid-type]
    anti_windup: bool = False
    disturbances: list[DisturbanceEntry] = Field(default_factory=list)  # type: ignore[valid-type]
    step: tuple[float, float] | None = None
    step_time: NonNegativeFloat = 0.0
    horizon: PositiveFloat = 1.0
    seed: int = 0
    limit_cycle: LimitCycleSpec = LimitCycleSpec()
    onset: OnsetSpec | None = None
    published: PublishedSimSpec | None = None

    @model_validator(mode="after")
    def _consistent(self) -> SimulationSpec:
        if self.controller_rate is not None:
            ratio = 1.0 / (self.controller_rate * self.dt)
            if ratio < 1 - 1e-9 or abs(ratio - round(ratio)) > 1e-6 * ratio:
                raise ValueError(f"controller_rate {self.controller_rate:g} Hz must be 1/dt "
                                 f"({1 / self.dt:g} Hz) divided by a whole number")
        fixed = "horizon" in self.model_fields_set  # else the horizon follows the loop's dynamics
        if fixed and self.step_time >= self.horizon:
            raise ValueError(f"step_time {self.step_time:g} s must be inside the horizon ({self.horizon:g} s)")
        if self.horizon / self.dt > MAX_RUN_SAMPLES:
            raise ValueError(f"horizon {self.horizon:g} s at dt {self.dt:g} s is {self.horizon / self.dt:.3g} samples; "
                             f"at most {MAX_RUN_SAMPLES:.3g}")
        if fixed and self.dt > self.horizon / 20:
            raise ValueError(f"dt {self.dt:g} s must be at most 1/20 of the horizon ({self.horizon:g} s)")
        delays = self.loop_delay + sum(b.delay for b in (*self.actuator, *self.sensor) if isinstance(b, DelaySpec))
        if delays / self.dt > MAX_DELAY_SAMPLES:
            raise ValueError(f"the in-loop delays ({delays:g} s) are {delays / self.dt:.3g} samples of {self.dt:g} s; "
                             f"at most {MAX_DELAY_SAMPLES:.3g}")
        if len(self.actuator) > 16 or len(self.sensor) > 15:
            raise ValueError("at most 16 actuator and 15 sensor blocks")
        return self

    def actuator_blocks(self) -> list[Block]:
        """The actuator chain as blocks."""
        return [b.build() for b in self.actuator]

    def sensor_blocks(self) -> list[Block]:
        """The sensor chain as blocks."""
        return [b.build() for b in self.sensor]

    def build_loop(self, plant: Any, controller: Any, label: str = "") -> Any:
        """The :class:`~synth.sim.loops.NonlinearLoop` of ``plant`` and ``controller``.

        Examples
        --------
        >>> from synth.plant import Plant; from synth.controllers import Controller
        >>> sim = SimulationSpec.model_validate({"loop_delay": 0.01})
        >>> sim.build_loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1})).total_delay
        0.01
        """
        from synth.sim.loops import NonlinearLoop, OperatingPoint

        return NonlinearLoop(plant, controller, tuple(self.actuator_blocks()), tuple(self.sensor_blocks()),
                             self.dt, self.controller_rate, self.loop_delay,
                             OperatingPoint(self.operating_point.input, self.operating_point.output),
                             self.controller_discretization, self.anti_windup, label)

    def build_disturbances(self) -> list[Any]:
        """Disturbance objects (record files are read here; errors name the file and column).

        Examples
        --------
        >>> SimulationSpec.model_validate({"disturbances": [{"type": "step", "size": 2}]}).build_disturbances()
        [StepDisturbance(size=2.0, at_time=0.0, at='output')]
        """
        out = []
        for i, d in enumerate(self.disturbances):
            try:
                out.append(d.build())
            except SynthError as exc:
                raise exc.located(f"simulation.disturbances[{i}]") from None
        return out

    def default_step(self) -> tuple[float, float]:
        """The spec's step, or one from the operating-point output to 10 % above it (1 if it is 0).

        Examples
        --------
        >>> SimulationSpec.model_validate({"operating_point": {"output": 870}}).default_step()
        (870.0, 957.0)
        """
        if self.step is not None:
            return self.step
        y0 = self.operating_point.output
        return (y0, y0 + (0.1 * abs(y0) if y0 else 1.0))
