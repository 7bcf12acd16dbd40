"""Stabilizing starts of a rational controller from exact one-parameter scans of its gain.

A rational controller ``C = X/D`` is affine in a common factor ``k`` of its numerator. For a denominator and
numerator shape drawn in the bounds (real poles, complex pairs and real zeros, log-uniform over the frequencies
the bounds allow),
the exact stabilizing set of ``k`` (D-decomposition, :func:`synth.synthesis.gainset.stability_set`) gives
starts that random draws of every coefficient miss: on an open-loop unstable plant a loop needs both a gain in
a narrow range and controller poles well above the crossover it forces, a corner of a box of several decades
per coefficient (problem 5 of the design benchmark's seed 23, whose reference met every requirement with
``b0`` at its bound and poles near 10 and 34 rad/s, while 600 random draws gave one stabilizing start).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from synth.controllers import RATIONAL, Controller
from synth.plant import Plant
from synth.synthesis.gainset import ScalarFamily, stability_set
from synth.synthesis.intervals import interval_middle
from synth.synthesis.parametrization import RationalParametrization

__all__ = ["RATIONAL_SLICES", "ShapedGain", "rational_slices"]

RATIONAL_SLICES = 40
"""Denominator and numerator shapes drawn by :func:`rational_slices`, each with the exact stabilizing set of
its gain."""

SPAN_BELOW = 10.0
"""Poles and zeros are drawn from ``w0 / SPAN_BELOW`` up to the fastest the bounds allow ..."""

SPAN_ABOVE = 1e4
"""... and at most ``w0 * SPAN_ABOVE`` where the bounds allow any."""

DAMPING_MIN = 0.05
"""Complex pole pairs are drawn with damping log-uniform in ``[DAMPING_MIN, 1]``: a lightly damped pair above the
crossover adds little phase lag below it while its gain still rolls off (seed 23 #5's feasible set needs one)."""


class ShapedGain(ScalarFamily):
    """Rational controllers ``k * shape_num / den``: the gain ``k`` varies, the shape is fixed.

    Examples
    --------
    >>> fam = ShapedGain({"b0": 1.0, "b1": 0.5}, {"a0": 2.0, "a1": 3.0})
    >>> fam.controller(4.0).parameters
    {'b0': 4.0, 'b1': 2.0, 'a0': 2.0, 'a1': 3.0}
    """

    def __init__(self, shape: dict[str, float], denominator: dict[str, float]) -> None:
        super().__init__(RATIONAL, "k", denominator)
        self.shape = dict(shape)

    def controller(self, value: float) -> Controller:
        """The controller of gain ``value``."""
        return Controller(RATIONAL, {**{n: float(value) * c for n, c in self.shape.items()}, **self.fixed})


def _fastest(hi: np.ndarray, count: int, cap: float) -> float:
    """The largest ``p <= cap`` with every coefficient of ``(s + p)^count`` below ``s^count`` inside its upper
    bound ``hi`` (``hi[i]`` bounds the coefficient of ``s^i``)."""
    binom = (np.poly1d([1.0, 1.0]) ** count).coeffs[::-1]  # binom[i]: the coefficient of s^i, times p^(count - i)
    p = cap
    for i, h in enumerate(hi):
        if np.isfinite(h) and binom[i] > 0:
            p = min(p, (max(h, 0.0) / binom[i]) ** (1.0 / (count - i)) if h > 0 else 0.0)
    return p


def _gain_range(shape: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[float, float]:
    """The gains ``k`` with ``lo <= k * shape <= hi`` coefficient by coefficient."""
    k_lo, k_hi = -np.inf, np.inf
    for c, a, b in zip(shape, lo, hi):
        if c == 0.0:
            continue
        lo_k, hi_k = sorted((a / c, b / c))
        k_lo, k_hi = max(k_lo, lo_k), min(k_hi, hi_k)
    return float(k_lo), float(k_hi)


def rational_slices(par: RationalParametrization, plants: list[Plant], draws: int = RATIONAL_SLICES,
                    seed: int = 0) -> Iterator[np.ndarray]:
    """Starts ``rho`` of a rational controller: for seeded draws of real poles (one at the origin with an
    integrator; in half the draws two of them replaced by a complex pair) and, in every other draw, real
    zeros (the others have the numerator ``b0`` alone where the bounds allow), the middle of every exact
    stabilizing interval of the numerator's gain.

    Examples
    --------
    >>> from synth.synthesis.parametrization import parametrize
    >>> bounds = {"b0": (-14416.4, 14416.4), "a0": (0, 65260), "a1": (0, 17914.7), "a2": (0, 4917.81)}
    >>> par = parametrize("rational", bounds, order=(0, 3), w0=0.425)
    >>> plant = Plant.from_string("3.66752/(s - 0.424971)")
    >>> rho = next(rational_slices(par, [plant]))
    >>> from synth.loop import Loop
    >>> Loop(plant, par.controller(rho)).stability().stable
    True
    """
    lo, hi = (np.array([par.bounds[n][i] for n in par.names], float) for i in (0, 1))
    b_names, a_names = par.names[: par.m + 1], par.names[par.m + 1:]
    integrator = par.has_integrator()
    free_poles = par.n - (1 if integrator else 0)
    a_hi = hi[par.m + 1:]
    if integrator:  # D = s * D1: the bounds on a_i hold D1's coefficient of s^(i-1)
        a_hi = a_hi[1:]
    p_min = par.w0 / SPAN_BELOW
    p_max = _fastest(a_hi, free_poles, par.w0 * SPAN_ABOVE) if free_poles > 0 else p_min
    z_max = par.w0 * SPAN_ABOVE
    if not (np.all(np.isfinite(lo[: par.m + 1])) or np.all(np.isfinite(hi[: par.m + 1]))) or p_max <= p_min:
        return
    rng = np.random.default_rng(seed)
    zeros_free = all(lo[i] <= 0.0 <= hi[i] for i in range(1, par.m + 1))
    for draw in range(draws):
        poles = p_min * (p_max / p_min) ** rng.random(free_poles)
        den = np.poly(-poles)
        if free_poles >= 2 and draw % 4 >= 2:  # half the draws with a complex pair in place of two real poles
            wn, zeta = np.sqrt(poles[0] * poles[1]), DAMPING_MIN ** rng.random()
            den = np.polymul(np.poly(-poles[2:]), [1.0, 2.0 * zeta * wn, wn * wn])
        if integrator:
            den = np.polymul(den, [1.0, 0.0])
        a = den[::-1][: par.n]
        if np.any(a < lo[par.m + 1:]) or np.any(a > hi[par.m + 1:]):
            continue
        with_zeros = par.m > 0 and (draw % 2 == 1 or not zeros_free)
        zeros = p_min * (z_max / p_min) ** rng.random(par.m) if with_zeros else np.zeros(0)
        num = np.poly(-zeros) / np.prod(zeros) if zeros.size else np.ones(1)  # unit DC gain: (s/z + 1) factors
        shape = np.zeros(par.m + 1)
        shape[: num.size] = num[::-1]
        k_lo, k_hi = _gain_range(shape, lo[: par.m + 1], hi[: par.m + 1])
        k_lo, k_hi = max(k_lo, -1e12), min(k_hi, 1e12)
        if not k_lo < k_hi:
            continue
        family = ShapedGain(dict(zip(b_names, shape.tolist())), dict(zip(a_names, a.tolist())))
        try:
            intervals = stability_set(family, plants, k_lo, k_hi)
        except (ArithmeticError, ValueError, RuntimeError):
            continue
        for k_a, k_b in intervals:
            yield par.rho(family.controller(interval_middle(k_a, k_b)))
