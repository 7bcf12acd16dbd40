"""Compare a design with published numbers (a paper's closed loop, its slew-rate crossing, ...).

Nothing here bends a number towards the published one: each comparison puts
the computed value beside the published value and, where they disagree,
computes what the published value would imply.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from synth.controllers import Controller
from synth.loop import BANDWIDTH_LEVEL, Loop
from synth.plant import Plant
from synth.requirements import SlewRate
from synth.requirements.base import fmt
from synth.settled_step import settled_step
from synth.spec import Spec
from synth.synthesis.gainset import critical_gains
from synth.timeresp import step_metrics

__all__ = ["compare", "loop_summary", "published_summary", "slew_reconciliation"]


def _poles_text(poles: np.ndarray) -> list[str]:
    out = []
    for p in poles:
        if abs(p.imag) <= 1e-9 * max(1.0, abs(p)):
            out.append(f"{p.real:.4g}")
        elif p.imag > 0:
            out.append(f"{p.real:.4g} +- {p.imag:.4g}j")
    return out


def loop_summary(loop: Loop) -> dict[str, Any]:
    """Closed-loop numbers of one loop: T, poles, bandwidth, crossover, margins, linear step metrics.

    Examples
    --------
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
    >>> s = loop_summary(Loop(G, Controller("P", {"kp": 3.0})))
    >>> s["closed_loop_tf"], s["closed_loop_poles"]
    ('69*(s+0.43)/((s+78.7)*(s+0.4429))', ['-0.4429', '-78.7'])
    """
    poles = loop.closed_loop_poles()
    t, y, dt = settled_step(loop)
    metrics = step_metrics(t, y, y_final=loop.dc_gain())
    margins = loop.margins()
    return {
        "controller": str(loop.controller),
        "closed_loop_tf": loop.closed_loop_text(),
        "closed_loop_poles": _poles_text(poles[:8]),
        "closed_loop_poles_values": [[float(p.real), float(p.imag)] for p in poles[:8]],
        "bandwidth": loop.bandwidth(),
        "crossover": loop.crossover(),
        "T0": loop.T0(),
        "margins": margins.to_dict(),
        "step": metrics.to_dict() | {"horizon": float(t[-1]), "dt": dt},
        "stability": loop.stability().to_dict(),
    }


def published_summary(label: str, tf: str) -> dict[str, Any]:
    """Poles, zeros, DC gain, -3 dB bandwidth and rise time of a published transfer function.

    Examples
    --------
    >>> s = published_summary("eq. 14", "68.85*(s+0.42)/((s+78.54)*(s+0.43))")
    >>> s["poles"], round(s["dc_gain"], 4)
    (['-0.43', '-78.54'], 0.8563)
    """
    T = Plant.from_string(tf)
    from synth.freqgrid import characteristic_range, crossings, log_grid

    dc = T.dc_gain()
    lo, hi = characteristic_range(T.num, T.den)
    cross = crossings(lambda w: np.abs(T.freqresp(w)), abs(dc) * BANDWIDTH_LEVEL, log_grid(lo, hi * 10))
    from synth.exact_steps import exact_step

    fastest = max(abs(np.roots(T.den).real).max(), 1e-6)
    t = np.linspace(0, 12.0 / fastest, 4001)
    y = exact_step(T.num, T.den, t)
    metrics = step_metrics(t, y, y_final=dc)
    poles = np.roots(T.den)
    poles = poles[np.argsort(-poles.real)]
    zeros = T.zeros()
    return {
        "label": label,
        "tf": tf,
        "poles": _poles_text(poles),
        "zeros": _poles_text(zeros),
        "dc_gain": dc,
        "bandwidth": float(cross[0]) if cross.size else None,
        "rise_time": metrics.rise_time,
    }


def slew_reconciliation(spec: Spec, controller: Controller, published: float | None) -> list[dict[str, Any]]:
    """For each slew-rate requirement: where ``controller`` reaches the bound, and what the
    published crossing frequency would imply for ``B/De``."""
    out = []
    plant = spec.nominal_plant()
    loop = Loop(plant, controller)
    for r in spec.requirements:
        if not isinstance(r, SlewRate):
            continue
        w_cross = r.crossing_frequency(loop)
        entry: dict[str, Any] = {
            "rate_limit": r.rate_limit,
            "max_error": r.max_error,
            "bound_over_error": r.rate_limit / r.max_error,
            "controller": str(controller),
            "crossing_frequency": w_cross,
            "published_crossing": published,
        }
        u = plant.input.unit or "input units"
        y = plant.output.unit or "output units"
        if published is not None:
            implied = float(np.abs(controller.freqresp([published])[0]) * published)
            entry["implied_bound_over_error"] = implied
            entry["ratio"] = (r.rate_limit / r.max_error) / implied
            entry["message"] = (
                f"With B = {fmt(r.rate_limit)} {u}/s and De = {fmt(r.max_error)} {y} "
                f"(B/De = {fmt(r.rate_limit / r.max_error)} 1/s), {controller} reaches the bound at "
                f"{fmt(w_cross)} rad/s. The source reports {fmt(published)} rad/s; that needs "
                f"B/De = {fmt(implied)} 1/s, {fmt(entry['ratio'])} times smaller. The units as "
                "published do not reconcile; synth uses the spec's B and De as written."
            )
        else:
            entry["message"] = f"{controller} reaches the slew-rate bound at {fmt(w_cross)} rad/s."
        out.append(entry)
    return out


def compare(spec: Spec, controller: Controller | None) -> dict[str, Any]:
    """Everything the report sets beside the design: the reference controller's loop, published
    closed loops, the slew-rate reconciliation, and critical gains against in-loop delay."""
    plant = spec.nominal_plant()
    ref = spec.reference
    out: dict[str, Any] = {"plant": plant.to_dict() | {"dc_gain": plant.dc_gain()}}
    loops = {}
    if controller is not None:
        loops["design"] = loop_summary(Loop(plant, controller))
    ref_controller = Controller.from_string(ref.controller) if ref and ref.controller else None
    if ref_controller is not None:
        loops["reference"] = loop_summary(Loop(plant, ref_controller))
    out["loops"] = loops
    if ref is not None:
        out["reference"] = {
            "source": ref.source,
            "controller": ref.controller,
            "published_closed_loops": [published_summary(p.label, p.tf) for p in ref.closed_loop],
            "published_rise_time": ref.rise_time,
            "published_bandwidth": ref.bandwidth,
            "notes": list(ref.notes),
        }
        probe = ref_controller or controller
        if probe is not None:
            out["slew_rate"] = slew_reconciliation(spec, probe, ref.slew_rate_crossing)
    if spec.controller.type == "P" and spec.analysis.loop_delays:
        out["delay_table"] = critical_gains(plant, list(spec.analysis.loop_delays))
        if controller is not None and controller.type == "P":
            out["delay_warning"] = delay_warning(controller, out["delay_table"], loops["design"]["margins"])
    return out


def delay_warning(controller: Controller, table: list[dict[str, Any]], margins: dict[str, Any]) -> str | None:
    """What the report's top verdict adds when the design is unstable at a delay of the spec's delay table
    (``analysis.loop_delays``), else None: its requirements then hold only without that delay in the loop. The X-4
    design P(kp=20) met every requirement with no word that 5 ms of delay makes it unstable (a black-box review;
    the identified plant has 20 ms).

    Examples
    --------
    >>> delay_warning(Controller("P", {"kp": 20.0}), [{"delay": 0.0, "critical_gain": float("inf")},
    ...               {"delay": 0.005, "critical_gain": 13.93}], {"delay_margin": 0.00346}).split(" (")[0]
    'P(kp=20) is unstable with 5 ms of delay in the loop'
    """
    kp = float(controller.parameters["kp"])
    first = next((r for r in table if not float(r.get("lowest_gain") or 0.0) < kp < float(r["critical_gain"])), None)
    if first is None:
        return None
    if kp <= float(first.get("lowest_gain") or 0.0) < float(first["critical_gain"]):
        return (f"{controller} is unstable with {fmt(1000 * float(first['delay']), 3)} ms of delay in the loop (the "
                f"gain must lie between {fmt(float(first['lowest_gain']), 4)} and {fmt(float(first['critical_gain']), 4)} "
                "there; delay table below): the requirements hold only without that delay")
    margin = margins.get("delay_margin")
    exact = f"; its exact delay margin is {fmt(1000 * margin, 3)} ms" if isinstance(margin, float) else ""
    return (f"{controller} is unstable with {fmt(1000 * float(first['delay']), 3)} ms of delay in the loop (critical "
            f"gain {fmt(float(first['critical_gain']), 4)} there; delay table below){exact}: the requirements hold "
            "only without that delay")
