"""Closed-loop stability of a loop ``L(s) = num(s)/den(s) * exp(-delay*s)``, decided exactly.

Without a delay the closed-loop poles are the roots of ``den + num``. With a
delay the characteristic function ``den(s) + num(s) exp(-delay s)`` has
infinitely many roots; the number in the closed right half-plane is counted
with the argument principle (Nyquist): ``Z = P + W``, where ``P`` counts the
open-loop poles in the open right half-plane and ``W`` the clockwise winding
of ``1 + L(jw)`` about the origin. The winding is computed on an adaptively
refined frequency path, with indentations around open-loop poles on the
imaginary axis, up to the frequency where ``|L(jw)|`` has fallen below a level
``r < 1`` for good (found exactly from a polynomial in ``w**2``); beyond it
``1 + L`` stays in the right half-plane and adds no winding.

The stabilizing set of a parameter (the D-decomposition) and the gain
margins built on this count are in :mod:`synth.stability_sets`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from functools import lru_cache

import numpy as np

from synth.errors import ModelError
from synth.polynomials import largest_crossing, shifted, trim, value_at_infinity

__all__ = [
    "BLUR_DEGREE",
    "MAX_PHASE_POINTS",
    "PHASE_STEP",
    "ROOT_PERTURBATION",
    "STABILITY_FLOOR",
    "Rational",
    "StabilityResult",
    "characteristic_scale",
    "closed_loop_stability",
    "neutral_with_any_delay",
    "root_blur",
    "stability_floor",
]

PHASE_STEP = np.pi / 8.0

MAX_PHASE_POINTS = 4_000_000
"""Most samples of a delay's phase (one per :data:`PHASE_STEP`) that a Nyquist count or a D-decomposition takes:
a P gain of 1e9 behind 20 s of delay asked the count for 1e11 (797 GiB), a delay of 1e6 s behind ``1/(s+1)``
with gains up to 1000 the D-decomposition for 6e9; 1/(s+1) e^(-100 s) needs 1e6 (a P design in 5 s). Beyond it
a count is not made (the loop is not certified stable) and a D-decomposition is refused
(:class:`synth.errors.ModelError`: check the delay's units)."""


@dataclass(frozen=True)
class StabilityResult:
    """Outcome of a closed-loop stability test.

    Attributes
    ----------
    stable : bool
        True when every closed-loop root has a negative real part.
    unstable_poles : int
        Closed-loop roots in the closed right half-plane.
    open_loop_unstable_poles : int
        Open-loop poles in the open right half-plane (``P`` of the Nyquist count).
    method : str
        ``"polynomial roots"`` (no delay) or ``"Nyquist argument principle, exact delay"``.
    marginal_frequency : float or None
        Frequency (rad/s) of a closed-loop root on the imaginary axis, if any.
    near_axis : float or None
        Set when the only roots that make the loop not stable lie left of the axis but within this
        distance of it (``Re s > -near_axis``; see :data:`STABILITY_FLOOR`).
    neutral_gain : float or None
        ``|L(j inf)|`` of a biproper loop with a delay when it is 1 or more (a neutral-type loop): the
        closed loop then has infinitely many roots whose real parts tend to ``ln|L(j inf)| / delay >= 0``,
        counted as one unstable root in ``unstable_poles``; no delay-robust stability is possible.
    """

    stable: bool
    unstable_poles: int
    open_loop_unstable_poles: int
    method: str
    marginal_frequency: float | None = None
    near_axis: float | None = None
    neutral_gain: float | None = None

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return asdict(self)

    def describe(self) -> str:
        """One plain-language line.

        Examples
        --------
        >>> closed_loop_stability(np.array([1.0]), np.array([1.0, 1.0])).describe()
        'closed loop stable (polynomial roots)'
        """
        if self.stable:
            return f"closed loop stable ({self.method})"
        if self.neutral_gain is not None:
            where = "in the right half-plane" if self.neutral_gain > 1.0 else "accumulating at the imaginary axis"
            return (f"closed loop UNSTABLE: |L(j inf)| = {self.neutral_gain:.4g} >= 1 with a delay (neutral type), "
                    f"infinitely many roots {where}")
        if (self.near_axis is not None and self.unstable_poles == 0) or self.method.startswith("not counted"):
            return f"closed loop not certified stable ({self.method})"
        if self.near_axis is not None:
            return (f"closed loop not stable in practice: {self.unstable_poles} root(s) within {self.near_axis:.3g} "
                    f"of the imaginary axis (Re s > -{self.near_axis:.3g}; {self.method})")
        if self.marginal_frequency is not None:
            return (f"closed loop marginally stable: a root on the imaginary axis near "
                    f"{self.marginal_frequency:.4g} rad/s ({self.method})")
        return f"closed loop UNSTABLE: {self.unstable_poles} root(s) in the right half-plane ({self.method})"


STABILITY_FLOOR = 1e-6
"""Closed-loop roots with ``Re s > -STABILITY_FLOOR * w_lo`` (``w_lo``: the plant's smallest characteristic
frequency) count as not stable: a root at ``-1e-12`` (a vanishing gain, a controller zero cancelling an
integrator) is stable in exact arithmetic but leaves a mode that never settles."""


def stability_floor(num: np.ndarray, den: np.ndarray, delay: float = 0.0) -> float:
    """:data:`STABILITY_FLOOR` times the smallest characteristic frequency of a plant (pole and zero
    magnitudes, ``1/delay``; 1 rad/s when it has none).

    Examples
    --------
    >>> stability_floor(np.array([1.0]), np.array([1.0, 0.5, 0.0]))
    5e-07
    """
    # kept per plant: every loop's stability count asks for its plant's floor (22,000 times in a design sample)
    return _plant_floor(np.asarray(num, float).tobytes(), np.asarray(den, float).tobytes(), float(delay))


@lru_cache(maxsize=64)
def _plant_floor(num: bytes, den: bytes, delay: float) -> float:
    return STABILITY_FLOOR * characteristic_scale(np.frombuffer(num), np.frombuffer(den), delay=delay)[0]


def neutral_with_any_delay(num: np.ndarray, den: np.ndarray) -> bool:
    """Whether the loop ``num/den`` has ``|L(j inf)| >= 1``: behind any delay it is then a neutral-type loop, with
    roots at ``Re s -> ln|L(j inf)| / delay >= 0`` (its delay margin is 0).

    Examples
    --------
    >>> neutral_with_any_delay(np.array([3.0, 6.0]), np.array([1.0, 1.0])), neutral_with_any_delay(np.array([3.0]),
    ...                                                                                              np.array([1.0, 1.0]))
    (True, False)
    """
    return abs(value_at_infinity(num, den)) >= 1.0


def characteristic_scale(*polys: np.ndarray, delay: float = 0.0) -> tuple[float, float]:
    """Smallest and largest characteristic frequencies (rad/s): root magnitudes and 1/delay."""
    roots = []
    for p in polys:
        p = trim(np.asarray(p, float))
        if p.size > 1:
            roots.append(np.roots(p))
    return _scale_of_roots(roots, delay)


def _scale_of_roots(roots: list[np.ndarray], delay: float) -> tuple[float, float]:
    """:func:`characteristic_scale` from each polynomial's roots (its roots at the origin may be left out)."""
    mags = []
    for r in roots:
        r = np.abs(r)
        if r.size:
            mags.extend(r[r > 1e-10 * max(1.0, float(r.max()))].tolist())
    if delay > 0:
        mags.append(1.0 / delay)
    if not mags:
        return 1.0, 1.0
    return float(min(mags)), float(max(mags))


def _axis_poles(den: np.ndarray, near: float | None = None,
                roots: np.ndarray | None = None) -> tuple[int, int, list[tuple[float, int]]]:
    """(open RHP pole count, poles at the origin, [(w_k > 0, multiplicity)]).

    A root within ``1e-9 max(1, |r|)`` of the axis counts as on it, one within ``1e-10`` of the largest root
    (at least 1) as at the origin. ``near`` (a thousandth of the stability floor, on the count of a loop shifted
    by that floor) caps both at ``near`` (and ``1e-9 |r|`` off the origin): a slow plant's floor (1e-9 rad/s for
    poles at 1e-3 rad/s) moves an integrator's pole no further than the absolute 1e-9, which put it back on the
    axis and broke the count. ``roots``: those of ``den`` without its trailing zeros, when the caller has them."""
    den = trim(den)
    n_origin = 0
    while den.size > 1 and den[-1] == 0.0:
        den = den[:-1]
        n_origin += 1
    if roots is None:
        roots = np.roots(den) if den.size > 1 else np.array([])
    tol = 1e-9 * np.maximum(1.0, np.abs(roots))
    tiny_level = 1e-10 * max(1.0, float(np.abs(roots).max(initial=0.0)))
    if near is not None:
        tol = np.minimum(tol, np.maximum(near, 1e-9 * np.abs(roots)))
        tiny_level = min(tiny_level, near)
    tiny = np.abs(roots) <= tiny_level
    roots = np.where(tiny, 0.0, roots)  # numerically at the origin
    on_axis = np.abs(roots.real) <= tol
    n_rhp = int(np.sum((roots.real > 0) & ~on_axis))
    axis = []
    for r in roots[on_axis & (roots.imag > 0)]:
        w = float(r.imag)
        for i, (wk, m) in enumerate(axis):
            if abs(wk - w) <= 1e-7 * max(1.0, w):
                axis[i] = (wk, m + 1)
                break
        else:
            axis.append((w, 1))
    n_origin += int(np.sum(on_axis & (np.abs(roots.imag) <= tol)))
    return n_rhp, n_origin, sorted(axis)


class _ReturnDifference:
    """F(s) = 1 + num(s)/den(s) * exp(-delay*s), and the loop's nonzero open-loop poles and zeros (``corners``,
    where :func:`_segment_phase` samples each segment first)."""

    def __init__(self, num: np.ndarray, den: np.ndarray, delay: float, roots: np.ndarray | None = None) -> None:
        self.num, self.den, self.delay = num, den, delay
        if roots is None:  # the open-loop zeros and poles, unless the caller has them
            roots = np.concatenate([np.roots(p) if p.size > 1 else np.zeros(0, complex) for p in (num, den)])
        self.corners = roots[np.abs(roots) > 0]

    def __call__(self, s: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return 1.0 + np.polyval(self.num, s) / np.polyval(self.den, s) * np.exp(-self.delay * s)


def _segment_phase(F: _ReturnDifference, a: float, b: float, delay: float) -> tuple[float, float]:
    """Continuous phase change of F(jw) for w from a to b, and min |F| seen.

    The first samples resolve the delay's phase (linear), every decade from two below the loop's lowest
    corner (40 points each, from ``a`` when it is positive) and each open-loop pole's and zero's band (a cluster
    of 17 points a quarter of its damping apart): the refinement below halves only steps it can see, so a lightly
    damped pair between two coarse samples could otherwise hide a whole turn of ``F`` around the origin (seen: a
    resonant controller's pair at 0.1 rad/s, damping 0.074, sampled at 0, 0.67 and 1.35 rad/s)."""
    pts = [np.linspace(a, b, max(3, int(np.ceil((b - a) * delay / PHASE_STEP)) + 2))]
    roots = F.corners
    start = a if a > 0 else (float(np.min(np.abs(roots))) / 100.0 if roots.size else b * 1e-6)
    if 0 < start < b:
        pts.append(np.geomspace(start, b, max(3, int(40 * np.log10(b / start)) + 2)))
    for r in roots:
        zeta = min(1.0, max(abs(r.real) / abs(r), 1e-9))
        cluster = abs(r) * (1.0 + zeta / 4.0 * np.arange(-8, 9))
        pts.append(cluster[(cluster > a) & (cluster < b)])
    w = np.unique(np.concatenate(pts))
    f = F(1j * w)
    for _ in range(60):
        ratio = f[1:] / f[:-1]
        step = np.abs(np.angle(ratio))
        chord = np.abs(f[1:] - f[:-1])
        bad = (step > PHASE_STEP) | (chord > 0.5 * np.minimum(np.abs(f[1:]), np.abs(f[:-1])))
        if not np.any(bad) or w.size > 2_000_000:
            break
        idx = np.flatnonzero(bad)
        lo, hi = w[idx], w[idx + 1]
        mid = np.where(lo > 0, np.sqrt(lo * np.maximum(hi, lo)), 0.5 * (lo + hi))
        mid = np.where((mid <= lo) | (mid >= hi), 0.5 * (lo + hi), mid)
        w = np.insert(w, idx + 1, mid)
        f = np.insert(f, idx + 1, F(1j * mid))
    return float(np.sum(np.angle(f[1:] / f[:-1]))), float(np.min(np.abs(f)))


def _indentation_phase(F: _ReturnDifference, center: float, radius: float) -> float:
    """Phase change of F along the right half-circle around j*center, upward."""
    phi = np.linspace(-np.pi / 2, np.pi / 2, 721)
    f = F(1j * center + radius * np.exp(1j * phi))
    return float(np.sum(np.angle(f[1:] / f[:-1])))


def closed_loop_stability(num: np.ndarray, den: np.ndarray, delay: float = 0.0, floor: float = 0.0) -> StabilityResult:
    """Decide closed-loop stability of unity negative feedback around ``L = num/den * exp(-delay s)``.

    With ``floor > 0`` a loop is stable only if every closed-loop root has ``Re s < -floor`` (the same count
    on the loop shifted by ``floor``: ``num(s - f) e^{f delay} / den(s - f)``); see :func:`stability_floor`.

    Parameters
    ----------
    num, den : ndarray
        Loop numerator and denominator (descending powers of ``s``).
    delay : float
        Loop delay in seconds.

    Returns
    -------
    StabilityResult

    Raises
    ------
    ModelError
        For an improper loop. (A biproper loop with a delay and ``|L(j inf)| >= 1`` is a neutral-type
        loop: not stable, see :attr:`StabilityResult.neutral_gain`.)

    Examples
    --------
    Integrator with a delay, ``L = k exp(-tau s)/s``, is stable iff ``k tau < pi/2``:

    >>> closed_loop_stability(np.array([1.5]), np.array([1.0, 0.0]), delay=1.0).stable
    True
    >>> closed_loop_stability(np.array([1.6]), np.array([1.0, 0.0]), delay=1.0).stable
    False

    ``L = 1e-8/s`` has its closed-loop root at ``s = -1e-8``: not stable with a floor of 1e-6:

    >>> closed_loop_stability(np.array([1e-8]), np.array([1.0, 0.0]), floor=1e-6).describe()[:52]
    'closed loop not stable in practice: 1 root(s) within'
    """
    exact = _count(num, den, delay)
    if floor <= 0.0 or not exact.stable:
        return exact
    try:
        # the shifted poles are told apart from the axis at a thousandth of the floor (absolute tolerances would
        # put an integrator moved by a slow plant's floor back on the axis)
        moved = _count(shifted(num, floor) * np.exp(floor * delay), shifted(den, floor), delay, near=1e-3 * floor)
    except RuntimeError:  # open-loop poles within the floor of the origin: the shifted count cannot be trusted
        return StabilityResult(False, 0, exact.open_loop_unstable_poles, exact.method + "; the count on the loop "
                               "shifted by the stability floor failed (open-loop poles within the floor of the "
                               "origin): not certified stable", None, float(floor))
    if moved.stable:
        return exact
    return StabilityResult(False, moved.unstable_poles, exact.open_loop_unstable_poles, exact.method,
                           None, float(floor))


ROOT_PERTURBATION = 1e-14
"""Relative change of a characteristic polynomial's coefficients by which :func:`root_blur` tests its roots."""

BLUR_DEGREE = 16
"""Least degree of a characteristic polynomial whose roots :func:`root_blur` tests (below it, clustered roots that
rounding could push across the axis need coefficients no plant here has)."""


def root_blur(char: np.ndarray, roots: np.ndarray) -> float | None:
    """How far a relative change of :data:`ROOT_PERTURBATION` in ``char``'s coefficients moves a root whose
    distance from the imaginary axis is no more than twice that move, or None when every root stays put (or the
    degree is below :data:`BLUR_DEGREE`). Expanded coefficients of ``(s + 1)^110`` (up to 1e32) put 14 roots of a
    stable loop in the right half-plane (a black-box test); their positions are that uncertain.

    Examples
    --------
    >>> char = np.poly(-np.ones(110)); char[-1] += 0.3
    >>> root_blur(char, np.roots(char)) is not None
    True
    >>> char = np.poly(-np.arange(1.0, 21.0) / 4)  # 20 distinct poles, 0.25 apart
    >>> root_blur(char, np.roots(char)) is None
    True
    """
    if roots.size < BLUR_DEGREE:
        return None
    worst = None
    for pattern in (np.resize([1.0, -1.0], char.size), np.resize([1.0, 1.0, -1.0], char.size)):
        moved = np.roots(char * (1.0 + ROOT_PERTURBATION * pattern))
        shift = np.min(np.abs(roots[:, None] - moved[None, :]), axis=1)
        blurred = np.abs(roots.real) <= 2.0 * shift
        if np.any(blurred):
            worst = max(worst or 0.0, float(np.max(shift[blurred])))
    return worst


def _count(num: np.ndarray, den: np.ndarray, delay: float, near: float | None = None) -> StabilityResult:
    num, den = trim(np.asarray(num, float)), trim(np.asarray(den, float))
    if num.size > den.size:
        raise ModelError("loop transfer function is improper")
    stripped = den[:max(1, np.flatnonzero(den)[-1] + 1)] if np.any(den) else den  # without poles at the origin
    pole_roots = np.roots(stripped) if stripped.size > 1 else np.zeros(0, complex)
    n_rhp, n_origin, axis = _axis_poles(den, near, pole_roots)
    shared_origin = 0
    while shared_origin < min(num.size, den.size) - 1 and num[-1 - shared_origin] == 0.0 \
            and den[-1 - shared_origin] == 0.0:
        shared_origin += 1
    if delay > 0.0 and shared_origin and np.any(num):
        # a pole at s = 0 cancelled by a zero: den(0) + num(0) exp(0) = 0, a closed-loop root at the origin
        return StabilityResult(False, shared_origin, n_rhp, "Nyquist argument principle, exact delay", 0.0)
    if delay <= 0.0 or not np.any(num):  # no loop (L = 0): the closed loop keeps the open-loop poles
        char = np.polyadd(den, num)
        if char.size < den.size or char[0] == 0.0:  # L(j inf) = -1: a closed-loop root at infinity (a gain's edge)
            return StabilityResult(False, 1, n_rhp, "polynomial roots; 1 + L(j inf) = 0, a closed-loop root at "
                                   "infinity")
        roots = np.roots(trim(char))
        tol = 1e-9 * np.maximum(1.0, np.abs(roots))
        n_bad = int(np.sum(roots.real >= -tol))
        marginal = roots[np.abs(roots.real) < tol]
        blur = root_blur(trim(char), roots)
        if blur is not None:
            return StabilityResult(False, max(n_bad, 1), n_rhp, f"not counted: the characteristic polynomial of "
                                   f"degree {roots.size} places its roots only to {blur:.2g} rad/s (a relative change "
                                   f"of {ROOT_PERTURBATION:g} in its coefficients moves a root that far, as far as it "
                                   "is from the imaginary axis): not certified stable")
        return StabilityResult(
            n_bad == 0, n_bad, n_rhp, "polynomial roots",
            float(np.abs(marginal[0].imag)) if marginal.size else None,
        )

    if not n_origin and abs(den[-1] + num[-1]) <= 1e-12 * max(abs(den[-1]), abs(num[-1])):
        # 1 + L(0) = 0: a closed-loop root at s = 0 (e.g. a gain on the edge of the stability floor)
        return StabilityResult(False, 1, n_rhp, "Nyquist argument principle, exact delay", 0.0)
    c_inf = value_at_infinity(num, den)
    if neutral_with_any_delay(num, den):  # 1 + c e^{-s delay} -> 0 far out: roots with Re s -> ln|c| / delay >= 0
        return StabilityResult(False, 1, n_rhp, "neutral-type loop: |L(j inf)| >= 1 with a delay",
                               neutral_gain=float(abs(c_inf)))
    level = max(0.5, 0.5 * (1.0 + abs(c_inf)))
    zero_roots = np.roots(num) if num.size > 1 else np.zeros(0, complex)  # the poles' are computed once above
    w_lo_scale, _ = _scale_of_roots([zero_roots, pole_roots], delay)
    w_top = largest_crossing(num, den, level)
    axis_max = max((w for w, _ in axis), default=0.0)
    w_top = max(w_top * 1.05, 2.0 * axis_max, 1e-3 * w_lo_scale)
    if w_top * delay / PHASE_STEP > MAX_PHASE_POINTS:  # not counted: not certified stable (at least one root)
        return StabilityResult(False, 1, n_rhp, f"not counted: the delay of {delay:g} s turns the loop's phase "
                               f"{w_top * delay / (2 * np.pi):.3g} times below {w_top:.3g} rad/s, where its gain "
                               f"falls to {level:g}, more than synth resolves "
                               f"({MAX_PHASE_POINTS * PHASE_STEP / (2 * np.pi):.3g} turns): not certified stable")

    F = _ReturnDifference(num, den, delay, np.concatenate([zero_roots, pole_roots]))
    eps0 = 1e-6 * w_lo_scale
    total_half = 0.0
    min_f = np.inf
    start = eps0 if n_origin else 0.0
    for wk, _m in axis:
        eps = 1e-6 * min(w_lo_scale, wk)
        dphi, mf = _segment_phase(F, start, wk - eps, delay)
        total_half += dphi + _indentation_phase(F, wk, eps)
        min_f = min(min_f, mf)
        start = wk + eps
    dphi, mf = _segment_phase(F, start, w_top, delay)
    total_half += dphi
    min_f = min(min_f, mf)
    total_half += -float(np.angle(F(np.array([1j * w_top]))[0]))  # tail: F -> right half-plane
    total = 2.0 * total_half
    if n_origin:
        total += _indentation_phase(F, 0.0, eps0)
    winding = -total / (2.0 * np.pi)
    if not np.isfinite(winding):  # e.g. 1/(s+1)^400: (j w)^400 overflows beyond 6 rad/s
        raise ModelError(f"cannot count the closed loop's poles: its frequency response overflows floating point "
                         f"(loop polynomials of degree {max(len(num), len(den)) - 1})")
    n_closed = round(winding) + n_rhp
    if abs(winding - round(winding)) > 0.1 or n_closed < 0:
        raise RuntimeError(f"Nyquist count failed to converge (winding {winding:.3f})")
    marginal = None
    if min_f < 1e-9:
        marginal = _marginal_frequency(F, w_top)
    stable = n_closed == 0 and marginal is None
    return StabilityResult(stable, n_closed, n_rhp, "Nyquist argument principle, exact delay", marginal)


def _marginal_frequency(F: _ReturnDifference, w_top: float) -> float:
    w = np.geomspace(1e-6 * w_top, w_top, 20000)
    return float(w[np.argmin(np.abs(F(1j * w)))])


# --------------------------------------------------------------------------- D-decomposition
Rational = tuple[np.ndarray, np.ndarray]
