"""Step-response limits of the linear loop, or under the spec's ``simulation:`` blocks: overshoot, settling
time, rise time."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import NonNegativeFloat, PositiveFloat, model_validator

from synth.requirements.base import Bound, Requirement, RequirementResult, fmt, register
from synth.requirements.margins import closed_loop_unstable, unstable_result
from synth.requirements.simulated import SimulatedStep, simulated_step
from synth.sim.spec import SimulationSpec

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.timeresp import LinearStep, StepMetrics

__all__ = ["MAX_DOUBLINGS", "StepResponse"]

MAX_DOUBLINGS = 8
"""The horizon starts at :func:`synth.timeresp.default_horizon` and doubles until the response has
settled (inside the band over the last quarter of the horizon, and what the closed loop's poles can still add
after it at most :data:`TAIL_SHARE` of the band); after this many doublings the verdict is "undetermined" (not
met)."""

TAIL_SHARE = 0.05
"""What the step may still move after the horizon, as a share of the settling band (``settle_band`` times the
final value): the bound ``sum |c_i| e^(Re p_i t)`` of :func:`synth.timeresp.step_tail`. A slow pole that a zero
nearly cancels creeps back out of the band, and up to a higher overshoot, long after the fast part has settled
(a PID whose step was within 2 % at 0.37 s overshot 5.5 % at 1.1 s)."""

_POINTS = 4001
_MAX_POINTS = 64001  # the samples grow with the horizon up to this: the fast part keeps its resolution
_LABELS = {"max_overshoot": ("overshoot", "%"), "max_settling_time": ("settling time", "s"),
           "max_rise_time": ("rise time", "s")}


@register
class StepResponse(Requirement):
    """Limits on the unit reference step response of the linear loop (the plant's delay exact).

    ``max_overshoot`` (percent of the final value ``T(0)``), ``max_settling_time`` (last exit from a
    band of ``settle_band`` times the final value, s) and ``max_rise_time`` (10 % to 90 %, s); give at
    least one. The response comes from :func:`synth.timeresp.linear_step` (exact without a delay, a
    fine zero-order-hold simulation with one, extrapolated with an error estimate and refined until that
    error cannot change a limit's verdict, or to :data:`synth.timeresp.STEP_TOLERANCE`, where a limit still
    within it is judged on the worst case it allows); the horizon follows the dynamics and is extended until
    the response has settled, else the verdict is "undetermined" (not met). The horizon, the number of
    samples, the time resolution, the simulation step and its error estimate (``simulation_error``, relative
    to the final value) are in ``details``. On a closed loop that is not stable the requirement is not met.

    ``under: simulation`` judges the limits on the spec's sampled nonlinear loop instead (its
    ``simulation:`` block: actuator and sensor blocks, operating point, ``dt``, the step
    ``simulation.step``; :func:`synth.requirements.simulated.simulated_step`), with the simulator's
    evidence rules: the run must be "settled" (a limit cycle, a diverging run or "undetermined within
    N s" is not met, and says so); ``under: both`` requires both. The spec parser copies its
    ``simulation:`` block into the entry (``simulation`` here), which is an error without one. Overshoot
    is then in percent of the step, from the output at the step to its final value.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s*(s+1))"), Controller("P", {"kp": 1.0}))
    >>> r = StepResponse(max_overshoot=20, max_settling_time=10).evaluate(loop)
    >>> r.met, round(r.details["overshoot"], 2), round(r.details["settling_time"], 2)
    (True, 16.3, 8.08)

    Under a saturation at +-0.5 the same loop, stepped by 1, overshoots less (12.75 % by an independent
    ``solve_ivp`` run), and says what it ran; ``under: both`` also holds the linear loop to the limit:

    >>> sim = {"dt": 0.005, "step": [0, 1], "actuator": [{"type": "saturation", "min": -0.5, "max": 0.5}]}
    >>> r = StepResponse(max_overshoot=15, under="simulation", simulation=sim).evaluate(loop)
    >>> r.met, round(r.details["simulated"]["overshoot"], 1), r.details["simulated"]["verdict"]
    (True, 12.8, 'settled')
    >>> StepResponse(max_overshoot=15, under="both", simulation=sim).evaluate(loop).met
    False
    """

    type: Literal["step_response"] = "step_response"
    max_overshoot: NonNegativeFloat | None = None
    max_settling_time: PositiveFloat | None = None
    max_rise_time: PositiveFloat | None = None
    settle_band: PositiveFloat = 0.02
    under: Literal["linear", "simulation", "both"] = "linear"
    simulation: SimulationSpec | None = None
    title: ClassVar[str] = "step response"
    costly: ClassVar[bool] = True
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
        if self.under != "linear" and self.simulation is None:
            raise ValueError(f"under: {self.under} judges the step under the spec's simulation: blocks, "
                             "and the spec has no simulation: block")
        return self

    @classmethod
    def wants_simulation(cls, entry: dict[str, Any]) -> bool:
        """Whether a spec entry asks for the spec's ``simulation:`` block (``under`` is not ``linear``).

        Examples
        --------
        >>> StepResponse.wants_simulation({"type": "step_response", "under": "both"})
        True
        """
        return entry.get("under", "linear") != "linear"

    def _limits(self, measured: dict[str, float]) -> list[tuple[float, str, float, float, str]]:
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
        return parts

    def _simulated(self, loop: Loop, linear: RequirementResult | None) -> RequirementResult:
        """The limits on the simulated nonlinear step (and on the linear one, ``linear``, when given)."""
        assert self.simulation is not None
        s = simulated_step(self.simulation, loop, self.settle_band)
        blocks = ", ".join(s.evidence["actuator"] + s.evidence["sensor"]) or "no blocks"
        what = f"simulated step {fmt(s.evidence['step'][0])} -> {fmt(s.evidence['step'][1])} ({blocks})"
        details = {"simulated": s.to_dict(), "under": self.under}
        if linear is not None:
            details["linear"] = {k: linear.details.get(k) for k in ("overshoot", "settling_time", "rise_time")}
            details["linear"]["met"] = linear.met
        if s.verdict != "settled":
            first = next(f for f in _LABELS if getattr(self, f) is not None)
            slack = -1.0 if s.verdict in ("limit_cycle", "diverging") else -1e-3
            return self.result(value=float("nan"), bound=getattr(self, first), unit=_LABELS[first][1], slack=slack,
                               margin=float("nan"), binding_frequency=None, binding=_LABELS[first][0],
                               determined=s.verdict != "undetermined",
                               message=f"{what}: {s.summary}: NOT met", **details)
        parts = self._limits(_measured(s))
        slack, name, value, bound, unit = min(parts, key=lambda p: p[0])
        texts = "; ".join(f"{n} {fmt(v)} {u} (max {fmt(b)})" for _, n, v, b, u in parts)
        msg = f"{what}: {texts}: {'met' if slack >= 0 else 'NOT met'}, tightest: {name} ({s.summary})"
        if linear is not None and linear.slack < slack:
            slack, name, value, bound, unit = linear.slack, f"linear {linear.details.get('binding')}", linear.value, \
                linear.bound, linear.unit
            msg = f"{linear.message}; {msg}; tightest: the linear loop"
        return self.result(value=value, bound=bound, unit=unit, slack=slack, margin=bound - value,
                           binding_frequency=None, message=msg, binding=name, determined=True, **details)

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        if closed_loop_unstable(loop):
            return unstable_result(self, loop, "step response")
        if self.under == "simulation":
            return self._simulated(loop, None)
        linear = self._linear(loop)
        return linear if self.under == "linear" else self._simulated(loop, linear)

    def _linear(self, loop: Loop) -> RequirementResult:
        from synth.timeresp import default_horizon, linear_step, step_metrics, step_tail

        final = loop.T0()
        poles = loop.closed_loop_poles()  # once: the horizon and the tail's residues both start from them
        horizon = default_horizon(loop, poles)
        poles, weights = step_tail(loop, poles)
        band = self.settle_band * abs(final)

        def after(h: float) -> float:
            return float(np.sum(weights * np.exp(poles.real * h))) if poles.size else 0.0

        # the doublings the poles' tail needs at least, skipped (each pole's term within its share of the bound;
        # past the last doubling the response is simulated once there, for the evidence)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            needed = np.log(np.maximum(weights * poles.size / (TAIL_SHARE * band), 1.0)) / -poles.real
        longest = float(np.max(needed, initial=0.0))
        start = 0 if longest <= horizon else int(min(MAX_DOUBLINGS, np.ceil(np.log2(longest / horizon))))
        horizon *= 2.0**start
        points = min(2**start * (_POINTS - 1) + 1, _MAX_POINTS)

        agreed: list[LinearStep] = []  # the runs whose verdicts were found decided (not judged twice)

        def bounds_agree(run: LinearStep) -> bool:  # the run's error cannot change any limit's verdict
            tail = run.t >= 0.75 * run.t[-1]
            if not np.all(np.abs(run.y[tail] - final) <= band):
                return True  # not settled here: the horizon doubles, this run is not judged
            if self._decided(run, final):
                agreed.append(run)
                return True
            return False

        settled = False
        for _ in range(start, MAX_DOUBLINGS + 1):
            run = linear_step(loop, horizon, points, decided=bounds_agree)
            t, y = run.t, run.y
            tail = t >= 0.75 * horizon
            settled = bool(np.all(np.abs(y[tail] - final) <= band)) and after(horizon) <= TAIL_SHARE * band
            if settled:
                break
            horizon *= 2.0
            points = min(2 * points - 1, _MAX_POINTS)
        else:
            horizon /= 2.0  # the last one simulated
        tail_bound = after(horizon)
        # else judged on the worst case the error allows
        decided = run.dt == 0.0 or any(r is run for r in agreed) or self._decided(run, final)
        m = step_metrics(t, y, 0.0, final, self.settle_band, None if decided else run.error)
        error = float(np.max(run.error)) / abs(final) if final else float("nan")
        measured = _measured(m)
        resolution = float(t[1] - t[0])
        evidence = dict(horizon=float(horizon), samples=int(t.size), resolution=resolution,
                        simulation_step=run.dt, simulation_error=error, settled=settled, tail_bound=tail_bound,
                        poles_counted=int(poles.size), **m.to_dict())
        parts = self._limits(measured)
        slack, name, value, bound, unit = min(parts, key=lambda p: p[0])
        if not settled:
            texts = (f"undetermined: not settled within {fmt(horizon)} s (the closed-loop poles can still move it by "
                     f"{fmt(tail_bound)})")
            return self.result(value=float("nan"), bound=bound, unit=unit, slack=min(slack, -1e-3), margin=float("nan"),
                               binding_frequency=None, message=f"step response {texts}: NOT met", binding=name,
                               determined=False, **evidence)
        texts = "; ".join(f"{n} {fmt(v)} {u} (max {fmt(b)})" for _, n, v, b, u in parts)
        if run.dt == 0.0:
            held = ""
        elif not np.isfinite(error):
            held = f"; held at {fmt(run.dt)} s, the delay one step of it: error not estimated"
        else:
            held = (f"; held at {fmt(run.dt)} s, estimated error up to {fmt(error)} of the final value"
                    + ("" if decided else ", a limit within it: judged on the worst case it allows"))
        msg = (f"step response: {texts}: {'met' if slack >= 0 else 'NOT met'}, tightest: {name} "
               f"({t.size} samples over {fmt(horizon)} s, resolution {fmt(resolution)} s{held}; after it the "
               f"{poles.size} closed-loop poles can move it by at most {fmt(tail_bound)})")
        return self.result(value=value, bound=bound, unit=unit, slack=slack, margin=bound - value,
                           binding_frequency=None, message=msg, binding=name, determined=True, **evidence)

    def _decided(self, run: LinearStep, final: float) -> bool:
        """Whether every limit has the same verdict on the worst and on the best response ``run``'s error
        allows."""
        from synth.timeresp import step_metrics

        worst, best = (step_metrics(run.t, run.y, 0.0, final, self.settle_band, sign * run.error)
                       for sign in (1.0, -1.0))
        return all((a[0] >= 0) == (b[0] >= 0) for a, b in zip(self._limits(_measured(worst)),
                                                               self._limits(_measured(best))))


def _measured(s: SimulatedStep | StepMetrics) -> dict[str, float]:
    return {"max_overshoot": s.overshoot, "max_settling_time": s.settling_time, "max_rise_time": s.rise_time}
