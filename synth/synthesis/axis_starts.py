"""Stabilizing starts from exact one-parameter scans: each gain alone, the others at zero.

The convex stage needs a stabilizing controller to start from, and draws them at random in the bounds. Where
the stabilizing set is a thin slab of the box that random draws miss, such as a plant with an unstable pole
left of a right-half-plane zero that only a negative gain in a narrow range stabilizes, the exact
stabilizing set of each gain alone (the other gains at the value nearest zero in their bounds, the
structural parameters as fixed by the parametrization) is computed by D-decomposition
(:func:`synth.synthesis.gainset.stability_set`) and the middle of every interval is offered as a start.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from synth.controllers import RATIONAL
from synth.plant import Plant
from synth.synthesis.gainset import ScalarFamily, stability_set
from synth.synthesis.intervals import interval_middle
from synth.synthesis.parametrization import Parametrization, RationalParametrization
from synth.synthesis.rational_slices import RATIONAL_SLICES, rational_slices

__all__ = ["LEADLAG_SLICES", "axis_starts", "leadlag_slices", "scan_note"]

SCANNED_TYPES = ("P", "PI", "PID")
"""Controller types whose convex parameters are their own gains (a lead-lag's are ``k`` and ``k z``)."""


LEADLAG_SLICES = 40
"""Zeros drawn by :func:`leadlag_slices`, each with the exact stabilizing set of the gain ``k``."""


def leadlag_slices(par: Parametrization, plants: list[Plant], draws: int = LEADLAG_SLICES,
                   seed: int = 0) -> Iterator[np.ndarray]:
    """Starts ``rho = (k, k z)`` of a lead-lag with its pole fixed: for zeros ``z`` drawn in their bounds
    (log-uniform when the bounds are positive; seeded), the middle of every exact stabilizing interval of ``k``
    alone (the loop is affine in ``k``). On an unstable plant with a right-half-plane zero the stabilizing
    set can be a region random draws of all three parameters miss (600 found none on problem 181 of the design
    benchmark's seed 13, whose reference found a design); one zero in seven of the same plant has an interval.

    Examples
    --------
    >>> from synth.synthesis.parametrization import parametrize
    >>> par = parametrize("leadlag", {"k": (0, 7.66), "z": (0.14, 55.8), "p": (34.2, 34.2)})
    >>> plant = Plant.from_string("21.6258*(1-s/4.2526)/((s-0.486492)*(s+1.70187)*(s+0.236173))")
    >>> rho = next(leadlag_slices(par, [plant]))
    >>> from synth.loop import Loop; from synth.controllers import Controller
    >>> k, z = float(rho[0]), float(rho[1] / rho[0])
    >>> Loop(plant, Controller("leadlag", {"k": k, "z": z, "p": 34.2})).stability().stable
    True
    """
    (k_lo, k_hi), (z_lo, z_hi) = par.bounds["k"], par.bounds["z"]
    p = par.fixed.get("p")
    if p is None or not all(np.isfinite([k_lo, k_hi, z_lo, z_hi])) or k_lo >= k_hi:
        return
    rng = np.random.default_rng(seed)
    u = rng.random(draws)
    zs = z_lo * (z_hi / z_lo) ** u if z_lo > 0 else z_lo + (z_hi - z_lo) * u
    for z in zs:
        family = ScalarFamily("leadlag", "k", {"z": float(z), "p": float(p)})
        try:
            intervals = stability_set(family, plants, float(k_lo), float(k_hi))
        except (ArithmeticError, ValueError, RuntimeError):
            continue
        for a, b in intervals:
            k = interval_middle(a, b)
            yield np.array([k, k * z])


def scan_note(ctype: str) -> str:
    """What :func:`axis_starts` searched for a controller type, for the message of a search that found nothing.

    Examples
    --------
    >>> scan_note("leadlag")
    ' and the exact stabilizing set of k for 40 zeros drawn in the bounds'
    """
    if ctype in SCANNED_TYPES:
        return " and the exact stabilizing set of each gain alone (the others at their values nearest 0)"
    if ctype == "leadlag":
        return f" and the exact stabilizing set of k for {LEADLAG_SLICES} zeros drawn in the bounds"
    if ctype == RATIONAL:
        return f" and the exact stabilizing set of the numerator's gain for {RATIONAL_SLICES} pole/zero patterns"
    return ""


def axis_starts(par: Parametrization, plants: list[Plant]) -> Iterator[np.ndarray]:
    """``rho`` at the middle of every exact stabilizing interval of each gain alone (see the module
    docstring), gain by gain, for P, PI and PID controllers; of the gain ``k`` for drawn zeros of a lead-lag
    (:func:`leadlag_slices`) and of the numerator's gain for drawn pole/zero patterns of a rational controller
    (:func:`synth.synthesis.rational_slices.rational_slices`).

    Examples
    --------
    >>> from synth.synthesis.parametrization import parametrize
    >>> par = parametrize("PID", {"kp": (-10, 10), "ki": (-5, 5), "kd": (0, 1), "tf": (0.01, 0.01)})
    >>> starts = list(axis_starts(par, [Plant.from_string("(s-2)/((s-1)*(s+3))")]))
    >>> [float(v) for v in starts[0].round(6)]  # kp in (-2, -1.5) alone stabilizes
    [-1.75, 0.0, 0.0]
    """
    if par.ctype == "leadlag":
        yield from leadlag_slices(par, plants)
        return
    if isinstance(par, RationalParametrization):
        yield from rational_slices(par, plants)
        return
    if par.ctype not in SCANNED_TYPES:
        return
    lo, hi = par.box()
    nearest_zero = np.clip(0.0, lo, hi)
    for i, name in enumerate(par.names):
        if not (np.isfinite(lo[i]) and np.isfinite(hi[i])) or lo[i] >= hi[i]:
            continue
        fixed = {**par.fixed, **{n: float(nearest_zero[j]) for j, n in enumerate(par.names) if j != i}}
        family = ScalarFamily(par.ctype, name, fixed)
        try:
            intervals = stability_set(family, plants, float(lo[i]), float(hi[i]))
        except (ArithmeticError, ValueError, RuntimeError):
            continue
        for a, b in intervals:
            rho = nearest_zero.astype(float).copy()
            rho[i] = interval_middle(a, b)
            yield rho
