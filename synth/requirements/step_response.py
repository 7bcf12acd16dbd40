"""Step-response limits of the linear loop, or under the spec's ``simulation:`` blocks: overshoot, settling
time, rise time."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import NonNegativeFloat, PositiveFloat, model_validator

from synth.loop_memo import LoopMemo
from synth.requirements.base import Bound, Requirement, RequirementResult, fmt, register
from synth.requirements.margins import UNSTABLE_SLACK, closed_loop_unstable, unstable_result
from synth.requirements.simulated import SimulatedStep, simulated_step
from synth.requirements.tracking import tracking_note
from synth.sim.spec import SimulationSpec

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch
    from synth.timeresp import LinearStep, StepMetrics

__all__ = ["INTERVALS", "MAX_DOUBLINGS", "StepResponse"]

MAX_DOUBLINGS = 8
"""The horizon starts at :func:`synth.timeresp.default_horizon` and doubles until the response has
settled (inside the band over the last quarter of the horizon, and what the closed loop's poles can still add
after it at most :data:`TAIL_SHARE` of the band); after this many doublings the verdict is "undetermined" (not
met), unless the closed-loop poles' tail needs more (:data:`POLE_DOUBLINGS`)."""

POLE_DOUBLINGS = 30
"""Most doublings the closed-loop poles' tail may ask for: the first horizon follows the fastest pole when the
poles span more than 50:1, and a slow pole's tail may need more than :data:`MAX_DOUBLINGS` of it (a PI on
``1/((s+1)(0.001 s+1))``, poles -999, -1.84, -0.163, settling at 19.7 s: "undetermined within 3.075 s", 0.012 s
doubled 8 times; a PID's design on ``12.98/s`` called "infeasible" for the same reason). The horizon then starts
where the tail says and may double twice more. Only without a delay, where the step is exact and each doubling
costs 4,000 samples: a delayed loop's step is simulated, and a design's candidates with a slow pole then ran
up to the simulation's limit each (a delayed PID of the step-design benchmark's seed 56, #9: 13.5 -> 200 s);
a delayed loop keeps :data:`MAX_DOUBLINGS` (a PID on ``12.98/s`` behind 5.2 ms is still "undetermined")."""

TAIL_SHARE = 0.05
"""What the step may still move after the horizon, as a share of the settling band (``settle_band`` times the
final value): the bound ``sum |c_i| e^(Re p_i t)`` of :func:`synth.timeresp.step_tail`. A slow pole that a zero
nearly cancels creeps back out of the band, and up to a higher overshoot, long after the fast part has settled
(a PID whose step was within 2 % at 0.37 s overshot 5.5 % at 1.1 s)."""

