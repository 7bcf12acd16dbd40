"""Whether any controller in a box of two gains stabilizes the loop: the D-decomposition of the plane.

A controller affine in its two free parameters, ``C = C0 + x C1 + y C2`` (a PI's ``kp`` and ``ki``, two gains of a
PID), puts a closed-loop root on the imaginary axis where ``x`` and ``y`` solve the real and the imaginary part of
``1 + C G = 0`` at ``s = j w``: a curve ``(x(w), y(w))``, and the line where a real root passes ``s = 0``. The
count of right-half-plane roots is the same everywhere in each region these boundaries cut the plane into. A
region's leftmost and rightmost points lie where a boundary turns back in ``x``, where two boundaries cross, or
where a boundary meets the box's edges: between two neighbouring such values of ``x`` every column of the box
meets the same regions in the same order. The exact stabilizing set of ``y`` in one column of each strip
(:func:`synth.synthesis.gainset.stability_set`, the one-parameter D-decomposition) therefore decides the whole
box: it returns a stabilizing controller from the first strip that holds one, or shows that none does. The lines
where a gain is 0 are decided apart (there the controller's form changes: a PI with ``ki = 0`` is a P controller).

Stability is counted as everywhere in synth: every root left of the stability floor
(:func:`synth.stability.stability_floor`), so the curves are those of the loop shifted by that floor. They are
sampled on a log grid, around every lightly damped root of the loop's polynomials and at every extremum of either
coordinate, then refined until every chord near the box is shorter than :data:`CHORD` of it and its middle sample
strays from it by less than that; the turning points and crossings are refined on the curve. The proof rests on
that sampling: an excursion of a curve into the box between two samples that are both far from it, with no
extremum and no middle sample seen near it, is not resolved. Only strictly proper loops are decided here (a
biproper loop's roots can also come in from infinity).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from synth.controllers import Controller
from synth.errors import NoStabilizingControllerError
from synth.loop import Loop
from synth.plant import Plant
from synth.polynomials import largest_crossing, shifted, trim
from synth.rootfind import bisect_roots
from synth.stability import MAX_PHASE_POINTS, PHASE_STEP, characteristic_scale, stability_floor
from synth.synthesis.chord_crossings import CHORD, chord_crossings, line_crossings
from synth.synthesis.gainset import ScalarFamily, stability_set
from synth.synthesis.intervals import interval_middle
from synth.synthesis.parametrization import Parametrization

__all__ = ["CHORD", "MAX_POINTS", "MAX_STRIPS", "PlaneSearch", "plane_search", "plane_starts"]

MAX_STRIPS = 600
"""Most strips decided (each a one-parameter D-decomposition); a box cut into more is left undecided."""

_NEAR = 0.02  # how far outside the box (as a share of it) a boundary's features still count
MAX_POINTS = 200_000
"""Most samples of one plant's boundary curve: a curve that needs more (a delay's phase turning thousands of times
where the box's gains still reach the axis) is left undecided."""


@dataclass(frozen=True)
class PlaneSearch:
    """What :func:`plane_search` found: a stabilizing controller's two parameters (None when the box holds none),
    the number of strips decided, and a sentence saying what the answer rests on."""

    start: dict[str, float] | None
    strips: int
    text: str


