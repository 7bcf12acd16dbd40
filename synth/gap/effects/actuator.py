"""Actuator effects on the command before the plant: rate limit, saturation (or output clipping), dead zone, backlash.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``rate_limit``         input     :class:`synth.sim.blocks.RateLimit` before ``G``             ``rate``
``saturation``         input     :class:`synth.sim.blocks.Saturation` before ``G``            ``lower, upper``
``saturation(output)`` output    ``min(upper, max(lower, y))`` after ``G`` (clipping, overflow) ``lower, upper``
``deadzone``           input     :class:`synth.sim.blocks.DeadZone` before ``G``              ``width``
``backlash``           input     :class:`synth.sim.blocks.Backlash` before ``G``              ``width``
=====================  ========  ===========================================================  ==============

The blocks run on the measured command with the block equations of :mod:`synth.sim.blocks`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import Effect, Params, command_span, log_grid, slowest_pole
from synth.gap.effects.block_memo import run_block
from synth.plant import Plant
from synth.sim.blocks import Backlash, DeadZone, RateLimit, Saturation

__all__ = ["BacklashEffect", "DeadzoneEffect", "RateLimitEffect", "SaturationEffect"]


@dataclass(frozen=True)
class RateLimitEffect(Effect):
    """Slew-rate limit ``rate`` [input units/s] on the command (:class:`synth.sim.blocks.RateLimit`).

    The grid runs from a ramp lasting twenty slowest plant time constants over the
    input's span up to the fastest rate in the command (inactive).

    Examples
    --------
    >>> import numpy as np
    >>> RateLimitEffect().input_map(np.array([0.0, 0, 5, 5, 5]), 1.0, {"rate": 2.0}).tolist()
    [0.0, 0.0, 2.0, 4.0, 5.0]
    """

    name: ClassVar[str] = "rate_limit"
    parameter_names: ClassVar[tuple[str, ...]] = ("rate",)
    grid_names: ClassVar[tuple[str, ...]] = ("rate",)
    default_candidates: ClassVar[tuple[str, ...]] = ("rate_limit",)

    def off(self) -> Params:
        return {"rate": np.inf}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        dt = float(t[1] - t[0])
        top = float(np.max(np.abs(np.diff(u)))) / dt
        return {"rate": (0.05 * command_span(u) * slowest_pole(plant), top)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        lo, hi = self.bounds(t, u, plant)["rate"]
        return log_grid(lo, hi, 12, "rate")

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        rate = params.get("rate", np.inf)
        return u if not np.isfinite(rate) else run_block(RateLimit(rate), u, dt)


@dataclass(frozen=True)
class SaturationEffect(Effect):
    """Amplitude limits ``lower <= . <= upper`` on the command or on the output.

    ``placement="input"`` (default): the command is limited before ``G``
    (:class:`synth.sim.blocks.Saturation`; an actuator's range). Grid: the upper
    limit alone, then the lower limit alone, at fractions of the input's span.

    ``placement="output"``: the model's output (offset included) is clipped
    after ``G`` (a sensor's range, a tank that overflows). Grid: the upper limit
    at the measured maximum and a little below it, then the lower limit likewise
    (a clipped record rests on its limit). The linear part is fitted with the
    clipped samples censored (:meth:`Effect.censor`).

    Examples
    --------
    >>> import numpy as np
    >>> SaturationEffect().input_map(np.array([0.0, 5, 10]), 1.0, {"upper": 8.0}).tolist()
    [0.0, 5.0, 8.0]
    >>> t = np.arange(4.0); u = np.array([0.0, 1, 2, 3])
    >>> SaturationEffect("output").apply(Plant.from_string("2"), t, u, {"upper": 3.0}).tolist()
    [0.0, 2.0, 3.0, 3.0]
    """

    placement: str = "input"
    name: ClassVar[str] = "saturation"
    joint_search: ClassVar[bool] = True
    parameter_names: ClassVar[tuple[str, ...]] = ("lower", "upper")
    grid_names: ClassVar[tuple[str, ...]] = ("lower", "upper")
    spellings: ClassVar[dict[str, dict[str, str]]] = {
        "saturation(output)": {"placement": "output"}, "clipping": {"placement": "output"},
        "saturation(input)": {"placement": "input"}}
    #: the actuator's limit only: output clipping is seen directly in a record (:mod:`synth.gap.where.clipping`)
    #: and is named with ``candidates`` when it is
    default_candidates: ClassVar[tuple[str, ...]] = ("saturation",)

    def __post_init__(self) -> None:
        if self.placement not in ("input", "output"):
            raise ModelError(f"must be 'input' or 'output', got {self.placement!r}", where="saturation.placement")

    @property
    def label(self) -> str:
        return "saturation" if self.placement == "input" else "saturation(output)"

    def to_dict(self) -> dict[str, Any]:
        return {"effect": self.label, "side": self.placement, "parameters": list(self.parameter_names)}

    def off(self) -> Params:
        return {"lower": -np.inf, "upper": np.inf}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"lower": (float(np.min(u)), float(np.max(u))), "upper": (float(np.min(u)), float(np.max(u)))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        span, lo, hi = command_span(u), float(np.min(u)), float(np.max(u))
        fractions = (0.03, 0.1, 0.2, 0.35, 0.5, 0.7)
        uppers = [hi - f * span for f in fractions]
        lowers = [lo + f * span for f in fractions]
        # limits that clip a few samples of a command with outliers (a derivative kick) lie far inside the
        # span: add the levels above which 0.5 ... 20 % of the samples lie (and below, for the lower limit)
        for share in (0.005, 0.02, 0.05, 0.2):
            up, down = float(np.quantile(u, 1.0 - share)), float(np.quantile(u, share))
            if all(abs(up - x) > 0.01 * span for x in uppers) and lo < up < hi:
                uppers.append(up)
            if all(abs(down - x) > 0.01 * span for x in lowers) and lo < down < hi:
                lowers.append(down)
        # and both limits at once, each at the same fraction of the span from its end: an actuator's range clips
        # both ways, which one limit at a time fits only as a one-sided clip plus a bias
        both = [{"upper": hi - f * span, "lower": lo + f * span} for f in fractions if f < 0.5]
        # ... and around the command's median: a wound-up integrator drives the command past each limit unevenly
        mid = float(np.median(u))
        both += [{"upper": mid + h, "lower": mid - h} for h in np.quantile(np.abs(u - mid), (0.65, 0.8, 0.9, 0.95))
                 if lo < mid - h and mid + h < hi]
        return ([{"upper": x} for x in sorted(uppers, reverse=True)] + [{"lower": x} for x in sorted(lowers)]
                + both)

    def data_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant) -> list[Params]:
        if self.placement == "input" or type(self).grid is not SaturationEffect.grid:  # a subclass's own grid wins
            return self.grid(t, u, plant)
        y = np.asarray(y, float)
        span, lo, hi = command_span(y), float(np.min(y)), float(np.max(y))
        fractions = (0.0, 0.01, 0.03, 0.1, 0.2)
        return [{"upper": hi - f * span} for f in fractions] + [{"lower": lo + f * span} for f in fractions]

    def seed_grid(self, point: Params, u_train: np.ndarray | None = None) -> list[Params]:
        """One limit at a time, as the effect's own grid, bracketed by +-5 % of the command's span, and with the
        other limit added beyond 5, 10 and 20 % of the training command's samples.

        The screen held the denominator fixed, which biases the limit.

        Examples
        --------
        >>> [g["upper"] for g in SaturationEffect().seed_grid({"upper": 5.0, "lower": -np.inf}, np.array([0.0, 10.0]))]
        [4.5, 4.8, 5.0, 5.2, 5.5, 5.0, 5.0, 5.0]
        >>> SaturationEffect().seed_grid({"upper": 5.0}, np.linspace(0.0, 10.0, 101))[5:]
        [{'upper': 5.0, 'lower': 0.5}, {'upper': 5.0, 'lower': 1.0}, {'upper': 5.0, 'lower': 2.0}]
        """
        side = "upper" if np.isfinite(point.get("upper", np.inf)) else "lower"
        other = "lower" if side == "upper" else "upper"
        span = float(np.ptp(u_train)) if u_train is not None and np.ptp(u_train) > 0 else abs(point[side]) or 1.0
        if np.isfinite(point.get("upper", np.inf)) and np.isfinite(point.get("lower", -np.inf)):  # both limits
            return [{"upper": point["upper"] + a * span, "lower": point["lower"] + b * span}
                    for a in (-0.03, 0.0, 0.03) for b in (-0.03, 0.0, 0.03)]
        grid = [{side: point[side] + f * span} for f in (-0.05, -0.02, 0.0, 0.02, 0.05)]
        one_sided = [{k: v for k, v in g.items() if k != other} for g in grid]
        if u_train is None:
            return one_sided
        # the other limit too, beyond 5-20 % of the samples: a one-sided screen may hide a two-sided range, and
        # the joint fit searches both limits together from the best two-sided point
        levels = np.quantile(u_train, (0.05, 0.1, 0.2) if other == "lower" else (0.95, 0.9, 0.8))
        return one_sided + [{side: point[side], other: float(x)} for x in levels
                            if (x < point[side]) == (other == "lower")]

    def clip(self, x: np.ndarray, params: Params) -> np.ndarray:
        """``x`` limited to ``[lower, upper]`` (unchanged when neither limit is finite).

        Examples
        --------
        >>> SaturationEffect("output").clip(np.array([-2.0, 0.5, 3.0]), {"lower": -1.0, "upper": 1.0}).tolist()
        [-1.0, 0.5, 1.0]
        """
        lo, hi = params.get("lower", -np.inf), params.get("upper", np.inf)
        if not (np.isfinite(lo) or np.isfinite(hi)):
            return x
        big = 1e30
        return Saturation(max(lo, -big), min(hi, big)).apply(x, 1.0)

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        return self.clip(u, params) if self.placement == "input" else u

    def output_map(self, y: np.ndarray, params: Params) -> np.ndarray:
        return self.clip(y, params) if self.placement == "output" else y

    @property
    def screenable(self) -> bool:
        return self.placement == "input"

    @property
    def has_output_map(self) -> bool:
        return self.placement == "output"

    @property
    def has_input_side(self) -> bool:
        return self.placement == "input"


@dataclass(frozen=True)
class DeadzoneEffect(Effect):
    """Dead zone of half-width ``width`` around ``center`` (:class:`synth.sim.blocks.DeadZone`).

    The center is the command at rest (the first sample) unless given: the
    drive does not move until the command leaves the band around where it rests.

    Examples
    --------
    >>> import numpy as np
    >>> DeadzoneEffect().input_map(np.array([0.0, 0.5, 3.0]), 1.0, {"width": 1.0, "center": 0.0}).tolist()
    [0.0, 0.0, 2.0]
    """

    name: ClassVar[str] = "deadzone"
    parameter_names: ClassVar[tuple[str, ...]] = ("width", "center")
    grid_names: ClassVar[tuple[str, ...]] = ("width",)
    default_candidates: ClassVar[tuple[str, ...]] = ("deadzone",)

    def off(self) -> Params:
        return {"width": 0.0, "center": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"width": (0.0, command_span(u))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        span, c = command_span(u), float(u[0])
        return [{"width": float(f * span), "center": c} for f in (0.02, 0.05, 0.1, 0.2, 0.35, 0.5)]

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        w = params.get("width", 0.0)
        return u if w <= 0 else run_block(DeadZone(w, params.get("center", 0.0)), u, dt)


@dataclass(frozen=True)
class BacklashEffect(Effect):
    """Backlash (play) of total ``width`` (:class:`synth.sim.blocks.Backlash`).

    Examples
    --------
    >>> import numpy as np
    >>> BacklashEffect().input_map(np.array([0.0, 0.5, 2, 1.5]), 1.0, {"width": 2.0}).tolist()
    [0.0, 0.0, 1.0, 1.0]
    """

    name: ClassVar[str] = "backlash"
    parameter_names: ClassVar[tuple[str, ...]] = ("width",)
    grid_names: ClassVar[tuple[str, ...]] = ("width",)
    default_candidates: ClassVar[tuple[str, ...]] = ("backlash",)

    def off(self) -> Params:
        return {"width": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"width": (0.0, command_span(u))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        return [{"width": float(f * command_span(u))} for f in (0.02, 0.05, 0.1, 0.2, 0.35, 0.5)]

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        w = params.get("width", 0.0)
        return u if w <= 0 else run_block(Backlash(w), u, dt)
