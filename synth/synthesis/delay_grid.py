"""Design-grid frequencies that resolve a long plant delay where the loop gain can matter.

A log grid of 40 points per decade steps by about 6 % in frequency. A delay ``tau`` turns the loop's phase
by ``w tau``, so above ``w = pi/4 / (0.06 tau)`` the phase turns by more than pi/4 between neighbouring grid
points; for a delay of several seconds that happens below 1 rad/s. There the grid sees an aliased
``L(jw)``: a closed-loop pole can cross the imaginary axis between grid points unseen, and a design stage
whose constraints live on the grid can walk out of the stabilizing set (seen in the design benchmark: a PID
on a plant with a 4.3 s delay, whose every NLP round ended at an unstable loop).

The points added are evenly spaced, ``pi/4 / tau`` apart, from where the log grid first under-resolves the delay
up to the log-grid point above the highest frequency at which the loop gain can still reach
:data:`LOOP_GAIN_FLOOR` for some controller in the bounds. Where ``|L| < 0.5`` the point ``L = -1`` is out of
reach whatever the phase: ``|1 + L| > 0.5``, so no closed-loop pole crosses the axis there, the stages' own
keeping of ``|1 + L| >= 0.05`` cannot bind, |S| stays below 6 dB and |T| below 0 dB. The points are an aid to
the design stages, not to correctness: every design is certified on a grid at least 20 times denser than the
design grid (steps of at most 0.3 %, which resolve the delay's phase to pi/4 up to ``w = 270/tau``), and a
requirement with a tighter bound (a peak |S| below 6 dB) is checked there. The bound on the controller's gain
comes from its parametrization (:func:`controller_gain_bound`); a rational controller has none (its
denominator's coefficients do not bound ``1/|D(jw)|``), so its grid is left as it is.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from synth.plant import Plant
from synth.synthesis.parametrization import LinearParametrization, Parametrization

__all__ = ["DELAY_STEP", "LOOP_GAIN_FLOOR", "MAX_DELAY_POINTS", "controller_gain_bound", "delay_points",
           "delay_resolving_step"]

DELAY_STEP = np.pi / 4
"""Largest turn of the longest delay's phase (rad) between neighbouring design frequencies."""

LOOP_GAIN_FLOOR = 0.5
"""Loop gain below which the delay's phase keeps ``L`` away from -1 (see the module docstring). 0.1 (|1 + L|
within 10 % of 1) was tried first: more points moved the design stages' paths, and on the benchmark's seed 1
problem 105 (PID, 42 ms delay) the polish ended 30 % lower; at 0.5 that design is within 0.1 % of the
reference and seed 5 problem 20 within 3 % (18 % on the log grid alone)."""

MAX_DELAY_POINTS = 400
"""Most frequencies :func:`delay_points` adds."""

_DENSER = 8
"""The plant's gain is taken on a grid this many times denser than the design grid (a lightly damped mode's
peak between two grid points counts)."""


def delay_resolving_step(delay: float) -> float | None:
    """The largest frequency step (rad/s) that turns a ``delay``'s phase by :data:`DELAY_STEP`; None without a
    delay (for :func:`synth.freqgrid.resolving_grid`).

    Examples
    --------
    >>> round(delay_resolving_step(2.0), 4), delay_resolving_step(0.0)
    (0.3927, None)
    """
    return DELAY_STEP / delay if delay > 0 else None


def controller_gain_bound(par: Parametrization) -> Callable[[np.ndarray], np.ndarray] | None:
    """An upper bound on ``|C(jw)|`` over the parametrization's box, or None when it has none.

    For a controller linear in its parameters, ``C = sum rho_k phi_k``, the triangle inequality gives
    ``|C(jw)| <= sum_k max(|lo_k|, |hi_k|) |phi_k(jw)|``.

    Examples
    --------
    >>> from synth.synthesis.parametrization import parametrize
    >>> bound = controller_gain_bound(parametrize("PI", {"kp": (0, 2), "ki": (-1, 4)}))
    >>> bound(np.array([1.0, 4.0])).round(3)  # 2 + 4/w
    array([6., 3.])
    >>> controller_gain_bound(parametrize("rational", {}, order=(1, 1))) is None
    True
    """
    if not isinstance(par, LinearParametrization):
        return None
    lo, hi = par.box()
    reach = np.maximum(np.abs(lo), np.abs(hi))
    if not np.all(np.isfinite(reach)):
        return None
    return lambda w: np.abs(par.basis(np.asarray(w, float))) @ reach


def delay_points(plants: list[Plant], grid: np.ndarray,
                 gain_bound: Callable[[np.ndarray], np.ndarray] | None) -> np.ndarray:
    """Evenly spaced frequencies (rad/s) that resolve the longest plant delay on ``grid`` where the loop
    gain can reach :data:`LOOP_GAIN_FLOOR` (see the module docstring); empty when none is needed.

    Parameters
    ----------
    plants : list of Plant
    grid : ndarray
        The log design grid (rad/s, increasing).
    gain_bound : callable or None
        ``w -> upper bound on |C(jw)|`` over the controller's bounds (:func:`controller_gain_bound`);
        None adds nothing.

    Examples
    --------
    >>> g = np.geomspace(0.01, 100.0, 161)
    >>> pid = lambda w: 2.0 + 1.0 / w + 5.0 * w / np.abs(1 + 0.1j * w)  # kp 2, ki 1, kd 5, tf 0.1
    >>> extra = delay_points([Plant.from_string("1/(s+1)", delay=4.0)], g, pid)
    >>> round(float(extra[0]), 2), round(float(extra[1] - extra[0]), 4), extra.size  # |L| > 0.5 to 100: the cap
    (3.55, 0.1963, 400)
    >>> p_only = delay_points([Plant.from_string("1/(s+1)", delay=4.0)], g, lambda w: 2.0 + 0 * w)
    >>> round(float(p_only[-1]), 1)  # |L| = 2/|1 + jw| falls to 0.5 at w = 3.9
    3.9
    >>> delay_points([Plant.from_string("1/(s+1)", delay=4.0)], g, lambda w: 0.2 + 0 * w).size  # below 0.5 there
    0
    >>> delay_points([Plant.from_string("1/(s+1)")], g, pid).size
    0
    """
    tau = max((p.delay for p in plants), default=0.0)
    if tau <= 0 or gain_bound is None or grid.size < 2:
        return np.array([])
    step = DELAY_STEP / tau
    coarse = np.flatnonzero(np.diff(grid) > step)
    if coarse.size == 0:
        return np.array([])
    start = float(grid[coarse[0]])
    dense = np.geomspace(start, float(grid[-1]), max(2, _DENSER * (grid.size - int(coarse[0]))))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        plant_gain = np.max([np.abs(p.freqresp(dense)) for p in plants], axis=0)
        loop_gain = np.nan_to_num(gain_bound(dense) * plant_gain, nan=np.inf, posinf=np.inf)
    reach = np.flatnonzero(loop_gain >= LOOP_GAIN_FLOOR)
    if reach.size == 0:
        return np.array([])
    last = float(dense[reach[-1]])  # the grid points around the last frequency that can reach the floor
    stop = float(grid[min(int(np.searchsorted(grid, last)), grid.size - 1)])
    # the cap before the points are made: a delay of 1e8 s asked for 1.4e9 of them (10.6 GiB), to keep 400
    return np.arange(start + step, min(stop, start + step * (MAX_DELAY_POINTS + 0.5)), step)
