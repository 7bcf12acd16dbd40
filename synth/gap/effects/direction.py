"""Direction-dependent dynamics: a drive that answers a rising command otherwise than a falling one.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``direction``          input     each command change waits ``delay_up`` or ``delay_down``,    ``gain_down,
                                 then a lag with ``tau_up`` or ``tau_down``; while the         offset_down,
                                 command last fell the drive's gain is ``1 + gain_down``       tau_up, tau_down,
                                 and ``offset_down`` is added (a friction of that direction)  delay_up, delay_down``
=====================  ========  ===========================================================  ==============

Real drives show it: a BLDC motor whose up-steps wait about 105 ms and then rise in 15 ms while its
down-steps start after 30 ms; a load cell with 38-45 ms time constants up and 23-26 ms down; a drive
whose torque-to-speed gain differs between the directions. The gain of the rising direction is the
nominal gain (re-fitted), so only the ratio of the falling direction's to it is a parameter; likewise
the rising direction's input offset is the output constant's, and ``offset_down`` is the falling
direction's difference to it (a drive whose friction differs by direction).
The drive is continuous in time (latencies at any point within a sample, the lag between samples);
the held-input plant gets its mean over each sample interval (:func:`directional_block`), so the
model follows the continuous drive closely even where a time constant or a latency is shorter than a
sample, and its output is continuous in every parameter: the screen searches the four time parameters
together from its best grid point (:meth:`DirectionEffect.refine_screen`, a pattern search).
Not a default candidate (:attr:`DirectionEffect.excluded_because`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from synth.gap.effects.base import Effect, Params, slowest_pole
from synth.gap.effects.search import pattern_search
from synth.plant import Plant

__all__ = ["DirectionEffect", "directional_block"]


def _lag_piece(x: float, target: float, h: float, tau_up: float, tau_down: float) -> tuple[float, float]:
    """The lag's state after ``h`` seconds towards a held ``target`` from ``x``, and its integral over them.

    The time constant is ``tau_up`` while the state lies below the target, ``tau_down`` above it; an
    exponential approach never crosses its target, so it holds for the whole piece.

    Examples
    --------
    >>> x, area = _lag_piece(0.0, 1.0, 1.0, 1.0, 0.0)
    >>> round(x, 4), round(area, 4)  # 1 - exp(-1), and 1 - (1 - exp(-1))
    (0.6321, 0.3679)
    """
    if h <= 0.0:
        return x, 0.0
    tau = tau_up if target > x else tau_down
    if tau <= 0.0:
        return target, target * h
    e = math.exp(-h / tau)
    return target + (x - target) * e, target * h + (x - target) * tau * (1.0 - e)


def directional_block(u: np.ndarray, dt: float, params: Params) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The command after its direction-dependent latency and lag, averaged over each sample interval.

    Each change of the held command arrives ``delay_up`` (rising) or ``delay_down`` (falling) later, at
    any time within a sample (no rounding to whole samples); the drive follows the arrived command
    through a continuous first-order lag whose time constant is ``tau_up`` while it lies below its
    target and ``tau_down`` while above. The linear plant is simulated with the input held over each
    sample (:func:`synth.ident.simulate.simulate_plant`), so each sample carries the drive's *mean* over
    its interval: the integral the plant sees is exact, whereas the drive's value at the start of the
    interval would lag it by up to a whole sample (a time constant shorter than a sample, common for a
    fast direction, would then act as a one-sample delay).

    Parameters
    ----------
    u : numpy.ndarray
        Command samples (each held over its interval).
    dt : float
        Sample time [s].
    params : dict
        ``tau_up``, ``tau_down``, ``delay_up``, ``delay_down`` [s] (missing: 0).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Interval means of the drive's output ``x``, of ``x d`` and of ``d``, where ``d`` is 1 while the last
        change that arrived was a fall and 0 otherwise.

    Examples
    --------
    >>> u = np.array([0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    >>> v, vd, down = directional_block(u, 0.1, {"delay_up": 0.15})
    >>> v.tolist(), down.tolist()  # the rise arrives half-way through the third interval
    ([0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    >>> v, _, _ = directional_block(u, 0.1, {"tau_up": 0.1})
    >>> round(float(v[1]), 4), round(float(np.exp(-1)), 4)  # its mean over the first interval: 1 - (1 - 1/e) tau/dt
    (0.3679, 0.3679)
    """
    u = np.asarray(u, float)
    n = u.size
    du = np.diff(u, prepend=u[0])
    idx = np.flatnonzero(du)
    delay_up, delay_down = max(0.0, params.get("delay_up", 0.0)), max(0.0, params.get("delay_down", 0.0))
    when = idx * dt + np.where(du[idx] > 0, delay_up, delay_down)  # arrival, from the first sample
    order = np.argsort(when, kind="stable")
    when_l, step_l = when[order].tolist(), du[idx][order].tolist()
    tau_up, tau_down = max(0.0, params.get("tau_up", 0.0)), max(0.0, params.get("tau_down", 0.0))
    # a whole interval without an arrival: x -> T + (x - T) E, mean T + (x - T) F (per direction)
    coef = [(math.exp(-dt / tau), tau / dt * (1.0 - math.exp(-dt / tau))) if tau > 0.0 else (0.0, 0.0)
            for tau in (tau_up, tau_down)]
    v, vd, dn = np.empty(n), np.empty(n), np.empty(n)
    x = target = float(u[0])
    down = 0.0
    j, m = 0, len(when_l)
    for i in range(n):
        a, b = i * dt, (i + 1) * dt
        if j >= m or when_l[j] >= b:  # no arrival in this interval
            e, f = coef[0] if target > x else coef[1]
            mean = target + (x - target) * f
            x = target + (x - target) * e
            v[i], vd[i], dn[i] = mean, mean * down, down
            continue
        area = area_down = time_down = 0.0
        while j < m and when_l[j] < b:
            s = max(when_l[j], a)
            x, piece = _lag_piece(x, target, s - a, tau_up, tau_down)
            area, area_down, time_down = area + piece, area_down + piece * down, time_down + down * (s - a)
            a = s
            target += step_l[j]
            down = 1.0 if step_l[j] < 0 else 0.0
            j += 1
        x, piece = _lag_piece(x, target, b - a, tau_up, tau_down)
        area, area_down, time_down = area + piece, area_down + piece * down, time_down + down * (b - a)
        v[i], vd[i], dn[i] = area / dt, area_down / dt, time_down / dt
    return v, vd, dn


