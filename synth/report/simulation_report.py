"""The nonlinear section of the design report: step check, oscillation onset, published statements.

:func:`simulation_report` computes everything from the spec's ``simulation:``
block: the nonlinear and the linear (every nonlinear block off) step
response of the design and of the reference controller, their metrics, the
onset gain of oscillation against in-loop delay and rate limit (P control,
when ``simulation.onset`` is given), and, when ``simulation.published`` is
given, where the source's statements sit on those results. The design report
(:mod:`synth.report.design_report`) stores ``to_dict()`` in ``result.json``
and draws the figures of :mod:`synth.sim.figures`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.loop import Loop
from synth.report.onset_delay import delay_for_gain, exact_delay_for_gain
from synth.requirements.base import fmt
from synth.sim.blocks import RateLimit
from synth.sim.loops import OperatingPoint
from synth.sim.metrics import nonlinear_step_metrics
from synth.sim.onset import OnsetResult, oscillation_onset
from synth.sim.results import SimResult
from synth.sim.simulator import simulate_batch, simulate_open_loop, simulate_step
from synth.sim.spec import SimulationSpec
from synth.sim.verdict import step_verdict
from synth.spec import Spec
from synth.timeresp import step_metrics, step_response

__all__ = ["SimulationReport", "simulation_figures", "simulation_report"]


@dataclass
class SimulationReport:
    """Numbers and time series of the nonlinear section.

    Attributes
    ----------
    data : dict
        JSON-ready numbers (stored in ``result.json`` under ``simulation``).
    runs : dict
        ``{label: {"nonlinear": SimResult, "linear": SimResult}}`` for the figures.
    onset : OnsetResult or None
    rise_vs_rate : dict or None
        ``{"rates": [...], "rise_times": [...]}`` at the published gain.
    """

    data: dict[str, Any]
    runs: dict[str, dict[str, SimResult]] = field(default_factory=dict)
    onset: OnsetResult | None = None
    rise_vs_rate: dict[str, Any] | None = None


_CACHE: dict[tuple[str, str, str], SimulationReport] = {}


def simulation_report(spec: Spec, design: Controller | None, reference: Controller | None,
                      progress: Callable[[int, int], None] | None = None,
                      studies: SimulationReport | None = None) -> SimulationReport:
    """The nonlinear section for ``spec`` (which must have a ``simulation:`` block).

    Results are cached per spec and controllers, so the JSON and the figures of one report share
    one computation. With a reference controller, everything but the design's own step runs (the
    reference's runs, the onset study and the published statements) depends on the spec and the reference
    alone: ``studies`` is that part, ``simulation_report(spec, None, reference)``, when the caller computed
    it already (the command line does, on the other core, while the design runs).

    Examples
    --------
    >>> from synth.spec import load_spec
    >>> spec = load_spec("specs/x4_rotor.yaml")
    >>> quick = spec.model_copy(update={"simulation": spec.simulation.model_copy(update={"onset": None})})
    >>> rep = simulation_report(quick, Controller("P", {"kp": 3.0}), None)
    >>> round(rep.data["runs"]["design"]["nonlinear"]["rise_time"], 3)  # linear model: 0.025 s
    0.051
    """
    sim = spec.simulation
    if sim is None:
        raise ValueError(f"spec {spec.name} has no simulation block")
    key = (spec.model_dump_json(), str(design), str(reference))
    if key in _CACHE:
        return _CACHE[key]
    plant = spec.nominal_plant()
    y_unit = plant.output.unit or "output units"
    if design is None and studies is not None:
        return studies
    if design is not None and reference is not None:
        part = studies if studies is not None else simulation_report(spec, None, reference, progress)
        runs, data = _step_runs(spec, "design", design)
        report = SimulationReport({**part.data, "runs": {"design": data, **part.data["runs"]}},
                                  {"design": runs, **part.runs}, part.onset, part.rise_vs_rate)
        report.data["verdict"], report.data["design_warning"] = _verdict(report.data, y_unit), _warning(report.data, y_unit)
        _CACHE.clear()
        _CACHE[key] = report
        return report
    step = sim.default_step()
    u_unit = plant.input.unit or "input units"
    report = SimulationReport({
        "step": list(step), "step_time": sim.step_time, "horizon": sim.horizon, "seed": sim.seed,
        "units": {"input": u_unit, "output": y_unit},
        "assumptions": _assumptions(sim, plant, u_unit, y_unit),
        "runs": {},
    })
    for label, ctrl in (("design", design), ("reference", reference)):
        if ctrl is None:
            continue
        report.runs[label], report.data["runs"][label] = _step_runs(spec, label, ctrl)
    report.data["verdict"], report.data["design_warning"] = _verdict(report.data, y_unit), _warning(report.data, y_unit)
    probe = reference or design
    if sim.onset is not None and probe is not None and probe.type == "P":
        loop = sim.build_loop(plant, probe)
        report.onset = oscillation_onset(loop, step, sim.onset.delays, sim.onset.rate_limits, sim.onset.gains,
                                         "kp", sim.onset.horizon, sim.limit_cycle.min_amplitude,
                                         progress=progress)
        report.data["onset"] = report.onset.to_dict()
        report.data["onset"]["linear_continuous"] = _continuous_critical(plant, sim.loop_delay, sim.onset.delays)
        report.data["onset"]["describing_function_check"] = _df_check(loop, report.onset, step, sim)
    if sim.published is not None:
        report.data["published"] = _published(spec, sim, report, probe)
    _CACHE.clear()
    _CACHE[key] = report
    return report


_TOWARDS_FINAL = ("rise_time", "overshoot", "settling_time", "final_value")
"""Step metrics measured against the final value: left out (None) of a run whose step does not settle."""


def _step_runs(spec: Spec, label: str, ctrl: Controller) -> tuple[dict[str, SimResult], dict[str, Any]]:
    """The nonlinear and the linear step run of one controller, and their numbers for ``result.json``."""
    sim = spec.simulation
    assert sim is not None
    step = sim.default_step()
    disturbances = sim.build_disturbances()
    loop = sim.build_loop(spec.nominal_plant(), ctrl, label)
    runs = {
        "nonlinear": simulate_step(loop, *step, sim.horizon, sim.step_time, disturbances, sim.seed),
        "linear": simulate_step(loop.linear(), *step, sim.horizon, sim.step_time, disturbances, sim.seed),
    }
    metrics = {k: nonlinear_step_metrics(r, sim.step_time, min_amplitude=sim.limit_cycle.min_amplitude,
                                         window=sim.limit_cycle.window, step_size=step[1] - step[0]).to_dict()
               for k, r in runs.items()}
    # what the step ends in is not read off the shown horizon: the run is extended until it decides
    verdict = step_verdict(loop, *step, t_step=sim.step_time, horizon=sim.horizon, disturbances=disturbances,
                           seed=sim.seed, min_amplitude=sim.limit_cycle.min_amplitude)
    if verdict.verdict != "settled":  # no final value: nothing to rise, overshoot or settle towards
        metrics["nonlinear"] = {**metrics["nonlinear"], **dict.fromkeys(_TOWARDS_FINAL)}
    else:  # measured towards the final value the verdict's run settles at (a shown run may end before that)
        settled = verdict.metrics.to_dict()
        metrics["nonlinear"] = {**metrics["nonlinear"], **{k: settled[k] for k in _TOWARDS_FINAL}}
    return runs, {"controller": str(ctrl), "loop": loop.to_dict(), **metrics,
                  "step_verdict": {**verdict.to_dict(), "summary": verdict.summary(loop.plant.output.unit or "")}}


def _assumptions(sim: SimulationSpec, plant: Any, u: str, y: str) -> list[str]:
    rate = sim.controller_rate or 1.0 / sim.dt
    out = [f"Simulation step {fmt(sim.dt)} s; controller at {fmt(rate)} Hz ({sim.controller_discretization} "
           "discretization); plant and delays discretized exactly (zero-order hold).",
           f"Operating point {fmt(sim.operating_point.input)} {u} at {fmt(sim.operating_point.output)} {y}: the "
           "linear plant model acts on deviations from it, the blocks on absolute values.",
           f"In-loop delay {fmt(sim.loop_delay * 1000)} ms besides the plant's {fmt(plant.delay * 1000)} ms."]
    for name, chain in (("Actuator", sim.actuator_blocks()), ("Sensor", sim.sensor_blocks())):
        if chain:
            out.append(f"{name} chain: " + ", ".join(_block_text(b, u if name == 'Actuator' else y) for b in chain)
                       + ".")
    if sim.limit_cycle.min_amplitude:
        amp = fmt(sim.limit_cycle.min_amplitude)
        out.append(f"A sustained oscillation counts as a limit cycle from {amp} {y} "
                   "half peak-to-peak (smaller ripples are quantization chatter).")
    return out


def _block_text(b: Any, unit: str) -> str:
    d = b.to_dict()
    kind = d.pop("type")
    if kind == "rate_limit":
        return f"rate limit {fmt(d['rate'])} {unit}/s"
    if kind == "saturation":
        return f"saturation {fmt(d['min'])}-{fmt(d['max'])} {unit}"
    if kind == "sample_hold":
        return f"sample-and-hold at {fmt(d['rate'])} Hz"
    if kind == "quantizer":
        return f"quantizer {fmt(d['step'])} {unit}"
    return kind + " " + ", ".join(f"{k} {v}" for k, v in d.items() if v is not None)


def _ending(v: dict[str, Any], y: str) -> str:
    """What a step verdict (``step_verdict``'s dict) says the step ends in, as a verb phrase."""
    if v["verdict"] == "limit_cycle":
        lc = v["limit_cycle"]
        return f"ends in a sustained oscillation of {fmt(lc['amplitude'])} {y} every {fmt(lc['period'])} s"
    if v["verdict"] == "settled":
        return "settles without a limit cycle"
    return "diverges" if v["verdict"] == "diverging" else f"is undetermined within {fmt(v['evidence']['horizon'])} s"


def _warning(data: dict[str, Any], y: str) -> str | None:
    """For the report's top verdict: what the design's simulated step ends in, unless it settles."""
    run = data["runs"].get("design")
    if run is None or run["step_verdict"]["verdict"] == "settled":
        return None
    step = " -> ".join(f"{fmt(x)}" for x in data["step"])
    return (f"Nonlinear step check: the design's simulated step {step} {y} {_ending(run['step_verdict'], y)} (the "
            "spec's simulation block: actuator and sensor limits; see below).")


def _verdict(data: dict[str, Any], y: str) -> str:
    """The section's verdict: for each controller what its step ends in (:func:`synth.sim.verdict.step_verdict`,
    on as long a run as it takes, which may exceed the horizon shown) and its rise time on the run shown."""
    parts = []
    shown = data["horizon"]
    for label, run in data["runs"].items():
        nl, lin, v = run["nonlinear"], run["linear"], run["step_verdict"]
        horizon = v["evidence"]["horizon"]
        beyond = f", beyond the {fmt(shown)} s shown" if horizon > shown * (1 + 1e-9) else ""
        if v["verdict"] == "undetermined":
            osc = f"{_ending(v, y)} ({v['evidence']['criterion']})"
        else:
            seen = "settled" if v["verdict"] == "settled" else "seen"
            osc = f"{_ending(v, y)} ({seen} on a run of {fmt(horizon)} s{beyond})"
        limited = f"rate-limited {fmt(nl['rate_limited_time'])} s, saturated {fmt(nl['saturated_time'])} s"
        if nl["rise_time"] is not None:
            rise = (f"nonlinear rise time {fmt(nl['rise_time'])} s against {fmt(lin['rise_time'])} s with every "
                    f"nonlinear block off ({limited})")
        else:
            rise = (f"no nonlinear rise time, having no final value to rise to ({fmt(lin['rise_time'])} s with every "
                    f"nonlinear block off; {limited} of the {fmt(shown)} s shown)")
        parts.append(f"The {label} {run['controller']} {osc}; {rise}.")
    return " ".join(parts)


def _continuous_critical(plant: Any, loop_delay: float, delays: list[float]) -> list[dict[str, Any]]:
    from synth.synthesis.gainset import critical_gains

    rows = critical_gains(plant, [loop_delay + d for d in delays])
    return [{"delay": d, "critical_gain": r["critical_gain"], "frequency": r["frequency"]}
            for d, r in zip(delays, rows)]


def _df_check(loop: Any, onset: OnsetResult, step: tuple[float, float], sim: SimulationSpec,
              factor: float = 1.3) -> list[dict[str, Any]]:
    """Harmonic balance against simulation at ``factor`` times each onset gain (as specified)."""
    from synth.sim.describing import predict_loop_cycles
    from synth.sim.limitcycle import detect_oscillation

    cases = []
    for row in onset.rows:
        if row.variant != "as specified" or row.onset_gain is None:
            continue
        k = min(factor * row.onset_gain, onset.gains[1])
        cases.append((row.delay, k, loop.replace(loop_delay=loop.loop_delay + row.delay).with_gain("kp", k)))
    if not cases:
        return []
    batch = simulate_batch([c[2] for c in cases], _step_ref(step, 0.0), onset.horizon)
    g0 = loop.plant.dc_gain()
    out = []
    for i, (delay, k, lp) in enumerate(cases):
        half = onset.horizon / 2
        res = batch[i]
        sim_y = detect_oscillation(res.t, res.measured, window=half, min_amplitude=sim.limit_cycle.min_amplitude)
        sim_u = detect_oscillation(res.t, res.command, window=half)
        y_ss = lp.operating_point.output + k * g0 * (step[1] - lp.operating_point.output) / (1 + k * g0)
        bias = lp.operating_point.input + k * (step[1] - y_ss)
        preds = predict_loop_cycles(lp, bias, (10.0, 0.999 * np.pi / lp.dt), points=80)
        stable = [p for p in preds if p.cycle.stable] or preds
        # several stable cycles: the largest is the one a large step settles on
        pred = max(stable, key=lambda p: p.cycle.amplitude) if stable else None
        out.append({
            "delay": delay, "gain": k,
            "simulated": {"present": sim_y.present, "output_amplitude": sim_y.fundamental_amplitude,
                          "period": sim_y.period, "command_amplitude": sim_u.fundamental_amplitude},
            "predicted": None if pred is None else {"output_amplitude": pred.output_amplitude,
                                                    "period": pred.cycle.period,
                                                    "command_amplitude": pred.cycle.amplitude,
                                                    "stable": pred.cycle.stable, "bias": bias},
        })
    return out


def _rise(result: SimResult, t_step: float) -> float:
    return nonlinear_step_metrics(result, t_step).rise_time


def _published(spec: Spec, sim: SimulationSpec, report: SimulationReport,
               probe: Controller | None) -> dict[str, Any]:
    pub = sim.published
    assert pub is not None
    plant = spec.nominal_plant()
    u = plant.input.unit or "input units"
    out: dict[str, Any] = {"notes": list(pub.notes), "statements": []}
    step = sim.default_step()
    gain = pub.gain if pub.gain is not None else (probe.parameters.get("kp") if probe and probe.type == "P"
                                                  else None)
    if gain is not None and pub.closed_loop_rise_time is not None:
        loop = sim.build_loop(plant, Controller("P", {"kp": gain}))
        variants = {"as specified": loop, "no rate limit": loop.without("rate_limit"),
                    "every nonlinear block off (sampled)": loop.linear()}
        for rate in sim.onset.rate_limits if sim.onset else []:
            variants[f"rate limit {fmt(rate)} {u}/s"] = loop.replace(actuator=tuple(
                RateLimit(rate) if isinstance(b, RateLimit) else b for b in loop.actuator))
        batch = simulate_batch(list(variants.values()), _step_ref(step, sim.step_time), sim.horizon)
        rises = {name: _rise(batch[i], sim.step_time) for i, name in enumerate(variants)}
        linear_loop = Loop(plant, Controller("P", {"kp": gain}))
        t, y, _ = step_response(linear_loop)
        rises["continuous linear model"] = step_metrics(t, y, y_final=linear_loop.dc_gain()).rise_time
        out["rise_time"] = {"gain": gain, "published": pub.closed_loop_rise_time, "simulated": rises}
        rates = np.geomspace(500.0, 2e5, 31)
        sweep = [loop.replace(actuator=tuple(RateLimit(r) if isinstance(b, RateLimit) else b
                                             for b in loop.actuator)) for r in rates]
        if any(isinstance(b, RateLimit) for b in loop.actuator):
            batch = simulate_batch(sweep, _step_ref(step, sim.step_time), sim.horizon)
            rr = np.array([_rise(batch[i], sim.step_time) for i in range(len(sweep))])
            report.rise_vs_rate = {"rates": rates.tolist(), "rise_times": rr.tolist(), "gain": gain,
                                   "published": pub.closed_loop_rise_time,
                                   "specified": next(b.rate for b in loop.actuator if isinstance(b, RateLimit))}
            needed = _crossing(np.log(rates), rr, pub.closed_loop_rise_time)
            out["rate_for_published_rise"] = None if needed is None else float(np.exp(needed))
            out["rise_vs_rate"] = report.rise_vs_rate
    if pub.open_loop_rise_time is not None:
        lo, hi = step
        g0 = plant.dc_gain()
        du = (hi - lo) / g0 if g0 else 1.0
        u0 = sim.operating_point.input
        slowest = max(1e-3, float(np.min(np.abs(np.roots(plant.den).real)))) if plant.den.size > 1 else 1.0
        n = round(min(30.0, max(2.0, 20.0 / slowest)) / sim.dt)
        u_rec = np.concatenate([[u0 - du / 2], np.full(n, u0 + du / 2)])
        op = OperatingPoint(sim.operating_point.input, sim.operating_point.output)
        ol = simulate_open_loop(plant, u_rec, sim.dt, sim.actuator_blocks(), operating_point=op)
        y0 = float(ol.output[0])
        to_dc = step_metrics(ol.t, ol.output, y0=y0, y_final=y0 + g0 * du)
        peak = float(ol.output[np.argmax(np.abs(ol.output - y0))])
        to_peak = step_metrics(ol.t, ol.output, y0=y0, y_final=peak)
        out["open_loop"] = {"published_rise_time": pub.open_loop_rise_time,
                            "model_rise_time_to_dc": to_dc.rise_time, "model_rise_time_to_peak": to_peak.rise_time,
                            "peak_over_dc": (peak - y0) / (g0 * du), "step_input": [u0 - du / 2, u0 + du / 2]}
    if pub.oscillation_onset_gain is not None and report.onset is not None:
        k = pub.oscillation_onset_gain
        needed = {}
        for variant in dict.fromkeys(r.variant for r in report.onset.rows):
            rows = [r for r in report.onset.rows if r.variant == variant]
            ds = np.array([r.delay for r in rows])
            ks = np.array([r.onset_gain if r.onset_gain is not None else np.inf for r in rows])
            needed[variant] = delay_for_gain(ds, ks, k)
        needed["continuous linear model"] = exact_delay_for_gain(plant, sim.loop_delay, k)
        out["onset"] = {"published_gain": k, "delay_for_published_onset": needed}
    out["statements"] = _statements(out, report, sim, u, plant.output.unit or "output units")
    return out


def _step_ref(step: tuple[float, float], t_step: float):
    from synth.sim.signals import step_reference

    return step_reference(step[0], step[1], t_step)


def _crossing(x: np.ndarray, y: np.ndarray, level: float) -> float | None:
    """First x where y crosses ``level`` (linear interpolation), scanning from large x to small."""
    for i in range(len(x) - 1, 0, -1):
        a, b = y[i - 1] - level, y[i] - level
        if np.isfinite(a) and np.isfinite(b) and a * b <= 0 and a != b:
            return float(x[i - 1] + (x[i] - x[i - 1]) * (-a) / (b - a))
    return None


def _statements(out: dict[str, Any], report: SimulationReport, sim: SimulationSpec, u: str, y: str) -> list[str]:
    lines = []
    rise = out.get("rise_time")
    if rise:
        s = rise["simulated"]
        spec_rise, nolim = s["as specified"], s["no rate limit"]
        lines.append(
            f"Rise time at K = {fmt(rise['gain'])}: the source measured {fmt(rise['published'])} s. The simulated "
            f"loop gives {fmt(spec_rise)} s as specified, {fmt(nolim)} s without the rate limit (saturation "
            f"only) and {fmt(s['every nonlinear block off (sampled)'])} s with every nonlinear block off "
            f"(continuous linear model: {fmt(s['continuous linear model'])} s). The gap between the linear "
            f"{fmt(s['continuous linear model'])} s and the measured {fmt(rise['published'])} s is "
            + ("accounted for by the actuator limits in this model" if abs(spec_rise - rise["published"])
               <= 0.2 * rise["published"] else "not accounted for by the actuator limits in this model")
            + (f"; the saturation does it: removing the rate limit changes the rise time by "
               f"{fmt(100 * abs(nolim - spec_rise) / spec_rise, 2)} %."
               if abs(nolim - spec_rise) < 0.05 * spec_rise else "."))
        need = out.get("rate_for_published_rise")
        sweep = report.rise_vs_rate
        if need is not None and sweep is not None:
            lines.append(f"With every other assumption kept, a rate limit of {fmt(need)} {u}/s gives exactly the "
                         f"published rise time (the spec uses {fmt(sweep['specified'])} {u}/s).")
        elif sweep is not None:
            rr = np.asarray(sweep["rise_times"], float)
            flat = np.asarray(sweep["rates"])[np.flatnonzero(rr <= 1.02 * np.nanmin(rr))[0]]
            lo_rate, hi_rate = fmt(sweep["rates"][0]), fmt(sweep["rates"][-1])
            lines.append(f"No rate limit between {lo_rate} and {hi_rate} {u}/s gives the published "
                         f"{fmt(rise['published'])} s exactly: above about {fmt(flat, 2)} {u}/s the rise time "
                         f"stays within 2 % of {fmt(float(np.nanmin(rr)))} s, set by the other limits of the "
                         "loop.")
    ol = out.get("open_loop")
    if ol:
        lines.append(
            f"Open-loop rise time: the source reports {fmt(ol['published_rise_time'])} s; the plant model gives "
            f"{fmt(ol['model_rise_time_to_peak'])} s to its peak and {fmt(ol['model_rise_time_to_dc'])} s to its "
            f"DC value (its response peaks at {fmt(ol['peak_over_dc'], 3)} times the DC value and then creeps "
            "back through the slow pole-zero pair), so the reading depends on the final value used.")
    onset = out.get("onset")
    if onset and report.onset is not None:
        k = onset["published_gain"]
        zero = [r for r in report.onset.rows if r.delay == min(rr.delay for rr in report.onset.rows)]
        z = next((r for r in zero if r.variant == "as specified"), None)
        if z is not None:
            lines.append(
                f"Limit cycles: the source reports them for K > {fmt(k)}. Without extra in-loop delay the "
                + (f"simulated loop first oscillates at K = {fmt(z.onset_gain)}" if z.onset_gain else
                   f"simulated loop does not oscillate anywhere up to K = {fmt(report.onset.gains[1])}")
                + " (sampling at the controller rate and the sensor's sample-and-hold add the only delay).")
        d = onset["delay_for_published_onset"]
        spec_d = d.get("as specified")
        if spec_d is not None:
            lines.append(f"The onset falls to K = {fmt(k)} with {fmt(spec_d * 1000)} ms of delay inside the loop "
                         f"(rate limit and saturation as specified); the continuous linear model needs "
                         f"{fmt((d.get('continuous linear model') or float('nan')) * 1000)} ms. The paper's "
                         "statement therefore needs an in-loop delay of about this size (the identified 20 ms "
                         "includes plant and processing and need not all be in the loop).")
        checks = [c for c in report.data["onset"].get("describing_function_check", [])
                  if c["predicted"] and c["simulated"]["present"] and c["simulated"]["output_amplitude"]]
        if checks:
            dp = max(abs(c["predicted"]["period"] / c["simulated"]["period"] - 1) for c in checks)
            da = max(abs(c["predicted"]["output_amplitude"] / c["simulated"]["output_amplitude"] - 1)
                     for c in checks)
            lines.append(
                f"Describing functions (harmonic balance on the sampled loop, the actuator chain's describing "
                f"function taken about its steady input) predict the cycle's period within {fmt(100 * dp, 2)} % "
                f"and its output amplitude within {fmt(100 * da, 2)} % of the simulation at 1.3 times each onset "
                "gain where the simulation oscillates (a single-sinusoid describing function ignores the shift of "
                "the cycle's mean that an asymmetric limit causes, and the sensor's quantization).")
        spread, split = [], []
        for dl in sorted({r.delay for r in report.onset.rows}):
            rows = [r for r in report.onset.rows if r.delay == dl]
            vals = [r.onset_gain for r in rows if r.onset_gain is not None]
            if len(vals) > 1:
                spread.append(max(vals) / min(vals) - 1)
            if vals and len(vals) < len(rows):  # some variants oscillate at this delay, others not up to the top gain
                split.append(dl)
        if spread:
            where = ("" if not split else
                     f" where every variant oscillates; at {', '.join(fmt(1000 * dl) for dl in split)} ms some "
                     f"oscillate and others do not up to K = {fmt(report.onset.gains[1])} (the table)")
            lines.append(
                f"The rate limit and the saturation move the onset gain by at most {fmt(100 * max(spread), 2)} % "
                f"against the linear sampled loop{where}: in this model the delay sets where oscillation starts; "
                "the limits set how large the cycle grows (compare the amplitudes in the table).")
    return lines


def simulation_figures(spec: Spec, design: Controller | None, reference: Controller | None, out: Any,
                       marks: dict[str, float]) -> dict[str, Any]:
    """Draw the nonlinear section's figures into the report folder ``out`` (an
    :class:`~synth.outputs.OutputDir`); returns ``{name: path}``."""
    from synth.sim import figures

    rep = simulation_report(spec, design, reference)
    figs: dict[str, Any] = {}
    if rep.runs:
        rises = [run[k]["rise_time"] for run in rep.data["runs"].values() for k in ("nonlinear", "linear")]
        rises = [r for r in rises if r is not None and np.isfinite(r)]
        t_end = rep.data["step_time"] + max(0.1, 5 * max(rises, default=0.0))
        if any(run["step_verdict"]["verdict"] != "settled" for run in rep.data["runs"].values()):
            t_end = np.inf  # a step that does not settle: the whole run shown
        figs["sim_step"] = figures.step_comparison(rep.runs, out.claim("nonlinear_step.png"), rep.data["units"],
                                                   min(t_end, rep.data["step_time"] + rep.data["horizon"]))
    if rep.onset is not None:
        pub = spec.simulation.published if spec.simulation else None
        figs["sim_onset"] = figures.onset_chart(rep.data["onset"], rep.data["onset"]["linear_continuous"], marks,
                                                out.claim("oscillation_onset.png"),
                                                pub.oscillation_onset_gain if pub else None)
    if rep.rise_vs_rate is not None:
        figs["sim_rise"] = figures.rise_vs_rate_chart(rep.rise_vs_rate, rep.data["units"]["input"],
                                                      out.claim("rise_time_vs_rate_limit.png"))
    return figs