def plane_search(ctype: str, names: tuple[str, str], fixed: dict[str, float], plants: list[Plant],
                 boxes: tuple[tuple[float, float], tuple[float, float]]) -> PlaneSearch | None:
    """A controller in the box ``boxes`` of the free parameters ``names`` (the others ``fixed``) that stabilizes
    the loop on every plant, or the proof that there is none (see the module docstring). None when the plane
    is not decided here: the controller is not affine in both parameters, a loop is not strictly proper, the
    delay turns the phase too often, or the box is cut into more than :data:`MAX_STRIPS` strips.

    Examples
    --------
    ``1/(s-1)`` under PI needs ``kp > 1``: none in ``kp <= 0.9``, one as soon as the box reaches past 1

    >>> G = Plant.from_string("1/(s-1)")
    >>> plane_search("PI", ("kp", "ki"), {}, [G], ((0.0, 0.9), (0.0, 5.0))).start is None
    True
    >>> found = plane_search("PI", ("kp", "ki"), {}, [G], ((0.0, 1.2), (0.0, 5.0))).start
    >>> found["kp"] > 1.0 and found["ki"] >= 0.0  # on the line ki = 0 the PI is the P controller kp
    True
    """
    (xn, yn), ((x_lo, x_hi), (y_lo, y_hi)) = names, boxes
    if not (x_lo < x_hi and y_lo < y_hi and np.all(np.isfinite([x_lo, x_hi, y_lo, y_hi]))):
        return None
    parts = _affine_parts(ctype, names, fixed, boxes)
    if parts is None:
        return None
    box = np.array([[x_lo, x_hi], [y_lo, y_hi]], float)
    events: list[np.ndarray] = [np.array([0.0, 1.0])]
    segments: list[np.ndarray] = []
    curves: list[_Curve] = []  # the curve of each piece of ``segments``
    lines: list[np.ndarray] = []
    for plant in plants:
        found = _boundaries(parts, plant, box)
        if found is None:
            return None
        curve, curve_events, pieces, line = found
        events.append(curve_events)
        segments.extend(pieces)
        curves.extend([curve] * len(pieces))
        if line is not None:
            lines.append(line)
    events.append(chord_crossings(segments, curves))
    events.append(line_crossings(lines, segments))
    cuts = np.unique(np.clip(np.concatenate(events), 0.0, 1.0))
    cuts = cuts[np.concatenate([[True], np.diff(cuts) > 1e-12])]
    if cuts.size - 1 > MAX_STRIPS:
        return None
    on_zero = _zero_lines(ctype, names, fixed, plants, boxes)
    if on_zero is not None:  # a start, or a line the check could not settle: no proof either way
        return on_zero if on_zero.start is not None else None
    middles = x_lo + (x_hi - x_lo) * 0.5 * (cuts[:-1] + cuts[1:])
    widths = np.diff(cuts)
    for k in np.argsort(-widths):  # the widest strips first: a stabilizing region is found soonest there
        x = float(middles[k])
        try:
            intervals = stability_set(ScalarFamily(ctype, yn, {**fixed, xn: x}), plants, y_lo, y_hi)
        except (ArithmeticError, ValueError, RuntimeError):
            return None
        start = _stable_point(ctype, fixed, plants, {xn: x}, yn, intervals)
        if start is not None:
            return PlaneSearch(start, int(widths.size), f"found in strip {k + 1} of {widths.size}")
        if intervals:  # stabilizing values the loop's own count did not confirm: no proof either way
            return None
    strips = f"{widths.size} strips" if widths.size > 1 else "one strip"
    return PlaneSearch(None, int(widths.size),
                       f"the D-decomposition of the {xn}-{yn} box: the boundaries' turning points and crossings cut it "
                       f"into {strips}, and in one column of each the exact stabilizing set of {yn} is empty")


def _zero_lines(ctype: str, names: tuple[str, str], fixed: dict[str, float], plants: list[Plant],
                boxes: tuple[tuple[float, float], tuple[float, float]]) -> PlaneSearch | None:
    """A stabilizing controller on a line where one gain is 0, when the box holds such a line and one (a search
    without a start when a line's set could not be computed or confirmed; None when the lines hold none): there the
    controller's form changes (a PI with ``ki = 0`` is ``kp``, its pole at 0 cancelled; a PID with ``kd = 0`` loses
    its filter's pole), so the loop is not the plane's affine family and its one-parameter set is computed apart."""
    for k, (lo, hi) in enumerate(boxes):
        if not lo <= 0.0 <= hi:
            continue
        other, (o_lo, o_hi) = names[1 - k], boxes[1 - k]
        undecided = PlaneSearch(None, 0, f"the line {names[k]} = 0 not decided")
        try:
            intervals = stability_set(ScalarFamily(ctype, other, {**fixed, names[k]: 0.0}), plants, o_lo, o_hi)
        except (ArithmeticError, ValueError, RuntimeError):
            return undecided
        start = _stable_point(ctype, fixed, plants, {names[k]: 0.0}, other, intervals)
        if start is not None:
            return PlaneSearch(start, 0, f"found on the line {names[k]} = 0")
        if intervals:
            return undecided
    return None