@dataclass(frozen=True)
class DirectionEffect(Effect):
    """Separate latency, time constant and gain for rising and falling commands (:func:`directional_block`).

    The plant is driven by ``v (1 + gain_down d) + offset_down d``, ``v`` the block's output and ``d`` 1
    where the command last fell: ``gain_down`` (a basis parameter) is the falling direction's gain
    relative to the rising one, minus 1, ``offset_down`` (basis) its input offset; the time constants
    and latencies are searched on a grid of pairs (one
    direction at a time, then both).

    Examples
    --------
    >>> t = np.arange(0, 4, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("1/(0.05*s+1)")
    >>> y = DirectionEffect().apply(G, t, u, {"tau_up": 0.2})
    >>> round(float(y[120]), 2), round(float(y[220]), 2)  # slow up, fast down
    (0.6, 0.02)
    """

    name: ClassVar[str] = "direction"
    parameter_names: ClassVar[tuple[str, ...]] = ("gain_down", "offset_down", "tau_up", "tau_down", "delay_up",
                                                  "delay_down")
    grid_names: ClassVar[tuple[str, ...]] = ("tau_up", "tau_down", "delay_up", "delay_down")
    basis_names: ClassVar[tuple[str, ...]] = ("gain_down", "offset_down")
    excluded_because: ClassVar[str] = (
        "five parameters searched on a grid of pairs, and a command that moves both ways on its own time scale "
        "(steps, not noise) to tell them apart: name it with candidates for a step record of a drive")

    def off(self) -> Params:
        return {"gain_down": 0.0, "offset_down": 0.0, "tau_up": 0.0, "tau_down": 0.0, "delay_up": 0.0,
                "delay_down": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        span = float(t[-1] - t[0])
        span_u = float(np.ptp(u))
        return {"gain_down": (-0.9, 9.0), "offset_down": (-span_u, span_u), "tau_up": (0.0, span),
                "tau_down": (0.0, span), "delay_up": (0.0, span), "delay_down": (0.0, span)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        dt = float(t[1] - t[0])
        slow = 1.0 / slowest_pole(plant)
        taus = [0.0, *np.geomspace(max(2 * dt, 0.02 * slow), max(3 * dt, 0.5 * slow), 4).tolist()]
        delays = [0.0, *np.geomspace(max(dt, 0.01 * slow), max(2 * dt, 0.3 * slow), 4).tolist()]
        off = self.off()
        grid = [{**off, "tau_up": a, "tau_down": b} for a in taus for b in taus if a != b]
        grid += [{**off, "delay_up": a, "delay_down": b} for a in delays for b in delays if a != b]
        return [dict(g) for g in grid]

    def refine_screen(self, cost: Callable[[Params], float], best: Params, t: np.ndarray, u: np.ndarray,
                      plant: Plant) -> Params:
        """Pattern search in all four time parameters (:func:`synth.gap.effects.search.pattern_search`).

        The grid holds either the time constants or the latencies nonzero, never both, and the
        golden-section search moves ``tau_up`` alone; a drive with a slow rise, a fast fall and a
        latency of its own lies between them. The interval means of :func:`directional_block` make the
        cost continuous in every parameter, latencies included, so a local search can walk there. It
        starts from the best point and from the best grid point of the other kind (time constants or
        latencies; the grid's cost is cached), a latency and a time constant being two routes to the
        same slowness.
        """
        dt = float(t[1] - t[0])
        upper = {k: b for k, (_, b) in self.bounds(t, u, plant).items() if k in self.grid_names}
        starts = [best]
        kinds = (("tau_up", "tau_down"), ("delay_up", "delay_down"))
        kind = next((ks for ks in kinds if any(best.get(k, 0.0) > 0 for k in ks)), kinds[0])
        others = [g for g in self.grid(t, u, plant) if not any(g.get(k, 0.0) > 0 for k in kind)]
        if others:
            starts.append(min(others, key=cost))
        found = [pattern_search(cost, {**self.off(), **g}, self.grid_names, 0.1 * dt, upper) for g in starts]
        return min([best, *found], key=cost)

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        return directional_block(u, dt, params)[0]

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        _, v_down, down = directional_block(u, dt, params)
        return [v_down, down]

    def required_samples(self, nominal_coefficients: int) -> int:
        """Rises and falls each need their own samples: twice the default."""
        return 2 * super().required_samples(nominal_coefficients)
