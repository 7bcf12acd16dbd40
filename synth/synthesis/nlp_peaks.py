"""Peaks of ``|S|``, ``|T|`` and ``|KS|`` tracked exactly in the NLP, between its grid points.

A peak bound imposed on a frequency grid is met on the grid; a sharp peak (a lightly damped closed-loop
pole, controller zeros near the axis) is narrower than the grid's spacing and the optimizer moves it between
the points, where the certificate finds it violated. Each local maximum of the start design's curve near the
bound becomes a variable frequency ``w_k`` held at a stationary point of the curve,
``d log|F(j w)|^2 / d log w = 0`` (as a gain crossover is held by ``|L| = 1``), in a box around its start,
and the bound is imposed at ``w_k``: the peak itself is bounded wherever the design moves it.
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

__all__ = ["NEAR_DB", "PEAK_TIGHT", "peak_brackets", "peak_frequencies", "track_peaks"]

NEAR_DB = 3.0
"""Local maxima of the start design within this many dB of the bound (or above it) are tracked."""

BOX = 1.5
"""A tracked peak frequency stays between the start curve's neighbouring minima and within ``[w0 / BOX, BOX w0]``
in one round."""

PER_DECADE = 160

PEAK_TIGHT = 1.0 - 2e-6
"""Tightening of a tracked peak's squared bound: the peak is exact there, so it needs far less than the grid's
:data:`~synth.synthesis.nlp_problem.TIGHT` (which covers what lies between the points), only IPOPT's tolerance."""


def peak_frequencies(plant: Plant, start: Controller, curve: str, bound: float,
                     band: tuple[float, float]) -> np.ndarray:
    """Local maxima of ``|curve|`` (``"S"``, ``"T"`` or ``"KS"``) of the loop at ``start`` inside ``band`` that
    come within :data:`NEAR_DB` of the linear ``bound``, refined by golden section (:func:`peak_brackets`).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> G = Plant.from_string("1/(s^2+0.04*s+1)")
    >>> [round(float(w), 3) for w in peak_frequencies(G, Controller("P", {"kp": 0.5}), "T", 1.0, (0.01, 100))]
    [1.224]
    """
    return np.array([w for w, _, _ in peak_brackets(plant, start, curve, bound, band)], float)


def peak_brackets(plant: Plant, start: Controller, curve: str, bound: float,
                  band: tuple[float, float]) -> list[tuple[float, float, float]]:
    """``(w, lo, hi)`` for each local maximum ``w`` of ``|curve|`` of the loop at ``start`` inside ``band`` within
    :data:`NEAR_DB` of ``bound``: ``[lo, hi]`` reaches the neighbouring minima (at most a factor :data:`BOX`
    away), where the stationary point held in the NLP is that maximum and no other. The curve is searched on a
    log grid with the plant delay's ripple resolved (steps of at most ``pi/4 / delay``): on the log grid alone a
    long delay's peaks alias, and a box of a factor 1.5 holds dozens of them.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> G = Plant.from_string("1/(s+1)", delay=5.0)  # peaks where w 5 + atan(w) = pi, 3 pi, ...
    >>> [(round(w, 2), round(lo, 2), round(hi, 2)) for w, lo, hi in
    ...  peak_brackets(G, Controller("P", {"kp": 0.5}), "S", 1.5, (0.01, 10.0))][:3]
    [(0.52, 0.35, 0.79), (1.67, 1.11, 2.27), (2.88, 2.27, 3.5)]
    """
    loop = Loop(plant, start)
    f = getattr(loop, curve)
    lo, hi = max(band[0], 1e-9), band[1]
    if not hi > lo:
        return []
    w = resolving_grid(lo, hi, PER_DECADE, delay_resolving_step(plant.delay))
    level = bound * 10 ** (-NEAR_DB / 20)
    found = bracketed_maxima(lambda x: np.abs(f(x)), w, lambda v: v >= level, (lo, hi), BOX)
    return [(float(a), float(b), float(c)) for a, b, c in zip(*found)]


def track_peaks(b: NLPBuilder, plant: Plant, designs: list[Controller], curve: str, bound: float,
                band: tuple[float, float], tight: float) -> None:
    """Add a tracked peak of ``|curve|`` with ``|curve(j w_k)|^2 <= tight bound^2`` for each local maximum near
    the bound (:func:`peak_frequencies`) of each of ``designs`` (the round's start, and the last answer whose
    peaks rose between the grid points); peaks within 1 % of one already tracked are tracked once."""
    found: list[tuple[float, float, float]] = []
    for design in designs:
        for w, lo, hi in peak_brackets(plant, design, curve, bound, band):
            if all(abs(np.log(w / f[0])) > 0.01 for f in found):
                found.append((w, lo, hi))
    for w0, lo, hi in found:
        v = b.var("w_peak", w0, lo, hi)
        C, L = loop_response(b.ctrl, plant, v)
        top = {"S": None, "T": L, "KS": C}[curve]
        log_f = -ca.log((1.0 + L).abs2()) if top is None else ca.log(top.abs2()) - ca.log((1.0 + L).abs2())
        b.eq(ca.jacobian(log_f, v) * v)  # a stationary point of the curve: d log|F|^2 / d log w = 0
        if top is None:
            b.geq(bound**2 * tight * (1.0 + L).abs2() - 1.0)
        else:
            b.geq((1.0 + L).abs2() - top.abs2() / (bound**2 * tight))

