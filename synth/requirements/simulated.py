"""Requirements judged under the spec's ``simulation:`` blocks: a simulated step and its verdict.

:func:`simulated_step` runs the spec's sampled nonlinear loop (its actuator and sensor blocks, operating
point, sample time, controller discretization) through :func:`synth.sim.verdict.step_verdict`: the horizon
follows the dynamics and doubles until the run is settled, a limit cycle or diverging, else the verdict is
"undetermined within N s". The step limits of :class:`~synth.requirements.step_response.StepResponse` and
the confirming runs of :class:`~synth.requirements.no_limit_cycle.NoLimitCycle` use it.

A requirement that needs the spec's ``simulation:`` block declares it by a ``simulation`` field and a
``wants_simulation(entry)`` class method; the spec parser copies the block into such an entry when the
entry does not give its own (:func:`bind_simulation`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from synth.sim.spec import SimulationSpec

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.requirements.base import RequirementResult

__all__ = ["SimulatedStep", "bind_simulation", "confirm_prediction", "confirming_runs", "simulated_step"]

_RUNS: dict[tuple[Any, ...], SimulatedStep] = {}
"""Confirming runs already simulated in this process, by loop, blocks and added delay (deterministic)."""


@dataclass
class SimulatedStep:
    """One simulated step of the nonlinear loop, judged.

    Attributes
    ----------
    verdict : str
        ``settled``, ``limit_cycle``, ``diverging`` or ``undetermined`` (:data:`synth.sim.verdict.VERDICTS`).
    overshoot, settling_time, rise_time : float
        Percent of the step, s, s (``nan`` when not measured, e.g. not settled).
    summary : str
        The verdict and its evidence in one line.
    evidence : dict
        The verdict's evidence (horizons tried, samples, cycles, rule) and what was simulated.
    amplitude, period : float or None
        Of the limit cycle, when there is one.
    """

    verdict: str
    overshoot: float
    settling_time: float
    rise_time: float
    summary: str
    evidence: dict[str, Any] = field(default_factory=dict)
    amplitude: float | None = None
    period: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def simulated_step(sim: SimulationSpec, loop: Loop, settle_band: float = 0.02, extra_delay: float = 0.0,
                   actuator: list[Any] | None = None, sensor: bool = True) -> SimulatedStep:
    """Simulate the spec's step (``sim.default_step()`` at ``sim.step_time``) on the nonlinear loop of
    ``loop``'s plant and controller, and judge it.

    ``extra_delay`` is added to the loop delay; ``actuator`` (block entries) replaces the spec's actuator
    chain and ``sensor=False`` drops its sensor chain (the describing-function check simulates exactly the
    blocks it analysed). The horizon is the spec's when it sets one, else from the dynamics; disturbances
    are not applied (the step limits are about the reference step).

    Examples
    --------
    The issue's loop, P(20) on ``1/(s(s+1)(s+2))`` saturated at +-1: a limit cycle; P(2) settles (with
    38.94 % overshoot by an independent ``solve_ivp`` run).

    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> sim = SimulationSpec.model_validate({"dt": 0.002, "step": [0, 0.1],
    ...                                      "actuator": [{"type": "saturation", "min": -1, "max": 1}]})
    >>> G = Plant.from_string("1/(s*(s+1)*(s+2))")
    >>> r = simulated_step(sim, Loop(G, Controller("P", {"kp": 20.0})))
    >>> r.verdict, round(r.amplitude, 2), round(r.period, 1)
    ('limit_cycle', 0.22, 4.5)
    >>> r = simulated_step(sim, Loop(G, Controller("P", {"kp": 2.0})))
    >>> r.verdict, round(r.overshoot, 1)
    ('settled', 39.0)
    """
    from synth.sim.verdict import step_verdict

    blocks = sim
    if actuator is not None or not sensor:
        data = sim.model_dump(exclude_unset=True)  # what the spec set (an unset horizon follows the dynamics)
        if actuator is not None:
            data["actuator"] = [b.model_dump() if hasattr(b, "model_dump") else b for b in actuator]
        if not sensor:
            data["sensor"] = []
        blocks = SimulationSpec.model_validate(data)
    nl = blocks.build_loop(loop.plant, loop.controller, str(loop.controller))
    if extra_delay:
        nl = nl.replace(loop_delay=nl.loop_delay + extra_delay)
    start, end = sim.default_step()
    given = sim.horizon if "horizon" in sim.model_fields_set else None
    v = step_verdict(nl, start, end, sim.step_time, given, None, (), sim.seed, sim.limit_cycle.min_amplitude,
                     sim.limit_cycle.window)
    evidence = {**v.evidence.to_dict(), "step": [float(start), float(end)], "step_time": sim.step_time,
                "actuator": [b.type for b in blocks.actuator], "sensor": [b.type for b in blocks.sensor],
                "loop_delay": float(nl.loop_delay), "dt": float(nl.dt)}
    nan = float("nan")
    if v.verdict != "settled":
        lc = v.metrics.limit_cycle
        cyc = v.verdict == "limit_cycle"
        return SimulatedStep(v.verdict, nan, nan, nan, v.summary(), evidence,
                             float(lc.amplitude) if cyc and lc.amplitude is not None else None,
                             float(lc.period) if cyc and lc.period is not None else None)
    from synth.sim.authority import short_of_reference
    from synth.sim.metrics import nonlinear_step_metrics

    if short_of_reference(v.result, sim.step_time, (start, end)):  # settled on a saturation, not at the reference
        return SimulatedStep("short_of_reference", nan, nan, nan, v.summary(), evidence)
    m = nonlinear_step_metrics(v.result, sim.step_time, settle_band=settle_band,
                               min_amplitude=sim.limit_cycle.min_amplitude, step_size=end - start)
    settling = nan if m.settling_time is None else float(m.settling_time)
    return SimulatedStep("settled", float(m.overshoot), settling, float(m.rise_time), v.summary(), evidence)


def bind_simulation(entries: Any, simulation: Any) -> Any:
    """The spec's requirement entries with its ``simulation:`` block copied into each entry whose type wants
    it (``wants_simulation(entry)``) and gives none of its own; other entries unchanged.

    Examples
    --------
    >>> entries = [{"type": "step_response", "max_overshoot": 20, "under": "simulation"},
    ...            {"type": "step_response", "max_overshoot": 20}]
    >>> [("simulation" in e) for e in bind_simulation(entries, {"dt": 0.001})]
    [True, False]
    """
    from synth.requirements.base import REQUIREMENT_TYPES, tagged_type

    if not isinstance(entries, list) or simulation is None:
        return entries
    out = []
    for e in entries:
        cls = tagged_type(REQUIREMENT_TYPES, e)
        wants = getattr(cls, "wants_simulation", None)
        if wants is not None and e.get("simulation") is None and wants(e):
            e = {**e, "simulation": simulation}
        out.append(e)
    return out


def confirming_runs(sim: SimulationSpec | None, loop: Loop, actuator: list[Any], delays: list[float],
                    frequency: float | None = None) -> list[tuple[float, SimulatedStep]]:
    """Simulated steps of ``loop`` with only the ``actuator`` blocks in the loop, one per extra in-loop delay
    in ``delays`` (duplicates dropped): what a describing-function verdict on those blocks predicts.

    The sample time, operating point, step and horizon rules are the spec's ``simulation:`` block's when
    given (its sensor chain is left out: the describing function does not model it); without one, a step
    from 0 to 1 with ``dt`` the power of ten at most ``0.3/frequency``, at least 20 samples per period of
    ``frequency`` (the fastest frequency of interest, e.g. the gain crossover or the predicted cycle's).
    The sampled controller's zero-order hold delays by about half its period ``h`` (``dt``, or
    ``1/controller_rate``): a run for the delay ``tau`` adds ``max(tau - h/2, 0)``, so that it simulates
    the loop the describing function analysed (at ``tau = 0`` the run is ``h/2`` late; the evidence says
    how much was compensated).

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s*(s+1)*(s+2))"), Controller("P", {"kp": 5.0}))
    >>> sat = [{"type": "saturation", "min": -1, "max": 1}]
    >>> [(tau, r.verdict) for tau, r in confirming_runs(None, loop, sat, [0.0, 0.3, 0.3], 1.4)]
    [(0.0, 'settled'), (0.3, 'limit_cycle')]
    """
    if sim is None:
        top = frequency if frequency is not None and np.isfinite(frequency) and frequency > 0 else 1.0
        dt = float(10.0 ** np.floor(np.log10(0.3 / top)))  # at least 20 samples per period at `frequency`
        sim = SimulationSpec.model_validate({"dt": min(dt, 0.01), "step": [0.0, 1.0]})
    hold = 1.0 / sim.controller_rate if sim.controller_rate else sim.dt
    cnum, cden = loop.controller.tf()
    loop_key = (sim.model_dump_json(), loop.plant.num.tobytes(), loop.plant.den.tobytes(), loop.plant.delay,
                cnum.tobytes(), cden.tobytes(),
                repr([b.model_dump() if hasattr(b, "model_dump") else b for b in actuator]))
    out = []
    for tau in sorted({float(d) for d in delays}):
        key = (*loop_key, tau)
        if key not in _RUNS:  # the same loop is confirmed by the design's check and its certificate
            # the sampled controller's zero-order hold lags by half a period: the run adds that much less delay
            run = simulated_step(sim, loop, extra_delay=max(tau - hold / 2, 0.0), actuator=actuator, sensor=False)
            run.evidence["zero_order_hold_compensation"] = min(hold / 2, tau)
            if len(_RUNS) >= 256:
                _RUNS.clear()
            _RUNS[key] = run
        out.append((tau, copy.deepcopy(_RUNS[key])))
    return out


def confirm_prediction(req: Any, predicted: RequirementResult, loop: Loop) -> RequirementResult:
    """A describing-function verdict of ``req`` (a :class:`~synth.requirements.no_limit_cycle.NoLimitCycle`)
    with the confirming simulations added: at both ends of its delay range and at the delay where the
    prediction is tightest (:func:`confirming_runs`).

    The runs are compared with what the describing function says of the loop at its own gain (a cycle when
    the gain factor is below 1; ``min_gain_margin_db`` asks for more, which a simulation cannot test).
    ``details["confirmation"]`` says how they compare: ``confirmed`` (every run settled where no cycle is
    predicted, or a run found the predicted cycle), ``disagrees`` (a run found a limit cycle or diverged
    where none is predicted: then NOT met, whatever the prediction; or a cycle is predicted and every run
    settled: the prediction stands, as a step that settles does not rule out a cycle of larger amplitude),
    or ``unconfirmed`` (a run was undetermined within its horizon cap: the prediction stands). Every run's
    verdict and evidence is in ``details["simulations"]``.
    """
    d = predicted.details
    tau = d.get("delay_at_binding")
    delays = [req.delay[0], req.delay[1]] + ([tau] if tau is not None else [])
    freq = predicted.binding_frequency or loop.crossover()
    runs = confirming_runs(req.simulation, loop, list(req.actuator), delays, freq)
    cycles = [(t, r) for t, r in runs if r.verdict in ("limit_cycle", "diverging")]
    unknown = [(t, r) for t, r in runs if r.verdict == "undetermined"]

    def at(t: float) -> str:
        return f"{t * 1e3:.4g} ms"

    said = "; ".join(f"{at(t)}: {r.summary}" for t, r in runs)
    value, slack, message = predicted.value, predicted.slack, predicted.message
    predicts = bool(d.get("gain_factor", np.inf) < 1.0)  # a cycle predicted at the loop's own gain
    if cycles and not predicts:
        how = "disagrees"
        t, r = cycles[0]
        message += (f"; DISAGREEMENT: the simulation with {at(t)} added finds "
                    f"{'a limit cycle' if r.verdict == 'limit_cycle' else 'a diverging run'} where none is "
                    "predicted: NOT met")
        value, slack = float("nan"), min(slack, -1e-3)
    elif predicts and not cycles and not unknown:
        how = "disagrees"
        message += ("; DISAGREEMENT: a cycle is predicted and every confirming step settled (the step may not "
                    "reach the cycle's amplitude); the prediction stands")
    elif unknown:
        how = "unconfirmed"
        message += f"; not confirmed: the simulation with {at(unknown[0][0])} added was undetermined"
    else:
        how = "confirmed"
        message += "; confirmed by simulation: " + ", ".join(
            f"{r.verdict.replace('_', ' ')} with {at(t)} added" for t, r in runs)
    details = {**d, "confirmation": how, "describing_function_margin_db": predicted.value,
               "simulations": [{"delay": t, **r.to_dict()} for t, r in runs], "simulation_text": said}
    return req.result(value=value, bound=predicted.bound, unit=predicted.unit, slack=slack,
                      margin=value - predicted.bound, binding_frequency=predicted.binding_frequency,
                      message=message, **details)