def _stable_point(ctype: str, fixed: dict[str, float], plants: list[Plant], line: dict[str, float], name: str,
                  intervals: list[tuple[float, float]]) -> dict[str, float] | None:
    """A point of the stabilizing ``intervals`` of ``name`` on ``line`` that the loop's own count confirms stable
    on every plant: each interval's middle, else points nearer its ends (the middle can be where the controller
    vanishes, ``0 / s``, whose pole at the origin the count keeps)."""
    for a, b in intervals:
        for value in (interval_middle(a, b), *(a + f * (b - a) for f in (0.25, 0.75, 0.1, 0.9))):
            start = {**line, name: float(value)}
            c = Controller(ctype, {**fixed, **start})
            if all(Loop(p, c).stability().stable for p in plants):
                return start
    return None


def plane_starts(par: Parametrization, plants: list[Plant], found: Callable[[], bool]) -> Iterator[np.ndarray]:
    """For a PI or a PID with two free gains, and only when ``found()`` says no start was found before: the
    stabilizing controller :func:`plane_search` finds in the bounds (as the convex stage's ``rho``), or
    :class:`~synth.errors.NoStabilizingControllerError` when it shows there is none. Nothing when the plane is
    not decided.

    Examples
    --------
    >>> from synth.synthesis.parametrization import parametrize
    >>> par = parametrize("PI", {"kp": (0.0, 0.9), "ki": (0.0, 5.0)})
    >>> next(plane_starts(par, [Plant.from_string("1/(s-1)")], lambda: False))
    Traceback (most recent call last):
    ...
    synth.errors.NoStabilizingControllerError: controller: no controller in the bounds stabilizes the loop: ...
    """
    if found() or par.ctype not in ("PI", "PID") or len(par.names) != 2:
        return
    lo, hi = par.box()
    names = (par.names[0], par.names[1])
    result = plane_search(par.ctype, names, dict(par.fixed), plants,
                          ((float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1]))))
    if result is None:
        return
    if result.start is None:
        raise NoStabilizingControllerError(f"no controller in the bounds stabilizes the loop: {result.text}",
                                           where="controller", searched=result.text, proof=result.text)
    yield np.array([result.start[n] for n in names])


# ------------------------------------------------------------------ the controller's parts


def _affine_parts(ctype: str, names: tuple[str, str], fixed: dict[str, float],
                  boxes: tuple[tuple[float, float], tuple[float, float]]) -> tuple[np.ndarray, ...] | None:
    """``(d, n0, n1, n2)`` with ``C = (n0 + x n1 + y n2) / d`` on the box (same length, highest power first),
    or None when the controller is not of that form."""
    (x_lo, x_hi), (y_lo, y_hi) = boxes
    # points inside the box, none at a round fraction (at a zero gain a transfer function's form can change)
    unit = np.array([[0.2871, 0.3419], [0.6213, 0.4137], [0.9137, 0.8713], [0.4471, 0.1297]])
    pts = np.column_stack([x_lo + (x_hi - x_lo) * unit[:, 0], y_lo + (y_hi - y_lo) * unit[:, 1]])
    try:
        tfs = [Controller(ctype, {**fixed, names[0]: float(x), names[1]: float(y)}).tf() for x, y in pts]
    except Exception:
        return None
    width = max(max(n.size, d.size) for n, d in tfs)
    nums = np.array([np.pad(n, (width - n.size, 0)) for n, _ in tfs])
    dens = np.array([np.pad(d, (width - d.size, 0)) for _, d in tfs])
    if not np.allclose(dens, dens[0], rtol=1e-12, atol=0.0):
        return None
    design = np.column_stack([np.ones(3), pts[:3]])
    try:
        coef = np.linalg.solve(design, nums[:3])  # rows n0, n1, n2
    except np.linalg.LinAlgError:
        return None
    scale = float(np.max(np.abs(nums)))
    check = coef[0] + pts[3, 0] * coef[1] + pts[3, 1] * coef[2]
    if not np.allclose(check, nums[3], rtol=1e-9, atol=1e-12 * scale):
        return None
    coef[np.abs(coef) <= 1e-12 * scale] = 0.0  # the solve's rounding: a PI's C0 is 0, not 1e-16 s
    return dens[0], coef[0], coef[1], coef[2]


# ------------------------------------------------------------------ one plant's boundaries


