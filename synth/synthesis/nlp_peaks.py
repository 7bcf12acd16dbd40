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
from synth.freqgrid import log_grid
from synth.loop import Loop
from synth.plant import Plant
from synth.synthesis.nlp_problem import NLPBuilder, loop_response

__all__ = ["PEAK_TIGHT", "peak_frequencies", "resonance_points", "track_peaks"]

NEAR_DB = 3.0
"""Local maxima of the start design within this many dB of the bound (or above it) are tracked."""

BOX = 1.5
"""A tracked peak frequency stays within ``[w0 / BOX, BOX w0]`` in one round."""

PER_DECADE = 160

PEAK_TIGHT = 1.0 - 2e-6
"""Tightening of a tracked peak's squared bound: the peak is exact there, so it needs far less than the grid's
:data:`~synth.synthesis.nlp_problem.TIGHT` (which covers what lies between the points), only IPOPT's tolerance."""


def peak_frequencies(plant: Plant, start: Controller, curve: str, bound: float,
                     band: tuple[float, float]) -> np.ndarray:
    """Local maxima of ``|curve|`` (``"S"``, ``"T"`` or ``"KS"``) of the loop at ``start`` inside ``band`` that
    come within :data:`NEAR_DB` of the linear ``bound``, refined to a relative 1e-6.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> G = Plant.from_string("1/(s^2+0.04*s+1)")
    >>> [round(float(w), 3) for w in peak_frequencies(G, Controller("P", {"kp": 0.5}), "T", 1.0, (0.01, 100))]
    [1.224]
    """
    loop = Loop(plant, start)
    f = getattr(loop, curve)
    lo, hi = max(band[0], 1e-9), band[1]
    if not hi > lo:
        return np.array([])
    w = log_grid(lo, hi, PER_DECADE)
    with np.errstate(all="ignore"):
        v = np.abs(f(w))
    inner = np.flatnonzero((v[1:-1] > v[:-2]) & (v[1:-1] >= v[2:])) + 1
    inner = inner[np.isfinite(v[inner]) & (v[inner] >= bound * 10 ** (-NEAR_DB / 20))]
    a, b = np.log(w[inner - 1]), np.log(w[inner + 1])
    for _ in range(40):  # golden section on log w, every peak at once
        c, d = b - 0.618 * (b - a), a + 0.618 * (b - a)
        with np.errstate(all="ignore"):
            left = np.abs(f(np.exp(c))) >= np.abs(f(np.exp(d)))
        a, b = np.where(left, a, c), np.where(left, d, b)
    return np.exp(0.5 * (a + b))


def track_peaks(b: NLPBuilder, plant: Plant, designs: list[Controller], curve: str, bound: float,
                band: tuple[float, float], tight: float) -> None:
    """Add a tracked peak of ``|curve|`` with ``|curve(j w_k)|^2 <= tight bound^2`` for each local maximum near
    the bound (:func:`peak_frequencies`) of each of ``designs`` (the round's start, and the last answer whose
    peaks rose between the grid points); peaks within 1 % of one already tracked are tracked once."""
    found: list[float] = []
    for design in designs:
        for w in peak_frequencies(plant, design, curve, bound, band):
            if all(abs(np.log(w / f)) > 0.01 for f in found):
                found.append(float(w))
    for w0 in found:
        v = b.var("w_peak", float(w0), max(w0 / BOX, band[0]), min(w0 * BOX, band[1]))
        C, L = loop_response(b.ctrl, plant, v)
        top = {"S": None, "T": L, "KS": C}[curve]
        log_f = -ca.log((1.0 + L).abs2()) if top is None else ca.log(top.abs2()) - ca.log((1.0 + L).abs2())
        b.eq(ca.jacobian(log_f, v) * v)  # a stationary point of the curve: d log|F|^2 / d log w = 0
        if top is None:
            b.geq(bound**2 * tight * (1.0 + L).abs2() - 1.0)
        else:
            b.geq((1.0 + L).abs2() - top.abs2() / (bound**2 * tight))


def resonance_points(plants: list[Plant], c: Controller, grid: np.ndarray, damping: float = 0.3,
                      half_width: int = 6) -> np.ndarray:
    """Frequencies that resolve every lightly damped root of the loop at ``c`` (plant and controller poles and
    zeros, closed-loop poles with the delay left out): ``|r| exp(k zeta / 2)`` for ``|k| <= half_width``. A
    peak of ``|S|`` or ``|T|`` is about ``2 zeta`` wide in relative frequency, narrower than the design grid's
    spacing for ``zeta`` under about 0.03, and it moves with the design between grid points.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> w = resonance_points([Plant.from_string("1/(s^2+0.02*s+1)")], Controller("P", {"kp": 0.0}),
    ...                      np.geomspace(0.01, 100, 41))
    >>> w.size, round(float(w[6]), 6)  # 13 points around the pole pair at 1 rad/s
    (13, 1.0)
    """
    cn, cd = c.tf()
    roots = []
    for p in plants:
        num, den = np.polymul(cn, p.num), np.polymul(cd, p.den)
        closed = np.polyadd(den, num)
        for poly in (num, den, closed):
            poly = np.trim_zeros(np.asarray(poly, float), "f")
            if poly.size > 1 and np.all(np.isfinite(poly)):
                roots.extend(np.roots(poly))
    out = []
    for r in roots:
        size = abs(r)
        if size <= 0 or not grid[0] <= size <= grid[-1] or abs(r.imag) < 1e-9 * size:
            continue
        zeta = abs(r.real) / size
        if zeta < damping:
            out.append(size * np.exp(np.arange(-half_width, half_width + 1) * max(zeta, 1e-3) / 2))
    return np.unique(np.concatenate(out)) if out else np.array([])
