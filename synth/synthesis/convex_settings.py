"""Settings of the convex-concave procedure and the design grid they give."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from synth.controllers import Controller
from synth.freqgrid import characteristic_range, log_grid
from synth.plant import Plant
from synth.requirements.base import Requirement
from synth.synthesis.delay_grid import delay_points
from synth.unity_gain import unity_gain_frequency

__all__ = ["RESONANCE_REFINED", "ConvexSettings", "design_grid", "resonance_points"]

RESONANCE_REFINED = 0.05
"""Damping below which a refinement of the convex stage's grid also resolves a root of the controller or of the
closed loop (:func:`~synth.synthesis.convex_settings.resonance_points`): its peak is then narrower than the
40-per-decade grid's spacing (2 zeta < 0.13 in log frequency). At 0.3, as the NLP polish uses, servo_pid's two
designs took 12 % more CPU for the same answers."""


@dataclass
class ConvexSettings:
    """Settings of the convex-concave procedure.

    Attributes
    ----------
    per_decade : int
        Design-grid density (points per decade) when ``n_points`` is not given.
    n_points : int or None
        Exact number of design-grid frequencies (log-spaced), overriding ``per_decade``.
    max_iterations : int
        Convex solves per phase.
    tolerance : float
        Relative objective change that ends a phase.
    stability_level : float
        Every iterate keeps ``|1 + L| >= stability_level`` on the grid (|S| <= 26 dB
        for 0.05), which keeps the closed loop stable along each step.
    bisection_steps : int
        Most levels the objective's bisection tries per run.
    bisection_tolerance : float
        The bisection stops when its bracket on the objective's logarithm is narrower than this (1e-3:
        0.1 % of the objective; the NLP polish that follows refines the answer to its own tolerance).
    restart_limit : float
        A restart of phase 1 (another stabilizing start after one that ended infeasible) stops once its elastic
        totals shrink geometrically towards at least this share of the lowest total an earlier start reached
        (:func:`synth.synthesis.phase_one_stop.heading_above`): it is converging to the same infeasible point or
        a worse one. Each start of an infeasible PID filter value took 30-40 solves to creep to the first start's
        total (k1 of session 62: 222-276 solves per value, 51-64 with the stop); 0 lets every start converge.
    """

    per_decade: int = 40
    n_points: int | None = None
    max_iterations: int = 60
    tolerance: float = 1e-6
    stability_level: float = 0.05
    bisection_steps: int = 18
    bisection_tolerance: float = 1e-3
    restart_limit: float = 0.9


def design_grid(plants: list[Plant], requirements: list[Requirement], settings: ConvexSettings,
                gain_bound: Callable[[np.ndarray], np.ndarray] | None = None) -> np.ndarray:
    """Log grid covering every plant's dynamics and every requirement's band, with the evenly spaced points of
    :func:`synth.synthesis.delay_grid.delay_points` where the longest delay needs them (``gain_bound``: an
    upper bound on the controller's gain, :func:`~synth.synthesis.delay_grid.controller_gain_bound`).

    Examples
    --------
    >>> from synth.requirements import PeakSensitivity
    >>> req = [PeakSensitivity(type="peak_sensitivity", max_db=6)]
    >>> plant = Plant.from_string("1/(s+1)", delay=4.0)
    >>> plain = design_grid([plant], req, ConvexSettings())
    >>> with_delay = design_grid([plant], req, ConvexSettings(), lambda w: 5.0 + 0 * w)
    >>> with_delay.size - plain.size > 0, bool(np.all(np.isin(plain, with_delay)))
    (True, True)
    """
    lo, hi = np.inf, 0.0
    for p in plants:
        a, b = characteristic_range(p.num, p.den, delay=p.delay)
        unity = unity_gain_frequency(p.num, p.den)  # a plant without corners (k / s): where a loop crosses over
        if unity is not None:  # (1 / delay alone put 4.59 e^(-0.00023 s) / s's grid at 43-430,000 rad/s)
            a, b = min(a, unity / 100.0), max(b, unity * 100.0)
        lo, hi = min(lo, a), max(hi, b)
    for r in requirements:
        band = getattr(r, "band", None)
        if band is not None:  # a band from 0 reaches two decades below its top (it had no point in it at all
            lo = min(lo, band[0] / 10 if band[0] > 0 else band[1] / 100)  # when the plant's range lay above it)
            hi = max(hi, band[1] * 10)
        for key, bound in r.bounds.items():  # frequency bounds (a bandwidth's min and max)
            v = getattr(r, key, None) if bound.unit == "rad/s" else None
            if v:
                lo, hi = min(lo, v / 100), max(hi, v * 100)
    grid = np.geomspace(lo, hi, settings.n_points) if settings.n_points else log_grid(lo, hi, settings.per_decade)
    return np.union1d(grid, delay_points(plants, grid, gain_bound))


def resonance_points(plants: list[Plant], c: Controller, grid: np.ndarray, damping: float = 0.3,
                     half_width: int = 6, moving_only: bool = False) -> np.ndarray:
    """Frequencies that resolve every lightly damped root of the loop at ``c`` (plant and controller poles and
    zeros, closed-loop poles with the delay left out; with ``moving_only`` those that move with the design: the
    controller's and the closed loop's): ``|r| exp(k zeta / 2)`` for ``|k| <= half_width``. A peak of ``|S|`` or
    ``|T|`` is about ``2 zeta`` wide in relative frequency, narrower than the design grid's spacing for ``zeta``
    under about 0.03, and it moves with the design between grid points. The NLP polish adds them to every
    round's grid. The convex stage adds the moving ones to each refinement's grid (a fixed plant resonance it
    resolves by refining at the violations it causes): a rational controller whose poles at 0.53 rad/s (damping
    0.04) put the gain crossover, at a phase margin of -95 deg, between two grid points passed every grid
    constraint, and each refinement added the crossover while the next design moved the resonance on (seed 12
    #284 of the design benchmark, tests/test_design_resonance_grid.py).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> w = resonance_points([Plant.from_string("1/(s^2+0.02*s+1)")], Controller("P", {"kp": 0.0}),
    ...                      np.geomspace(0.01, 100, 41))
    >>> w.size, round(float(w[6]), 6)  # 13 points around the pole pair at 1 rad/s
    (13, 1.0)
    """
    cn, cd = c.tf()
    polys = [cn, cd] if moving_only else []  # the controller's own roots: the same for every plant
    for p in plants:
        num, den = np.polymul(cn, p.num), np.polymul(cd, p.den)
        polys += [np.polyadd(den, num)] if moving_only else [num, den, np.polyadd(den, num)]
    roots = []
    for poly in polys:
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
