"""Close approaches of the Nyquist curve to -1, held on the start's side in the NLP.

The polish keeps ``|1 + L| >= level`` on its grid, but IPOPT's iterates may violate a constraint on their way:
a step can carry the curve across -1 (a pair of closed-loop poles across the imaginary axis) and the answer
end on the far side, where it meets every constraint and the loop is unstable. Around each close approach of
the start's curve (a local minimum of ``|1 + L(j w)|`` below :data:`NEAR`), a variable frequency ``w_k`` is
held at the stationary point of ``|1 + L|^2`` between the neighbouring maxima, where ``1 + L`` is normal to
the curve's tangent ``dL/dw``; the side of -1 is the sign of ``Im(conj(dL/dw) (1 + L))`` there, and the answer
must keep the start's sign. Crossing -1 at that approach is then infeasible for the answer, not only on the
grid's points.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from synth.controllers import Controller
from synth.freqgrid import bracketed_maxima, resolving_grid
from synth.loop import Loop
from synth.plant import Plant
from synth.synthesis.delay_grid import delay_resolving_step
from synth.synthesis.nlp_problem import NLPBuilder, loop_response

__all__ = ["NEAR", "close_approaches", "hold_sides"]

NEAR = 0.5
"""Local minima of ``|1 + L|`` of the start closer than this to -1 are held on their side."""

PER_DECADE = 400
"""Density of the log grid on which the close approaches are found (then refined by golden section); a plant
delay's ripple is resolved on it as well (steps of at most ``pi/4 / delay``)."""

BOX = 1.5
"""A held approach's frequency stays between the neighbouring maxima of ``|1 + L|`` and within this factor."""


def close_approaches(plant: Plant, start: Controller, band: tuple[float, float],
                     near: float = NEAR) -> list[tuple[float, float, float, float]]:
    """``(w, lo, hi, side)`` for each local minimum ``w`` of ``|1 + L(j w)|`` below ``near`` inside ``band``:
    its box ``[lo, hi]`` (the neighbouring maxima, at most a factor :data:`BOX` away) and the sign of
    ``Im(conj(dL/dw) (1 + L))`` at ``w`` (the side of the curve -1 lies on; it changes when the pair of
    closed-loop poles of that approach crosses the imaginary axis).

    Examples
    --------
    >>> G = Plant.from_string("1/(s*(s+1))", delay=1.0)  # stable for kp below 1.13
    >>> [(round(w, 3), side) for w, _, _, side in close_approaches(G, Controller("P", {"kp": 0.8}), (0.01, 10))]
    [(0.759, -1.0)]
    >>> [side for _, _, _, side in close_approaches(G, Controller("P", {"kp": 1.5}), (0.01, 10))]
    [1.0]
    """
    loop = Loop(plant, start)
    w = resolving_grid(max(band[0], 1e-9), band[1], PER_DECADE, delay_resolving_step(plant.delay))
    minima = bracketed_maxima(lambda x: -np.abs(1.0 + loop.L(x)), w, lambda v: -v < near, band, BOX)
    out = []
    for w0, lo, hi in zip(*(m.tolist() for m in minima)):
        h = 1e-6 * w0
        with np.errstate(all="ignore"):
            up, down, at = loop.L(np.array([w0 + h, w0 - h, w0]))
        side = float(np.sign((np.conj((up - down) / (2 * h)) * (1.0 + at)).imag))
        if side != 0 and np.isfinite(side):
            out.append((w0, lo, hi, side))
    return out


def hold_sides(b: NLPBuilder, plant: Plant, start: Controller, band: tuple[float, float], level: float) -> int:
    """Hold each close approach of the start's curve (:func:`close_approaches`) on its side of -1, at least
    ``level`` from it: a variable frequency at the stationary point of ``|1 + L|^2``, the side's sign kept
    there. Returns the number held.

    Examples
    --------
    >>> from synth.synthesis.nlp_problem import SymbolicController
    >>> G, c = Plant.from_string("1/(s*(s+1))", delay=1.0), Controller("P", {"kp": 0.8})
    >>> b = NLPBuilder(SymbolicController("P", c, {"kp": (0.0, 5.0)}))
    >>> hold_sides(b, G, c, (0.01, 10.0), 0.05), len(b.x), len(b.g)
    (1, 2, 3)
    """
    held = close_approaches(plant, start, band)
    for w0, lo, hi, side in held:
        v = b.var("w_near", w0, lo, hi)
        _, L = loop_response(b.ctrl, plant, v)
        one_plus = 1.0 + L
        d_re, d_im = ca.jacobian(L.re, v), ca.jacobian(L.im, v)
        b.eq((one_plus.re * d_re + one_plus.im * d_im) * v)  # d|1 + L|^2 / d log w = 0
        b.geq(side * (d_re * one_plus.im - d_im * one_plus.re) * v)  # the start's side of -1
        b.geq(one_plus.abs2() - level**2)
    return len(held)
