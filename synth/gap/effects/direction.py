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
Not a default candidate (:attr:`DirectionEffect.excluded_because`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from synth.gap.effects.base import Effect, Params, slowest_pole
from synth.plant import Plant

__all__ = ["DirectionEffect", "directional_block"]


def directional_block(u: np.ndarray, dt: float, params: Params) -> tuple[np.ndarray, np.ndarray]:
    """The command after its direction-dependent latency and lag, and where it last fell.

    Each change of the command takes effect ``delay_up`` (rising) or ``delay_down`` (falling) later
    (whole samples); the result follows it through a first-order lag whose time constant is
    ``tau_up`` while it lies below its target and ``tau_down`` while above (exact for a held target).

    Parameters
    ----------
    u : numpy.ndarray
        Command samples.
    dt : float
        Sample time [s].
    params : dict
        ``tau_up``, ``tau_down``, ``delay_up``, ``delay_down`` [s] (missing: 0).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The block's output and a 0/1 signal, 1 where the last change of the command was a fall.

    Examples
    --------
    >>> u = np.array([0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    >>> v, down = directional_block(u, 0.1, {"delay_up": 0.2})
    >>> v.tolist(), down.tolist()
    ([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    """
    u = np.asarray(u, float)
    n = u.size
    du = np.diff(u, prepend=u[0])
    k_up = max(0, round(params.get("delay_up", 0.0) / dt))
    k_dn = max(0, round(params.get("delay_down", 0.0) / dt))
    steps = np.zeros(n)
    for k, mask in ((k_up, du > 0), (k_dn, du < 0)):
        idx = np.nonzero(mask)[0] + k
        keep = idx < n
        np.add.at(steps, idx[keep], du[mask][keep])
    target = u[0] + np.cumsum(steps)
    change = np.sign(steps)
    last = np.maximum.accumulate(np.where(change != 0, np.arange(n), -1))
    down = np.where(last >= 0, change[np.maximum(last, 0)] < 0, False).astype(float)
    tau_up, tau_dn = params.get("tau_up", 0.0), params.get("tau_down", 0.0)
    if tau_up <= 0 and tau_dn <= 0:
        return target, down
    a_up = 1.0 - np.exp(-dt / tau_up) if tau_up > 0 else 1.0
    a_dn = 1.0 - np.exp(-dt / tau_dn) if tau_dn > 0 else 1.0
    v = np.empty(n)
    x = float(target[0])
    tl = target.tolist()
    for i in range(n):
        v[i] = x
        d = tl[i] - x
        x += (a_up if d > 0 else a_dn) * d
    return v, down


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

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        return directional_block(u, dt, params)[0]

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        v, down = directional_block(u, dt, params)
        return [v * down, down]

    def required_samples(self, nominal_coefficients: int) -> int:
        """Rises and falls each need their own samples: twice the default."""
        return 2 * super().required_samples(nominal_coefficients)