@dataclass(frozen=True)
class _Curve:
    """``1 + C G = 0`` on the shifted axis ``s = -floor + j w`` solved for ``(x, y)``, scaled to the box."""

    d: np.ndarray
    n: tuple[np.ndarray, np.ndarray, np.ndarray]
    N: np.ndarray
    D: np.ndarray
    delay: float
    box: np.ndarray

    def at(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Scaled ``(u, v)`` at ``w`` and the system's determinant (its sign splits the curve where it passes
        through infinity)."""
        s = 1j * np.asarray(w, float)
        M = np.polyval(self.N, s) * np.exp(-self.delay * s)
        A = np.polyval(self.d, s) * np.polyval(self.D, s) + np.polyval(self.n[0], s) * M
        B1, B2 = np.polyval(self.n[1], s) * M, np.polyval(self.n[2], s) * M
        det = B1.real * B2.imag - B1.imag * B2.real
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            x = (B2.real * A.imag - A.real * B2.imag) / det
            y = (A.real * B1.imag - B1.real * A.imag) / det
        (x_lo, x_hi), (y_lo, y_hi) = self.box
        return (x - x_lo) / (x_hi - x_lo), (y - y_lo) / (y_hi - y_lo), det


def _boundaries(parts: tuple[np.ndarray, ...], plant: Plant, box: np.ndarray,
                ) -> tuple[_Curve, np.ndarray, list[np.ndarray], np.ndarray | None] | None:
    """One plant's boundary curve, its chords near the box (rows ``[w0, u0, v0, w1, u1, v1]``, one array per
    piece), the scaled ``x`` of its turning points, its ends and its crossings of the box's lower and upper
    edges, and the line of a real root at ``s = 0`` (``a u + b v + c = 0`` as ``[a, b, c]``, None if none);
    None when the plane is not decided here."""
    d, n0, n1, n2 = parts
    floor = stability_floor(plant.num, plant.den, plant.delay)
    N = shifted(plant.num, floor) * np.exp(floor * plant.delay)
    D, sd = shifted(plant.den, floor), shifted(d, floor)
    sn = tuple(shifted(p, floor) for p in (n0, n1, n2))
    top = trim(np.polymul(sd, D)).size
    if any(np.any(p) and trim(np.polymul(p, N)).size >= top for p in sn):
        return None  # a biproper loop: roots may come in from infinity
    curve = _Curve(sd, sn, N, D, plant.delay, box)
    w = _frequencies(curve, plant)
    if w is None:
        return None
    u, v, det = curve.at(w)
    refined = _refined(curve, w, u, v, det)
    if refined is None:
        return None
    w, u, v, det = refined
    line = _zero_line(curve)
    events: list[float] = []
    pieces: list[np.ndarray] = []
    ok = np.isfinite(u) & np.isfinite(v) & (det != 0)
    breaks = np.flatnonzero(~ok[:-1] | ~ok[1:] | (np.sign(det[:-1]) != np.sign(det[1:])))
    for lo, hi in zip(np.concatenate([[0], breaks + 1]), np.concatenate([breaks + 1, [w.size]])):
        if hi - lo < 2 or not ok[lo]:
            continue
        pw, pu, pv = w[lo:hi], u[lo:hi], v[lo:hi]
        events += [float(pu[i]) for i in (0, -1) if _inside(pu[i], pv[i])]  # an end within the box
        events += _turning_points(curve, pw, pu, pv)
        for edge in (0.0, 1.0):
            events += _edge_crossings(curve, pw, pu, pv, edge)
        near = _near_segments(pu, pv)
        if np.any(near):
            i = np.flatnonzero(near)
            pieces.append(np.column_stack([pw[i], pu[i], pv[i], pw[i + 1], pu[i + 1], pv[i + 1]]))
    return curve, np.array(events, float), pieces, line


def _frequencies(curve: _Curve, plant: Plant) -> np.ndarray | None:
    """The first samples of the curve: every frequency where ``|C G|`` can reach 1 for some controller in the
    box, log-spaced, and with a delay also spaced by its phase; None when that is beyond synth's phase points."""
    (x_lo, x_hi), (y_lo, y_hi) = curve.box
    gains = (1.0, max(abs(x_lo), abs(x_hi)), max(abs(y_lo), abs(y_hi)))
    dD = np.polymul(curve.d, curve.D)
    tops = [largest_crossing(np.polymul(p, curve.N), dD, 1.0 / (3.0 * g)) for p, g in zip(curve.n, gains)
            if np.any(p) and g > 0]
    lo_scale, hi_scale = characteristic_scale(plant.num, plant.den, *curve.n, curve.d, delay=plant.delay)
    w_max = 1.2 * max([*tops, hi_scale])
    w_min = 1e-4 * lo_scale
    grid = [np.geomspace(w_min, w_max, int(100 * np.log10(w_max / w_min)) + 2)]
    # around every lightly damped root of the loop's polynomials: there the curve can swing out and back within a
    # span of 2 zeta w, narrower than the log grid's steps, with both neighbours far from the box
    for poly in (curve.N, curve.D, curve.d, *curve.n):
        poly = trim(poly)
        if poly.size < 3 or not np.all(np.isfinite(poly)):
            continue
        for r in np.roots(poly):
            w0, spread = abs(r.imag), abs(r.real)
            if w0 > 0 and spread < 0.2 * w0:
                grid.append(np.clip(w0 + max(spread, 1e-9 * w0) * np.linspace(-40.0, 40.0, 401), w_min, None))
    if curve.delay > 0:
        points = int(np.ceil(w_max * curve.delay / PHASE_STEP)) + 2
        if points > min(MAX_PHASE_POINTS, MAX_POINTS // 2):
            return None
        grid.append(np.linspace(0.0, w_max, points)[1:])
    return np.unique(np.concatenate(grid))


def _refined(curve: _Curve, w: np.ndarray, u: np.ndarray, v: np.ndarray, det: np.ndarray,
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """The samples with each chord's middle sample added wherever the chord's ends and that sample come near the box
    and the chord is longer than :data:`CHORD` or the middle strays from it by more than that (None when that
    takes more than :data:`MAX_POINTS`). The middle is looked at for every chord: a curve can leave the chord far
    from the box and swing into it between two samples."""
    extra = _extrema(curve, w, u, v)  # where the curve turns in u or in v: an arc that enters the box between two
    if extra.size:  # samples far from it turns there
        w = np.unique(np.concatenate([w, extra]))
        u, v, det = curve.at(w)
    for _ in range(60):
        mid = 0.5 * (w[:-1] + w[1:])
        mu, mv, mdet = curve.at(mid)
        with np.errstate(invalid="ignore"):
            su, sv = np.stack([u[:-1], u[1:], mu]), np.stack([v[:-1], v[1:], mv])
            near = (su.min(0) <= 1 + _NEAR) & (su.max(0) >= -_NEAR) & (sv.min(0) <= 1 + _NEAR) & (sv.max(0) >= -_NEAR)
            stray = np.hypot(mu - 0.5 * (u[:-1] + u[1:]), mv - 0.5 * (v[:-1] + v[1:]))
            split = near & ((np.hypot(np.diff(u), np.diff(v)) > CHORD) | (stray > CHORD)) \
                & (np.sign(det[:-1]) == np.sign(det[1:])) & (np.sign(mdet) == np.sign(det[:-1]))
        if not np.any(split):
            break
        if w.size + np.count_nonzero(split) > MAX_POINTS:
            return None
        i = np.flatnonzero(split)
        w, u, v, det = (np.insert(a, i + 1, b[i]) for a, b in ((w, mid), (u, mu), (v, mv), (det, mdet)))
    else:
        return None  # still refining: not resolved
    return w, u, v, det


def _extrema(curve: _Curve, w: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The frequencies of the curve's local extrema in ``u`` and in ``v`` between samples (:func:`_golden`)."""
    out = [np.zeros(0)]
    for axis, values in ((0, u), (1, v)):
        dv = np.diff(values)
        with np.errstate(invalid="ignore"):
            k = np.flatnonzero(dv[:-1] * dv[1:] < 0) + 1
        if k.size:
            out.append(_golden(curve, w[k - 1], w[k + 1], np.where(dv[k - 1] > 0, 1.0, -1.0), axis)[0])
    return np.concatenate(out)


def _near_segments(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Which chords ``k -> k + 1`` pass near the box (their bounding box meets it, widened by :data:`_NEAR`)."""
    with np.errstate(invalid="ignore"):
        return (np.minimum(u[:-1], u[1:]) <= 1 + _NEAR) & (np.maximum(u[:-1], u[1:]) >= -_NEAR) \
            & (np.minimum(v[:-1], v[1:]) <= 1 + _NEAR) & (np.maximum(v[:-1], v[1:]) >= -_NEAR)


def _inside(u: float, v: float) -> bool:
    return -_NEAR <= u <= 1 + _NEAR and -_NEAR <= v <= 1 + _NEAR


def _turning_points(curve: _Curve, w: np.ndarray, u: np.ndarray, v: np.ndarray) -> list[float]:
    """The scaled ``x`` of the curve's local extrema in ``x`` near the box (golden-section refined, all at once; a
    piece along which ``x`` stays put to rounding gives its own ``x``)."""
    du = np.diff(u)
    k = np.flatnonzero(du[:-1] * du[1:] < 0) + 1
    k = k[[_inside(u[i], v[i]) for i in k]]
    if k.size == 0:
        return []
    flat = np.maximum(np.abs(du[k - 1]), np.abs(du[k])) <= 1e-12 * np.maximum(1.0, np.abs(u[k]))
    out = u[k[flat]].tolist()
    k = k[~flat]
    sign = np.where(du[k - 1] > 0, 1.0, -1.0)  # a maximum (+1) or a minimum (-1) of u
    _, peak = _golden(curve, w[k - 1], w[k + 1], sign, 0)
    with np.errstate(invalid="ignore"):
        out += (sign * np.fmax(peak, sign * u[k])).tolist()
    return out


def _golden(curve: _Curve, a: np.ndarray, b: np.ndarray, sign: np.ndarray, axis: int,
            ) -> tuple[np.ndarray, np.ndarray]:
    """Golden-section search of ``sign * curve.at(w)[axis]``'s maximum in each ``[a, b]``, all at once: the
    frequencies and the values there."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    g = (np.sqrt(5.0) - 1.0) / 2.0
    c, e = b - g * (b - a), a + g * (b - a)
    fc, fe = sign * curve.at(c)[axis], sign * curve.at(e)[axis]
    for _ in range(60):
        left = fc > fe  # the maximum lies in [a, e]
        a, b = np.where(left, a, c), np.where(left, e, b)
        c, e = np.where(left, b - g * (b - a), e), np.where(left, c, a + g * (b - a))
        fresh = sign * curve.at(np.where(left, c, e))[axis]
        fc, fe = np.where(left, fresh, fe), np.where(left, fc, fresh)
        if np.all(b - a <= 1e-13 * b):
            break
    with np.errstate(invalid="ignore"):
        return 0.5 * (a + b), np.fmax(fc, fe)


def _edge_crossings(curve: _Curve, w: np.ndarray, u: np.ndarray, v: np.ndarray, edge: float) -> list[float]:
    """The scaled ``x`` where the curve crosses the box's edge ``v = edge`` within the box
    (:func:`synth.rootfind.bisect_roots`, all at once)."""
    f = v - edge
    k = np.flatnonzero(f[:-1] * f[1:] < 0)
    k = k[(np.maximum(u[k], u[k + 1]) >= -_NEAR) & (np.minimum(u[k], u[k + 1]) <= 1 + _NEAR)]
    if k.size == 0:
        return []
    return curve.at(bisect_roots(lambda x, _: curve.at(x)[1] - edge, w[k], w[k + 1], indexed=True))[0].tolist()


def _zero_line(curve: _Curve) -> np.ndarray | None:
    """``[a, b, c]`` of the scaled line where a real root sits at the shifted origin (None when none can)."""
    A = float(np.polyval(curve.d, 0.0) * np.polyval(curve.D, 0.0) + np.polyval(curve.n[0], 0.0)
              * np.polyval(curve.N, 0.0))
    B1, B2 = (float(np.polyval(p, 0.0) * np.polyval(curve.N, 0.0)) for p in curve.n[1:])
    (x_lo, x_hi), (y_lo, y_hi) = curve.box
    # A + x B1 + y B2 = 0 with x = x_lo + u (x_hi - x_lo), y = y_lo + v (y_hi - y_lo)
    a, b, c = B1 * (x_hi - x_lo), B2 * (y_hi - y_lo), A + B1 * x_lo + B2 * y_lo
    if a == 0.0 and b == 0.0:
        return None  # no controller moves that root: the columns count it
    return np.array([a, b, c]) / np.hypot(a, b)
