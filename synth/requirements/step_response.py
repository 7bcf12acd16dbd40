"""Step-response limits of the linear loop: overshoot, settling time, rise time."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import NonNegativeFloat, PositiveFloat, model_validator

from synth.requirements.base import Bound, Requirement, RequirementResult, fmt, register
from synth.requirements.margins import closed_loop_unstable, unstable_result

if TYPE_CHECKING:
    from synth.loop import Loop

__all__ = ["MAX_DOUBLINGS", "StepResponse"]

MAX_DOUBLINGS = 8
"""The horizon starts at :func:`synth.timeresp.default_horizon` and doubles until the response has
settled (inside the band over the last quarter of the horizon); after this many doublings the verdict is
"undetermined" (not met)."""

_POINTS = 4001
_LABELS = {"max_overshoot": ("overshoot", "%"), "max_settling_time": ("settling time", "s"),
           "max_rise_time": ("rise time", "s")}


@register
class StepResponse(Requirement):
    """Limits on the unit reference step response of the linear loop (the plant's delay exact).

    ``max_overshoot`` (percent of the final value ``T(0)``), ``max_settling_time`` (last exit from a
    band of ``settle_band`` times the final value, s) and ``max_rise_time`` (10 % to 90 %, s); give at
    least one. The response comes from :func:`synth.timeresp.step_response` (exact without a delay, a
    fine zero-order-hold simulation with one); the horizon follows the dynamics and is extended until
    the response has settled, else the verdict is "undetermined" (not met). The horizon, the number of
    samples and the time resolution are in ``details``. On a closed loop that is not stable the
    requirement is not met.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s*(s+1))"), Controller("P", {"kp": 1.0}))
    >>> r = StepResponse(max_overshoot=20, max_settling_time=10).evaluate(loop)
    >>> r.met, round(r.details["overshoot"], 2), round(r.details["settling_time"], 2)
    (True, 16.3, 8.08)
    """

    type: Literal["step_response"] = "step_response"
    max_overshoot: NonNegativeFloat | None = None
    max_settling_time: PositiveFloat | None = None
    max_rise_time: PositiveFloat | None = None
    settle_band: PositiveFloat = 0.02
    title: ClassVar[str] = "step response"
    bounds: ClassVar[dict[str, Bound]] = {"max_overshoot": Bound("upper", "%"),
                                          "max_settling_time": Bound("upper", "s"),
                                          "max_rise_time": Bound("upper", "s")}
    stricter: ClassVar[dict[str, int]] = {"settle_band": -1}
    example: ClassVar[dict[str, Any]] = {"type": "step_response", "max_overshoot": 20.0}

    @model_validator(mode="after")
    def _one_limit(self) -> StepResponse:
        if self.max_overshoot is None and self.max_settling_time is None and self.max_rise_time is None:
            raise ValueError("give at least one of max_overshoot, max_settling_time, max_rise_time")
        if self.settle_band >= 1:
            raise ValueError(f"settle_band is a fraction of the final value, got {self.settle_band:g}")
        return self

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        from synth.timeresp import default_horizon, step_metrics, step_response  # scipy.signal on first use

        if closed_loop_unstable(loop):
            return unstable_result(self, loop, "step response")
        final = loop.T0()
        horizon = default_horizon(loop)
        settled = False
        for _ in range(MAX_DOUBLINGS + 1):
            t, y, dt = step_response(loop, horizon, _POINTS)
            tail = t >= 0.75 * horizon
            settled = bool(np.all(np.abs(y[tail] - final) <= self.settle_band * abs(final)))
            if settled:
                break
            horizon *= 2.0
        m = step_metrics(t, y, 0.0, final, self.settle_band)
        measured = {"max_overshoot": m.overshoot, "max_settling_time": m.settling_time,
                    "max_rise_time": m.rise_time}
        resolution = float(t[1] - t[0])
        evidence = dict(horizon=float(horizon), samples=int(t.size), resolution=resolution,
                        simulation_step=dt, settled=settled, **m.to_dict())
        parts = []
        for f, (name, unit) in _LABELS.items():
            bound = getattr(self, f)
            if bound is None:
                continue
            value = measured[f]
            if not np.isfinite(value):
                slack = -np.inf
            elif unit == "%":  # percent: the slack in nepers of (1 + overshoot) against (1 + bound)
                slack = float(np.log((100.0 + bound) / (100.0 + value)))
            else:
                slack = float(np.log(bound / value)) if value > 0 else np.inf
            parts.append((slack, name, value, bound, unit))
        slack, name, value, bound, unit = min(parts, key=lambda p: p[0])
        if not settled:
            texts = f"undetermined: not settled within {fmt(horizon)} s"
            return self.result(value=float("nan"), bound=bound, unit=unit, slack=min(slack, -1e-3), margin=float("nan"),
                               binding_frequency=None, message=f"step response {texts}: NOT met", binding=name,
                               determined=False, **evidence)
        texts = "; ".join(f"{n} {fmt(v)} {u} (max {fmt(b)})" for _, n, v, b, u in parts)
        msg = (f"step response: {texts}: {'met' if slack >= 0 else 'NOT met'}, tightest: {name} "
               f"({_POINTS} samples over {fmt(horizon)} s, resolution {fmt(resolution)} s)")
        return self.result(value=value, bound=bound, unit=unit, slack=slack, margin=bound - value,
                           binding_frequency=None, message=msg, binding=name, determined=True, **evidence)