INTERVALS = 4000
"""Samples of the step over its first horizon (:func:`synth.timeresp.default_horizon`), and over each doubling of it
(:func:`synth.exact_steps.doubling_grid`): the step grows with the time, so every sample is within 1/4000 of its time
of the next, and a long horizon costs samples in proportion to its doublings, not its length. An even grid of up
to 64,001 samples ran before: a PID whose slow tail took eight doublings had 64,001 samples 1/250 of its first
horizon apart, where 36,001 now start 1/4000 apart. On 91 random PI and PID loops against a 400,001-sample even
grid: overshoot within 0.0011 points and settling times within 0.08 % (the even grid: 0.0025 points, 0.08 %); at
2000 per span, 0.0053 points and 0.18 %, and pid_step's design 0.8 s faster."""
SCREEN_INTERVALS = 400
"""Samples per span of :meth:`StepResponse.fails_surely`'s coarse step: a divisor of :data:`INTERVALS`, so that its
samples are among the ones the full evaluation takes (over the same first horizon and the doublings it starts
with), and what they prove the full evaluation finds too."""
_DELAYED_OUTCOMES: LoopMemo[_Outcome] = LoopMemo()  # the delayed loops' steps, by loop and requirement
_CHUNK = 2_000_000  # samples of the loops' steps computed together (16 MB per array)
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
        if self.under != "linear" and self.simulation.step is not None and \
                self.simulation.step[0] == self.simulation.step[1]:
            a = self.simulation.step[0]
            raise ValueError(f"under: {self.under} measures the simulation's step, and simulation.step [{a:g}, {a:g}] "
                             "does not step")
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
        linear = tracking_note(self._linear(loop), loop)
        return linear if self.under == "linear" else self._simulated(loop, linear)

    def stable_slack(self, loop: Loop, per_decade: int = 80) -> float:
        """:meth:`slack` on a loop known to be closed-loop stable: the linear step without counting the loop's
        roots first (with a delay that count is a Nyquist count, about a fifth of a map point's cost); ``under``
        a simulation, :meth:`slack`.

        Examples
        --------
        >>> from synth.plant import Plant; from synth.controllers import Controller; from synth.loop import Loop
        >>> loop = Loop(Plant.from_string("1/(s+1)", delay=0.1), Controller("PI", {"kp": 1.0, "ki": 2.0}))
        >>> req = StepResponse(max_overshoot=20)
        >>> fresh = Loop(loop.plant, loop.controller)
        >>> req.stable_slack(fresh) == req.slack(loop), "_stability" in vars(fresh)  # the same, not counted
        (True, False)
        """
        if self.under != "linear":
            return self.slack(loop, per_decade)
        return self._linear(loop).slack

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """The slack of every loop of ``batch`` (:class:`~synth.loop_batch.LoopBatch`), as :meth:`slack` gives it:
        without a delay the steps of all stable loops at once (:func:`synth.exact_steps.exact_steps`, the same
        arithmetic as one loop's); with a delay, one loop at a time where the batch's root counts
        (:meth:`~synth.loop_batch.LoopBatch.unstable_root_counts`: by D-decomposition when the loops differ by a
        gain) say the loop is stable; ``under`` a simulation, one loop at a time.

        Examples
        --------
        >>> from synth.loop_batch import LoopBatch; from synth.plant import Plant
        >>> from synth.controllers import Controller; from synth.loop import Loop
        >>> G, req = Plant.from_string("1/(s*(s+1))"), StepResponse(max_overshoot=20, max_settling_time=10)
        >>> batch = LoopBatch(G, [Controller("P", {"kp": k}) for k in (0.5, 1.0, 4.0)])
        >>> bool(np.allclose(req.batch_slack(batch), [req.slack(Loop(G, c)) for c in batch.controllers]))
        True
        """
        if self.under != "linear":
            return super().batch_slack(batch, per_decade)
        counts = batch.unstable_root_counts()
        out = UNSTABLE_SLACK * np.maximum(counts, 1).astype(float)
        stable = np.flatnonzero(counts == 0)
        loops = batch.loops()
        if batch.plant.delay > 0.0:  # simulated one by one, the count already made
            out[stable] = [self.stable_slack(loops[i], per_decade) for i in stable]
        else:
            out[stable] = [self._slack_of(o) for o in self._exact_outcomes([loops[i] for i in stable])]
        return out

    def vectorized_on(self, plants: list[Any]) -> bool:
        """Whether :meth:`batch_slack` is vectorized for these plants: the linear loop's step without a delay.

        Examples
        --------
        >>> from synth.plant import Plant
        >>> req = StepResponse(max_overshoot=20)
        >>> req.vectorized_on([Plant.from_string("1/(s+1)")]), req.vectorized_on([Plant.from_string("1/(s+1)", delay=0.1)])
        (True, False)
        """
        return self.under == "linear" and all(p.delay == 0.0 for p in plants)

    def fails_surely(self, loops: list[Loop]) -> np.ndarray:
        """For each stable loop, True where the step on a coarse grid (:data:`SCREEN_INTERVALS` per span, the
        horizon the full evaluation starts with) already breaks the overshoot limit (a sample above it) or the
        settling-time limit (a sample outside the band at or after it). Those samples are exact and among the
        full evaluation's, so its slack is negative too; a rise-time limit, a delayed loop or a simulated step is
        never proved here.

        Examples
        --------
        >>> from synth.plant import Plant; from synth.controllers import Controller; from synth.loop import Loop
        >>> G, req = Plant.from_string("1/(s*(s+1))"), StepResponse(max_overshoot=20)
        >>> loops = [Loop(G, Controller("P", {"kp": k})) for k in (0.5, 1.0, 4.0)]  # overshoot 0, 16.3, 44.4 %
        >>> req.fails_surely(loops).tolist(), [req.slack(lp) < 0 for lp in loops]
        ([False, False, True], [False, False, True])
        """
        from synth.exact_steps import doubling_grid, exact_steps
        from synth.polynomials import trim

        out = np.zeros(len(loops), dtype=bool)
        if self.under != "linear" or (self.max_overshoot is None and self.max_settling_time is None):
            return out
        plans = {i: self._plan(loop) for i, loop in enumerate(loops) if loop.delay == 0.0}
        for start in sorted({plan.start for plan in plans.values()}):
            rows = [i for i, plan in plans.items() if plan.start == start]
            unit = doubling_grid(1.0, start, SCREEN_INTERVALS)
            firsts = np.array([plans[i].first for i in rows])
            finals = np.array([plans[i].final for i in rows])
            y = exact_steps([loops[i].num for i in rows], [trim(np.polyadd(loops[i].den, loops[i].num)) for i in rows],
                            firsts, unit)
            fails = np.zeros(len(rows), dtype=bool)
            with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
                frac = y / finals[:, None]
                if self.max_overshoot is not None:
                    fails |= np.max(frac, axis=1) - 1.0 > self.max_overshoot / 100.0 * (1.0 + 1e-9) + 1e-12
                if self.max_settling_time is not None:
                    late = firsts[:, None] * unit[None, :] >= self.max_settling_time
                    fails |= np.any(late & (np.abs(frac - 1.0) > self.settle_band * (1.0 + 1e-9)), axis=1)
            out[rows] = fails & (finals != 0) & np.isfinite(finals)
        return out

    def _plan(self, loop: Loop) -> _Plan:
        """The step's final value, the closed loop's poles and tail weights, the band, the first horizon and the
        doublings the tail needs at least."""
        from synth.timeresp import default_horizon, step_tail

        final = loop.dc_gain()  # with its sign: a step to T(0) < 0 settles below 0
        poles = loop.closed_loop_poles()  # once: the horizon and the tail's residues both start from them
        first = default_horizon(loop, poles)
        poles, weights = step_tail(loop, poles)
        band = self.settle_band * abs(final)
        # the doublings the poles' tail needs at least, skipped (each pole's term within its share of the bound;
        # past the last doubling the response is simulated once there, for the evidence)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            needed = np.log(np.maximum(weights * poles.size / (TAIL_SHARE * band), 1.0)) / -poles.real
        longest = float(np.max(needed, initial=0.0))
        exact = loop.delay == 0.0  # a delayed loop's step is simulated: it keeps MAX_DOUBLINGS
        start = 0 if longest <= first else int(min(POLE_DOUBLINGS if exact else MAX_DOUBLINGS,
                                                   np.ceil(np.log2(longest / first))))
        last = max(MAX_DOUBLINGS, start + 2) if exact else MAX_DOUBLINGS
        return _Plan(final, poles, weights, band, first, start, last)

    def _exact_outcomes(self, loops: list[Loop]) -> list[_Outcome]:
        """The step of each loop (stable, without a delay), all at once: the loops needing the same doublings
        together (:func:`synth.exact_steps.exact_steps`), each doubled until settled or
        :data:`MAX_DOUBLINGS`, as :meth:`_delayed_outcome` does one loop with a delay."""
        from synth.exact_steps import doubling_grid, exact_steps
        from synth.polynomials import trim
        from synth.timeresp import StepMetrics, metric_rows

        plans = [self._plan(loop) for loop in loops]
        out: list[_Outcome | None] = [None] * len(loops)
        todo = {i: plan.start for i, plan in enumerate(plans)}
        while todo:
            doublings = min(todo.values())
            unit = doubling_grid(1.0, doublings, INTERVALS)
            tail = unit >= 0.75 * unit[-1]
            every = [i for i, d in todo.items() if d == doublings]
            chunk = max(1, _CHUNK // unit.size)
            for rows in (every[k:k + chunk] for k in range(0, len(every), chunk)):
                group = [plans[i] for i in rows]
                firsts = np.array([g.first for g in group])
                y = exact_steps([loops[i].num for i in rows], [trim(np.polyadd(loops[i].den, loops[i].num))
                                                              for i in rows], firsts, unit)
                finals = np.array([g.final for g in group])
                horizons = firsts * unit[-1]
                with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
                    inside = np.all(np.abs(y[:, tail] - finals[:, None]) <= np.array([g.band for g in group])[:, None],
                                    axis=1)
                    settled = inside & np.array([g.after(h) <= TAIL_SHARE * g.band for g, h in zip(group, horizons)])
                    done = settled | (doublings >= np.array([g.last for g in group]))  # the others double
                    rise, peak, settling = np.full((3, len(rows)), np.nan)
                    rise[done], peak[done], settling[done] = metric_rows(
                        firsts[done, None] * unit, y[done] / finals[done, None], None, self.settle_band)
                for j, i in enumerate(rows):
                    if not done[j]:
                        todo[i] = doublings + 1
                        continue
                    del todo[i]
                    final = finals[j]
                    if final == 0 or not np.isfinite(final):
                        m = StepMetrics(float("nan"), float("nan"), float("nan"), float(final), float(np.max(y[j])))
                    else:
                        m = StepMetrics(float(rise[j]), max(0.0, (float(peak[j]) - 1.0) * 100.0), float(settling[j]),
                                        float(final), float(peak[j] * final))
                    out[i] = _Outcome(m, float(horizons[j]), unit.size, float(firsts[j] * (unit[-1] - unit[-2])),
                                      float(firsts[j] * unit[1]), bool(settled[j]), group[j].after(horizons[j]),
                                      group[j].poles.size, 0.0, 0.0 if final else float("nan"), True)
        return [o for o in out if o is not None]

    def _linear(self, loop: Loop) -> RequirementResult:
        outcome = self._exact_outcomes([loop])[0] if loop.delay == 0.0 else \
            _DELAYED_OUTCOMES.get(loop, self._delayed_outcome, *self._linear_key())  # asked again: not simulated twice
        return self._result_of(outcome)

    def _linear_key(self) -> tuple[float | None, ...]:
        """What the linear step's outcome depends on besides the loop: the limits and the settling band (not the
        ``simulation`` block, whose lists do not hash, nor the label)."""
        return self.max_overshoot, self.max_settling_time, self.max_rise_time, self.settle_band

    def _delayed_outcome(self, loop: Loop) -> _Outcome:
        """The step of a loop with a delay: simulated (:func:`synth.timeresp.linear_step`, its error estimate
        refined until no limit's verdict depends on it), the horizon doubled until settled."""
        from synth.exact_steps import doubling_grid
        from synth.timeresp import linear_step, step_metrics

        plan = self._plan(loop)
        final, band = plan.final, plan.band
        horizon = plan.first * 2.0**plan.start
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
        for doublings in range(plan.start, plan.last + 1):
            run = linear_step(loop, decided=bounds_agree, times=doubling_grid(plan.first, doublings, INTERVALS),
                              extremes=True)
            t, y = run.t, run.y
            tail = t >= 0.75 * horizon
            settled = bool(np.all(np.abs(y[tail] - final) <= band)) and plan.after(horizon) <= TAIL_SHARE * band
            if settled:
                break
            horizon *= 2.0
        else:
            horizon /= 2.0  # the last one simulated
        # else judged on the worst case the error allows
        decided = any(r is run for r in agreed) or self._decided(run, final)
        m = step_metrics(t, y, 0.0, final, self.settle_band, None if decided else run.error)
        error = float(np.max(run.error)) / abs(final) if final else float("nan")
        return _Outcome(m, float(horizon), int(t.size), float(np.max(np.diff(t))), float(t[1] - t[0]), settled,
                        plan.after(horizon), plan.poles.size, run.dt, error, decided)

    def _slack_of(self, o: _Outcome) -> float:
        slack = min(p[0] for p in self._limits(_measured(o.metrics)))
        return slack if o.settled else min(slack, -1e-3)

    def _result_of(self, o: _Outcome) -> RequirementResult:
        """The requirement's result on a step :meth:`_exact_outcomes` or :meth:`_delayed_outcome` made."""
        evidence = dict(horizon=o.horizon, samples=o.samples, resolution=o.resolution, simulation_step=o.dt,
                        simulation_error=o.error, settled=o.settled, tail_bound=o.tail_bound,
                        poles_counted=o.poles, **o.metrics.to_dict())
        parts = self._limits(_measured(o.metrics))
        slack, name, value, bound, unit = min(parts, key=lambda p: p[0])
        if not o.settled:
            texts = (f"undetermined: not settled within {fmt(o.horizon)} s (the closed-loop poles can still move it "
                     f"by {fmt(o.tail_bound)})")
            return self.result(value=float("nan"), bound=bound, unit=unit, slack=min(slack, -1e-3), margin=float("nan"),
                               binding_frequency=None, message=f"step response {texts}: NOT met", binding=name,
                               determined=False, **evidence)
        texts = "; ".join(f"{n} {fmt(v)} {u} (max {fmt(b)})" for _, n, v, b, u in parts)
        if o.dt == 0.0:
            held = ""
        elif not np.isfinite(o.error):
            held = f"; held at {fmt(o.dt)} s, the delay one step of it: error not estimated"
        else:
            held = (f"; held at {fmt(o.dt)} s, estimated error up to {fmt(o.error)} of the final value"
                    + ("" if o.decided else ", a limit within it: judged on the worst case it allows"))
        coarsest = "" if o.resolution <= 1.01 * o.finest else f" to {fmt(o.resolution)} s"
        msg = (f"step response: {texts}: {'met' if slack >= 0 else 'NOT met'}, tightest: {name} "
               f"({o.samples} samples over {fmt(o.horizon)} s, resolution {fmt(o.finest)} s{coarsest}{held}; after it "
               f"the {o.poles} closed-loop poles can move it by at most {fmt(o.tail_bound)})")
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


@dataclass(frozen=True)
class _Plan:
    """What a loop's step starts from (:meth:`StepResponse._plan`)."""

    final: float
    poles: np.ndarray
    weights: np.ndarray
    band: float
    first: float
    start: int
    last: int  # the last doubling simulated before the verdict is "undetermined"

    def after(self, horizon: float) -> float:
        """What the closed-loop poles can still move the step after ``horizon`` (:func:`synth.timeresp.step_tail`)."""
        return float(np.sum(self.weights * np.exp(self.poles.real * horizon))) if self.poles.size else 0.0


@dataclass(frozen=True)
class _Outcome:
    """A loop's step as the requirement judges it: the metrics and what they rest on."""

    metrics: StepMetrics
    horizon: float
    samples: int
    resolution: float  # the coarsest spacing of the samples (the doublings' last span)
    finest: float
    settled: bool
    tail_bound: float
    poles: int
    dt: float  # the simulation step with a delay, 0 when exact
    error: float  # the simulation's estimated error, relative to the final value
    decided: bool  # the error cannot change a limit's verdict (else the metrics are the worst it allows)


def _measured(s: SimulatedStep | StepMetrics) -> dict[str, float]:
    return {"max_overshoot": s.overshoot, "max_settling_time": s.settling_time, "max_rise_time": s.rise_time}
