"""Seeded random nonlinear loops for the simulation-verdict benchmark (issue 15, item 3).

A case is a plain dict (the format ``benchmarks/sim_reference.py`` reads): a plant of order 1-4
(integrators, lightly damped pairs with damping down to 0.02, real poles), scaled so that
``|G(j wc)| = 1`` at a random crossover ``wc``; an in-loop delay (sometimes); P, PI or PID gains
around that crossover (some loops are linearly unstable on purpose); one or two of saturation,
rate limit, dead zone, backlash, relay and quantization, sized against the controller's answer to
the step; a step amplitude, sometimes a step time. ``synth_loop`` turns a case into synth's
:class:`~synth.sim.loops.NonlinearLoop` (the only function here that imports synth).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["KINDS", "random_case", "random_cases", "synth_loop"]

KINDS = ("saturation", "rate_limit", "dead_zone", "backlash", "relay", "quantizer")


def _log(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def random_case(rng: np.random.Generator, dt: float | None = None) -> dict[str, Any]:
    """One random loop (see the module docstring); ``dt`` forces the sample time."""
    order = int(rng.integers(1, 5))
    poles: list[complex] = []
    if order >= 2 and rng.random() < 0.4:
        zeta, wn = _log(rng, 0.02, 0.3), _log(rng, 0.5, 4.0)
        wd = wn * np.sqrt(1 - zeta**2)
        poles += [complex(-zeta * wn, wd), complex(-zeta * wn, -wd)]
    if len(poles) < order and rng.random() < 0.35:
        poles.append(0.0)
    while len(poles) < order:
        poles.append(-_log(rng, 0.3, 5.0))
    den = np.real(np.poly(poles))
    wc = _log(rng, 0.3, 2.0)
    gain = float(abs(np.polyval(den, 1j * wc)))
    delay = float(rng.uniform(0.0, 0.3 / wc)) if rng.random() < 0.4 else 0.0
    kind = str(rng.choice(["P", "PI", "PID"], p=[0.4, 0.35, 0.25]))
    kp = _log(rng, 0.3, 3.0)
    ctrl: dict[str, Any] = {"type": kind, "kp": kp}
    if kind in ("PI", "PID"):
        ctrl["ki"] = kp * wc * _log(rng, 0.05, 0.5)
    if kind == "PID":
        ctrl["kd"] = kp / wc * rng.uniform(0.1, 0.6)
        ctrl["tf"] = ctrl["kd"] / kp / rng.uniform(5.0, 15.0)
    fastest = max([abs(p) for p in poles] + [wc] + ([1 / ctrl["tf"]] if kind == "PID" else []))
    if dt is None:
        dt = max([d for d in (0.001, 0.002, 0.005, 0.01) if d <= 0.05 / fastest] or [0.001])
    if kind == "PID":
        ctrl["tf"] = max(ctrl["tf"], 2 * dt)
    amp = _log(rng, 0.1, 10.0)
    u_scale = kp * amp
    actuator: list[Any] = []
    sensor: list[Any] = []
    for k in rng.choice(KINDS, size=int(rng.integers(1, 3)), replace=False):
        if k == "saturation":
            lim = u_scale * _log(rng, 0.1, 1.0)
            actuator.append(["saturation", {"min": -lim, "max": lim}])
        elif k == "rate_limit":
            actuator.append(["rate_limit", {"rate": u_scale * wc * _log(rng, 0.2, 3.0)}])
        elif k == "dead_zone":
            actuator.append(["dead_zone", {"width": u_scale * _log(rng, 0.01, 0.2)}])
        elif k == "backlash":
            actuator.append(["backlash", {"width": u_scale * _log(rng, 0.02, 0.3)}])
        elif k == "relay":
            level = u_scale * _log(rng, 0.2, 1.0)
            actuator.append(["relay", {"level": level, "eps": 1e-6 * u_scale}])
        elif rng.random() < 0.6:
            sensor.append(["quantizer", {"step": amp * _log(rng, 0.005, 0.05)}])
        else:
            actuator.append(["quantizer", {"step": u_scale * _log(rng, 0.005, 0.05)}])
    rng.shuffle(actuator)
    return {"plant": {"num": [gain], "den": den.tolist()}, "poles": [str(p) for p in poles], "wc": wc,
            "delay": delay, "controller": ctrl, "actuator": actuator, "sensor": sensor, "dt": float(dt),
            "step": amp, "t_step": float(rng.choice([0.0, 0.0, 1.0]))}


def random_cases(n: int, seed: int = 15, dt: float | None = None) -> list[dict[str, Any]]:
    """``n`` random loops from one seed.

    Examples
    --------
    >>> len(random_cases(3)), sorted(random_cases(3)[0])[:3]
    (3, ['actuator', 'controller', 'delay'])
    """
    rng = np.random.default_rng(seed)
    return [random_case(rng, dt) for _ in range(n)]


def _block(kind: str, p: dict[str, float]) -> Any:
    from synth.sim.blocks import Backlash, DeadZone, Quantizer, RateLimit, Saturation, Static

    if kind == "saturation":
        return Saturation(p["min"], p["max"])
    if kind == "rate_limit":
        return RateLimit(p["rate"])
    if kind == "dead_zone":
        return DeadZone(p["width"])
    if kind == "backlash":
        return Backlash(p["width"])
    if kind == "quantizer":
        return Quantizer(p["step"])
    if kind == "relay":
        e, m = p["eps"], p["level"]
        return Static(((-2 * e, -m), (-e, -m), (e, m), (2 * e, m)))
    raise ValueError(kind)


def synth_loop(case: dict[str, Any]) -> Any:
    """synth's :class:`~synth.sim.loops.NonlinearLoop` for ``case``."""
    from synth.controllers import Controller
    from synth.plant import Plant
    from synth.sim.loops import NonlinearLoop

    c = case["controller"]
    params = {k: float(c[k]) for k in ("kp", "ki", "kd", "tf") if k in c}
    return NonlinearLoop(Plant(np.asarray(case["plant"]["num"]), np.asarray(case["plant"]["den"])),
                         Controller(c["type"], params),
                         actuator=tuple(_block(k, p) for k, p in case["actuator"]),
                         sensor=tuple(_block(k, p) for k, p in case["sensor"]),
                         dt=case["dt"], loop_delay=case["delay"])
