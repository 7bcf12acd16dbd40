"""Stabilizing sets of one real parameter (the D-decomposition) and gain margins, on the exact count of
:mod:`synth.stability`.

:func:`affine_stability_intervals` finds every value of a real parameter ``rho`` (the controller is
``C0 + rho*C1``) at which a closed-loop root crosses the imaginary axis, then tests one point between
neighbouring boundaries with :func:`synth.stability.closed_loop_stability`: the result is the exact set of
stabilizing values. :func:`gain_margin_factors` reads the loop-gain factors at which ``k L`` turns marginal.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from synth.errors import ModelError
from synth.freqgrid import grid_decades
from synth.polynomials import largest_crossing, polymul, shifted, trim, value_at_infinity
from synth.rootfind import bisect_roots
from synth.stability import MAX_PHASE_POINTS, PHASE_STEP, Rational, characteristic_scale, closed_loop_stability

__all__ = ["COUNTED_PIECES", "GAIN_SEARCH_LIMIT", "ROOTS_PER_CROSSING", "StabilityInterval",
           "affine_root_counts", "affine_stability_intervals", "gain_margin_factors", "stability_boundaries"]


@dataclass(frozen=True)
class StabilityInterval:
    """A closed interval of a parameter over which the closed loop is stable.

    ``lo_is_boundary`` / ``hi_is_boundary`` tell whether the end is a
    stability boundary (a closed-loop root on the imaginary axis, excluded)
    rather than the end of the searched range.
    """

    lo: float
    hi: float
    lo_is_boundary: bool
    hi_is_boundary: bool
    lo_frequency: float | None = None
    hi_frequency: float | None = None


def _boundary_function(c0: Rational | None, c1: Rational, num: np.ndarray, den: np.ndarray, delay: float):
    a1, b1 = c1
    a0, b0 = c0 if c0 is not None else (np.array([0.0]), np.array([1.0]))

    def parts(w: np.ndarray):
        s = 1j * np.asarray(w, dtype=float)
        e = np.exp(-delay * s)
        n, d = np.polyval(num, s), np.polyval(den, s)
        Y = np.polyval(b0, s) * d  # once: X's first term is the same product
        X = Y + np.polyval(a0, s) * n * e
        U = np.polyval(a1, s) * n * e
        V = np.polyval(b1, s) * d
        return X * V, Y * U

    def h(w: np.ndarray) -> np.ndarray:
        top, bottom = parts(w)
        return np.imag(top * np.conj(bottom))

    def rho(w: np.ndarray) -> np.ndarray:
        top, bottom = parts(np.atleast_1d(np.asarray(w, dtype=float)))
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(np.abs(bottom) < 1e-300, np.inf, np.real(-top / bottom))

    return h, rho


def stability_boundaries(
    c0: Rational | None,
    c1: Rational,
    num: np.ndarray,
    den: np.ndarray,
    delay: float,
    rho_max: float,
) -> list[tuple[float, float]]:
    """Values ``rho`` (with their frequencies) where ``1 + (C0 + rho C1) G`` has a root on the axis.

    ``G = num/den * exp(-delay s)``; only ``|rho| <= rho_max`` is searched.

    Examples
    --------
    For ``G = 1/(s+1)^3`` the gain ``rho = 8`` puts roots at ``+-j sqrt(3)``:

    >>> [(round(r, 6), round(w, 6)) for r, w in stability_boundaries(
    ...     None, (np.array([1.0]), np.array([1.0])), np.array([1.0]),
    ...     np.array([1.0, 3.0, 3.0, 1.0]), 0.0, 100.0)]
    [(-1.0, 0.0), (8.0, 1.732051)]
    """
    a1, b1 = c1
    a0, b0 = c0 if c0 is not None else (np.array([0.0]), np.array([1.0]))
    h, rho = _boundary_function(c0, c1, num, den, delay)
    loop0_num, loop0_den = polymul(a0, num), polymul(b0, den)
    loop1_num, loop1_den = polymul(a1, num), polymul(b1, den)
    w_a = largest_crossing(loop0_num, loop0_den, 0.5) if np.any(a0 != 0) else 0.0
    w_b = largest_crossing(loop1_num, loop1_den, 0.5 / max(rho_max, 1e-300))
    lo_scale, hi_scale = characteristic_scale(a0, b0, a1, b1, num, den, delay=delay)
    w_max = max(w_a, w_b, hi_scale) * 1.2
    w_lin = min(w_max, max(w_a, w_b) * 1.2)
    l0, l1 = value_at_infinity(loop0_num, loop0_den), value_at_infinity(loop1_num, loop1_den)
    if delay > 0 and np.isfinite(l0) and np.isfinite(l1) and abs(l0) + rho_max * abs(l1) >= 0.5:
        # |L0 + rho L1| may stay near 1 at every frequency (a biproper loop): its delayed Nyquist curve then meets
        # -1 once per 2 pi / delay up to infinity, the rho of these crossings tending monotonically to the neutral
        # boundaries beyond the corners; two delay periods past ten times the corners hold the first of them
        w_max = max(w_max, 10.0 * hi_scale + 4.0 * np.pi / delay)
        w_lin = w_max
    w_min = 1e-4 * lo_scale
    grid = [np.geomspace(w_min, w_max, int(100 * grid_decades(w_min, w_max)) + 2)]
    if delay > 0:  # the delay's phase, sampled finely up to the last frequency where |L0 + rho L1| can be 1
        points = int(np.ceil(w_lin * delay / PHASE_STEP)) + 2
        if points > MAX_PHASE_POINTS:
            raise ModelError(f"the delay of {delay:g} s turns the loop's phase {w_lin * delay / (2 * np.pi):.3g} times "
                             f"below {w_lin:.3g} rad/s, where the loop gain can still reach 1: more than synth "
                             f"resolves ({MAX_PHASE_POINTS * PHASE_STEP / (2 * np.pi):.3g} turns); check that the "
                             "delay is in seconds, or narrow the controller's bounds", where="plant.delay")
        grid.append(np.linspace(0.0, w_lin, points)[1:])
    w = np.unique(np.concatenate(grid))
    hv = h(w)
    scale = np.max(np.abs(hv)) if hv.size else 1.0
    sign = np.sign(hv)
    idx = np.flatnonzero(sign[:-1] * sign[1:] < 0)
    exact = np.flatnonzero((sign == 0) & (np.arange(sign.size) > 0) & (np.abs(hv) <= 1e-14 * scale))
    w_cross = np.concatenate([[0.0], bisect_roots(lambda x, _: h(x), w[idx], w[idx + 1], indexed=True), w[exact]])
    r_cross = rho(w_cross)
    keep = np.isfinite(r_cross) & (np.abs(r_cross) <= rho_max)
    found = list(zip(r_cross[keep].tolist(), w_cross[keep].tolist()))
    if np.isfinite(l0) and np.isfinite(l1) and l1 != 0.0:
        # a biproper loop: roots come in from infinitely far out where L(j inf) = -1 (the characteristic
        # polynomial loses its leading term), and with a delay where |L(j inf)| = 1 (a neutral loop)
        ends = ((1.0 - l0) / l1, (-1.0 - l0) / l1) if delay > 0 else ((-1.0 - l0) / l1,)
        found += [(r, float("inf")) for r in ends if abs(r) <= rho_max]
    return sorted(found)



def _combine(c0: Rational | None, c1: Rational, rho: float) -> Rational:
    a1, b1 = c1
    if c0 is None:
        return rho * np.asarray(a1, float), np.asarray(b1, float)
    a0, b0 = c0
    return np.polyadd(polymul(a0, b1), rho * polymul(a1, b0)), polymul(b0, b1)


ROOTS_PER_CROSSING = 4
"""Most closed-loop roots taken to cross the imaginary axis at one boundary found at a finite frequency: a
complex pair (a real root at ``w = 0``), doubled for a double root. :func:`affine_stability_intervals` skips the
count of a piece that must hold right-half-plane roots by this bound; a boundary at infinite frequency (a
biproper loop's) can take any number."""


def roots_crossing(boundaries: list[tuple[float, float]]) -> np.ndarray:
    """The most closed-loop roots that can cross the imaginary axis at each boundary ``(rho, w)`` of
    :func:`stability_boundaries`: :data:`ROOTS_PER_CROSSING` at a finite frequency, any number (``inf``) at an
    infinite one.

    Examples
    --------
    >>> roots_crossing([(8.0, 1.7), (2.0, float("inf"))]).tolist()
    [4.0, inf]
    """
    return np.array([float(ROOTS_PER_CROSSING) if np.isfinite(w) else np.inf for _, w in boundaries])


def affine_stability_intervals(
    c0: Rational | None,
    c1: Rational,
    num: np.ndarray,
    den: np.ndarray,
    delay: float,
    lo: float,
    hi: float,
    first_only: bool = False,
    floor: float = 0.0,
) -> list[StabilityInterval]:
    """Exact stabilizing set of ``rho`` in ``[lo, hi]`` for the controller ``C0 + rho C1``.

    With ``floor > 0`` every closed-loop root must have ``Re s < -floor`` (the same D-decomposition on the loop
    shifted by ``floor``, as :func:`closed_loop_stability` does).

    Parameters
    ----------
    c0 : (num, den) or None
        Fixed part of the controller (None for zero).
    c1 : (num, den)
        Part multiplied by ``rho``.
    num, den, delay
        Plant rational part and delay.
    lo, hi : float
        Range searched.
    first_only : bool
        Stop at the end of the first stabilizing interval that starts at ``lo`` (the pieces between
        boundaries are tested in order, so only those up to the first destabilizing boundary are
        counted; e.g. a critical gain). Empty when ``lo`` itself is not stabilizing.

    Returns
    -------
    list of StabilityInterval

    Examples
    --------
    The X-4 rotor plant with a 20 ms in-loop delay under P control:

    >>> from synth.plant import Plant
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    >>> iv = affine_stability_intervals(None, (np.array([1.0]), np.array([1.0])),
    ...                                 G.num, G.den, G.delay, 0.0, 20.0)
    >>> [(round(i.lo, 3), round(i.hi, 3)) for i in iv]
    [(0.0, 3.688)]
    """
    if hi < lo:
        raise ModelError(f"range [{lo}, {hi}] is reversed")
    if floor > 0.0:
        num, den = shifted(num, floor) * np.exp(floor * delay), shifted(den, floor)
        c0 = None if c0 is None else (shifted(c0[0], floor), shifted(c0[1], floor))
        c1 = (shifted(c1[0], floor), shifted(c1[1], floor))
    rho_max = max(abs(lo), abs(hi)) * 1.0001 + 1e-12
    bounds = stability_boundaries(c0, c1, num, den, delay, rho_max)
    cuts = sorted({lo, hi, *[r for r, _ in bounds if lo < r < hi]})
    freq = {r: w for r, w in bounds}
    pieces: list[StabilityInterval] = []
    leaving: dict[float, float] = {}  # most roots that can cross the axis at each boundary value
    for (r, _), most in zip(bounds, roots_crossing(bounds)):
        leaving[r] = leaving.get(r, 0.0) + most

    def unstable_at(r: float) -> int:
        cn, cd = _combine(c0, c1, r)
        ln, ld = polymul(cn, num), polymul(cd, den)
        if np.all(ln == 0):
            return int(np.sum(np.roots(trim(den)).real >= 0)) if trim(den).size > 1 else 0
        return closed_loop_stability(ln, ld, delay).unstable_poles

    at_least = 0.0  # closed-loop roots in the right half-plane that the piece holds at least
    for a, b in pairwise(cuts) if len(cuts) > 1 else [(lo, hi)]:
        # the count changes only at boundaries, by at most the roots that cross there: a piece after one with
        # n roots holds at least n minus those (a long delay's hundreds of boundaries beyond the critical gain
        # are then counted at a few pieces, not each: 1/(s+1) e^(-20 s) up to a gain of 1000, 3184 -> 12 counts)
        n = at_least if at_least > 0 else unstable_at(0.5 * (a + b))
        at_least = n - leaving.get(b, 0.0)
        if n > 0:
            if first_only:
                break
            continue
        if pieces and pieces[-1].hi == a:
            # stable on both sides of a boundary the loop only touches: one interval
            prev = pieces.pop()
            pieces.append(StabilityInterval(prev.lo, b, prev.lo_is_boundary, b in freq,
                                            prev.lo_frequency, freq.get(b)))
        else:
            pieces.append(StabilityInterval(a, b, a in freq, b in freq, freq.get(a), freq.get(b)))
    return pieces


def affine_root_counts(
    c0: Rational | None,
    c1: Rational,
    num: np.ndarray,
    den: np.ndarray,
    delay: float,
    values: np.ndarray,
    floor: float = 0.0,
) -> np.ndarray:
    """Closed-loop roots in the closed right half-plane at each of ``values`` of ``rho`` (controller
    ``C0 + rho C1``), as :func:`synth.stability.closed_loop_stability` with ``floor`` counts them at each value.

    The count is constant between neighbouring stability boundaries (:func:`stability_boundaries`, on the
    loop shifted by ``floor`` when it is positive): one count per piece that holds a value, and every value
    within ``1e-9`` (relative) of a boundary counted by itself. When values lie in more than
    :data:`COUNTED_PIECES` pieces, a piece that must hold right-half-plane roots gets their lower bound
    uncounted (zero and non-zero stay exact).

    Examples
    --------
    ``G = 1/(s+1)^3`` under P control: stable for ``-1 < k < 8``, a complex pair beyond 8:

    >>> affine_root_counts(None, (np.array([1.0]), np.array([1.0])), np.array([1.0]),
    ...                    np.array([1.0, 3.0, 3.0, 1.0]), 0.0, np.array([-2.0, 0.0, 7.9, 8.1, 20.0])).tolist()
    [1, 0, 0, 2, 2]
    """
    values = np.asarray(values, dtype=float)
    counts = np.zeros(values.size, dtype=int)
    if values.size == 0:
        return counts
    b_num, b_den = num, den
    b_c0, b_c1 = c0, c1
    if floor > 0.0:
        b_num, b_den = shifted(num, floor) * np.exp(floor * delay), shifted(den, floor)
        b_c0 = None if c0 is None else (shifted(c0[0], floor), shifted(c0[1], floor))
        b_c1 = (shifted(c1[0], floor), shifted(c1[1], floor))
    rho_max = float(np.max(np.abs(values))) * 1.0001 + 1e-12
    boundaries = sorted(stability_boundaries(b_c0, b_c1, b_num, b_den, delay, rho_max))
    edges = np.array([r for r, _ in boundaries])
    crossing = roots_crossing(boundaries)

    def count_at(r: float) -> int:
        cn, cd = _combine(c0, c1, r)
        while cn.size > 1 and cd.size > 1 and cn[-1] == 0.0 and cd[-1] == 0.0:  # C0 + 0 C1 = C0: s cancels
            cn, cd = cn[:-1], cd[:-1]
        return closed_loop_stability(polymul(cn, num), polymul(cd, den), delay, floor).unstable_poles

    piece = np.searchsorted(edges, values) if edges.size else np.zeros(values.size, dtype=int)
    near = np.zeros(values.size, bool) if edges.size == 0 else \
        np.min(np.abs(values[:, None] - edges[None, :]), axis=1) <= 1e-9 * np.maximum(1.0, np.abs(values))
    held = np.unique(piece[~near])
    bound_them = held.size > COUNTED_PIECES
    last: tuple[int, float] | None = None  # the last piece with a count (or bound) and that number
    for k in held:  # in increasing order
        inside = values[(piece == k) & ~near]
        at_least = last[1] - float(np.sum(crossing[last[0]:k])) if bound_them and last is not None else 0.0
        n = at_least if at_least > 0 else float(count_at(0.5 * (float(inside.min()) + float(inside.max()))))
        counts[(piece == k) & ~near] = int(np.ceil(n))
        last = (int(k), n)
    for i in np.flatnonzero(near):
        counts[i] = count_at(float(values[i]))
    return counts


COUNTED_PIECES = 40
"""Pieces between stability boundaries that :func:`affine_root_counts` counts each, at most: with more (a long
delay's boundaries, one per turn of its phase beyond the critical gain), a piece that must hold right-half-plane
roots, because the last piece counted before it held more than can leave at the boundaries between them
(:data:`ROOTS_PER_CROSSING` each), gets that lower bound instead of a count. Stable and unstable stay exact; an
unstable loop's count is then only bounded below (its slack of -1 per root a bulk estimate, which the scalar
check refines where a sign matters: 1/(s+1) e^(-100 s) under P up to 1000, 167 counts of 0.14 s each)."""


GAIN_SEARCH_LIMIT = 1e4
"""Loop-gain factors beyond this (80 dB) are reported as infinite gain margin."""


def gain_margin_factors(
    num: np.ndarray, den: np.ndarray, delay: float
) -> tuple[float, float, float | None, float | None]:
    """Scalar loop-gain factors ``(k_lo, k_hi)`` bracketing ``k = 1`` at which ``k L`` turns marginal.

    Returns ``(k_lo, k_hi, w_lo, w_hi)`` with the frequencies of the axis roots;
    ``k_lo = 0`` and ``k_hi = inf`` when no such gain exists within a factor
    :data:`GAIN_SEARCH_LIMIT` (80 dB). Only meaningful for a stable loop:
    ``20 log10(k_hi)`` is the classical gain margin.

    Examples
    --------
    >>> k_lo, k_hi, _, w = gain_margin_factors(np.array([1.0]), np.array([1.0, 3.0, 3.0, 1.0]), 0.0)
    >>> round(k_hi, 6), round(w, 4)
    (8.0, 1.7321)
    """
    # At a boundary |rho| = 1/|L(jw)|: a search up to |rho| = cap finds every boundary below cap,
    # so widen the cap tenfold until a gain above 1 turns up (most loops stop at the first step). Without a
    # delay a larger cap only adds a few decades of grid, cheaper than another search (a PID with a gain margin
    # beyond 20 dB: three searches, 3.2 ms; one, 1.4 ms, the same factors to 2e-14); with one, it samples the
    # delay's phase finely up to where |L| falls below 1/(2 cap).
    cap = 10.0 if delay > 0 else GAIN_SEARCH_LIMIT
    while True:
        bounds = stability_boundaries(None, (num, den), np.array([1.0]), np.array([1.0]), delay, cap)
        pos = [(r, w) for r, w in bounds if r > 0]
        above = [(r, w) for r, w in pos if r > 1.0 + 1e-12]
        if above or cap >= GAIN_SEARCH_LIMIT:
            break
        cap = min(cap * 10.0, GAIN_SEARCH_LIMIT)
    below = [(r, w) for r, w in pos if r < 1.0 - 1e-12 and r > 1.0 / GAIN_SEARCH_LIMIT]
    k_hi, w_hi = min(above) if above else (np.inf, None)
    k_lo, w_lo = max(below) if below else (0.0, None)
    return float(k_lo), float(k_hi), w_lo, w_hi
