"""Convex constraints for each requirement around the current design (convex-concave procedure).

With a parametrization in which ``C = X/D`` and ``L = N/D`` (``N = G X``) are
ratios of quantities affine in ``rho`` (see :mod:`.parametrization`), every
magnitude requirement reads ``|U(rho)| <= kappa |V(rho)|`` with ``U, V``
affine. Around the current design ``rho_c`` with ``V_c = V(rho_c)``,

    Re{V(rho) conj(V_c)} / |V_c|  <=  |V(rho)|

is a linear lower bound, tight at ``rho_c`` (Hast, Astrom, Bernhardsson, Boyd
2013; for ``C = X/D``: Karimi and Kammer 2017). Replacing ``|V|`` by it gives a
second-order cone that is an *inner* approximation: whatever satisfies it
satisfies the true requirement.

=====================  =========  =========  ===================
requirement            U          V          kappa
=====================  =========  =========  ===================
|S| <= m               D          D + N      m
|T| <= M               N          D + N      M
|KS| <= M              X          D + N      M
slew rate              X          D          B / (De w)
static sensitivity     D(0)       D(0)+gX(0) m
bandwidth >= wb        D + N      N          1 / (l T0), w <= wb
bandwidth <= wb        N          D + N      l T0, at wb
crossover >= wc        D          N          1, w <= wc
stability kept         D          D + N      1 / delta
=====================  =========  =========  ===================

For linear parametrizations (``D = 1``) the slew-rate cone is exact and
``|S|`` bounds are linear. Gain and phase margins become a half-plane in the
Nyquist plane near crossover (linear parametrizations only; for rational
controllers the NLP stage enforces margins). Every bound is tightened by
:data:`BACKOFF` (1e-4 relative) so that a design that is tight on the grid
still meets the exact requirement between grid points. Every form takes an
elastic slack ``s >= 0`` in relative units (the constraint reads
``|U|/(kappa |V|) <= 1 + s`` at the linearization point), used to diagnose
infeasible specs. Constants that change with ``rho_c`` are cvxpy Parameters,
so the problem is built once and only their values change between solves.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.loop import BANDWIDTH_LEVEL
from synth.plant import Plant
from synth.polynomials import dc_value, polymul
from synth.requirements.base import magnitude
from synth.synthesis.cvxpy_loader import cp
from synth.synthesis.parametrization import Affine, Parametrization

__all__ = [
    "BACKOFF",
    "LOWER_SECTOR",
    "T0",
    "Form",
    "HalfPlane",
    "Kappa",
    "Points",
    "RatioBound",
    "bandwidth_floor",
    "make_points",
    "sensitivity_form",
    "without_implied",
]

BACKOFF = 1e-4
"""Relative tightening of every convex bound (about 0.001 dB)."""


@dataclass
class Points:
    """Frequency points of one form on every plant, with the loop's affine parts there."""

    w: np.ndarray  # (n,)
    plant_index: np.ndarray  # (n,)
    N: Affine  # loop numerator G X
    D: Affine  # controller denominator
    X: Affine  # controller numerator

    @property
    def n(self) -> int:
        return self.w.size

    @property
    def P(self) -> Affine:
        """``D + N`` (the return difference times D)."""
        return self.D + self.N


def make_points(plants: list[Plant], par: Parametrization, w: np.ndarray,
                gains: list[complex] | None = None) -> Points:
    """Stack the frequencies ``w`` over every plant (``gains`` replaces the plant response, e.g. by a
    stated static gain). Frequencies where the controller is infinite (``w = 0`` with an integrator,
    where ``|1 + L|`` is infinite too) are left out."""
    w = np.asarray(w, dtype=float)
    X, D = par.numerator(w), par.denominator(w)
    finite = np.all(np.isfinite(X.Q), axis=1) & np.isfinite(X.q0) & (
        np.abs(D.q0) + np.sum(np.abs(D.Q), axis=1) > 0)
    w, X, D = w[finite], X.rows(finite), D.rows(finite)
    Ns, Ds, Xs, idx, ws = [], [], [], [], []
    for i, plant in enumerate(plants):
        G = plant.freqresp(w) if gains is None else np.full(w.size, gains[i], complex)
        Ns.append(X.scaled(G))
        Ds.append(D)
        Xs.append(X)
        idx.append(np.full(w.size, i))
        ws.append(w)

    def stack(parts: list[Affine]) -> Affine:
        return Affine(np.concatenate([p.q0 for p in parts]), np.concatenate([p.Q for p in parts]))

    return Points(np.concatenate(ws), np.concatenate(idx), stack(Ns), stack(Ds), stack(Xs))


class Form:
    """Base class: convex constraints of one requirement around the current design."""

    name: str = ""
    elastic = True

    def constraints(self, rho: cp.Variable, slack: Any) -> list[cp.Constraint]:  # pragma: no cover
        raise NotImplementedError

    def update(self, rho_c: np.ndarray) -> None:
        """Refresh parameters at the current design ``rho_c``."""

    def violation(self, rho: np.ndarray) -> float:
        """Largest relative violation of the exact (not linearized) constraint on this form's points;
        ``<= 0`` when met."""
        return -np.inf

    def price(self) -> float:
        """Dual price after an elastic solve: the rate at which the total violation would fall per
        unit relative relaxation of this requirement."""
        total = 0.0
        for c in getattr(self, "_cons", []):
            if c.dual_value is not None:
                total += float(np.sum(np.abs(c.dual_value)))
        return total


Kappa = Callable[[np.ndarray], np.ndarray]


class RatioBound(Form):
    """``|U(rho)| <= kappa |V(rho)|`` at every point, as ``|U|/(kappa |V_c|) <= Re{V conj(V_c)}/|V_c|^2 + s``.

    ``kappa`` is a number, an array over the points, or a function of ``rho_c``
    returning such an array (when it depends on the design, e.g. ``T0``).
    ``active`` (a function of ``rho_c`` returning a boolean mask) switches rows
    off; an inactive row reads ``0 <= 1 + s``.
    """

    def __init__(self, name: str, U: Affine, V: Affine, kappa: float | np.ndarray | Kappa, n_rho: int,
                 elastic: bool = True, active: Callable[[np.ndarray], np.ndarray] | None = None) -> None:
        self.name, self.U, self.V, self.elastic = name, U, V, elastic
        self.kappa = kappa
        self.active = active
        self.switchable = active is not None or callable(kappa)  # rows can be off (inactive, or infinite kappa)
        n = U.q0.size
        # |U| is built from constants; only the right-hand side changes with the design (small DPP tensor):
        #   |U(rho)| <= on * kappa |V_c| (Re{V conj V_c}/|V_c|^2 + s)  =  R rho + c + w s
        self.Ure, self.Uim = np.real(U.Q), np.imag(U.Q)
        self.u0re, self.u0im = np.real(U.q0), np.imag(U.q0)
        self.constant = not np.any(U.Q)  # |U| a number at each point (|S| bounds of a linear parametrization)
        self.on = cp.Parameter(n, nonneg=True)
        self.R, self.c = cp.Parameter((n, n_rho)), cp.Parameter(n)
        self.w = cp.Parameter(n, nonneg=True)

    def _kappa(self, rho: np.ndarray) -> np.ndarray:
        k = self.kappa(rho) if callable(self.kappa) else self.kappa
        return np.broadcast_to(np.asarray(k, float), self.U.q0.shape)

    def constraints(self, rho, slack):
        """One second-order cone per point, written as ``cp.SOC(rhs, [Re U; Im U])`` (no epigraph
        variable per point), or one linear row per point where ``|U|`` does not depend on ``rho``.

        Parameters scale expressions through ``cp.diag(p) @ e``: cvxpy's DPP compilation of
        ``cp.multiply(p, e)`` grows with the square of the number of points, ``diag`` linearly."""
        n = self.U.q0.size
        rhs = self.R @ rho + self.c
        if self.elastic and not (isinstance(slack, (int, float)) and slack == 0):
            rhs = rhs + cp.diag(self.w) @ (np.ones(n) * slack)
        if self.constant:
            lhs = np.abs(self.U.q0) if not self.switchable else cp.diag(self.on) @ np.abs(self.U.q0)
            self._cons = [lhs <= rhs]
        else:
            parts = cp.vstack([self.Ure @ rho + self.u0re, self.Uim @ rho + self.u0im])
            if self.switchable:
                parts = parts @ cp.diag(self.on)
            self._cons = [cp.SOC(rhs, parts, axis=0)]
        return self._cons

    def update(self, rho_c):
        Vc = self.V(rho_c)
        mag = np.maximum(np.abs(Vc), 1e-300)
        on = np.ones(mag.size, bool) if self.active is None else self.active(rho_c)
        kappa = self._kappa(rho_c)
        on = on & np.isfinite(kappa)  # an infinite kappa bounds nothing (e.g. |T| >= l T0 / 0 where T(0) = 0)
        with np.errstate(all="ignore"):
            scale = np.where(on, kappa / mag, 0.0)  # kappa |V_c| / |V_c|^2
            R = np.real(np.conj(Vc)[:, None] * self.V.Q) * scale[:, None]
            c = np.real(np.conj(Vc) * self.V.q0) * scale
        on = on & np.all(np.isfinite(R), axis=1) & np.isfinite(c)  # V infinite at a pole on the grid: no bound
        self.on.value = on.astype(float)
        self.R.value = np.where(on[:, None], R, 0.0)
        self.c.value = np.where(on, c, 1.0)
        self.w.value = np.where(on, kappa * mag, 1.0)

    def price(self) -> float:
        """Dual price in relative units: duals times the slack's weight in each row."""
        total = 0.0
        for c in getattr(self, "_cons", []):
            dual = c.dual_value
            if isinstance(dual, list):  # a cone: the multiplier of its right-hand side
                dual = dual[0]
            if dual is not None and self.w.value is not None:
                total += float(np.sum(np.abs(dual) * self.w.value))
        return total

    def violation(self, rho):
        if self.U.q0.size == 0:
            return -np.inf
        ratio = np.abs(self.U(rho)) / (self._kappa(rho) * np.maximum(np.abs(self.V(rho)), 1e-300))
        if self.active is not None:
            on = self.active(rho)
            if not np.any(on):
                return -np.inf
            ratio = ratio[on]
        return float(np.max(ratio - 1.0))

    def set_level(self, level: float) -> None:
        """Move a level used by ``kappa``/``active`` (objectives bisect on it)."""
        self.level = level


LOWER_SECTOR = float(np.tan(np.radians(10.0)))
"""Half-width (as ``|Im L| / |Re L|``) of the sector about the negative real axis where :class:`HalfPlane` holds
``|L| >= g`` (the lower gain limit)."""


class HalfPlane(Form):
    """Gain and phase margins: ``L(jw)`` stays in a half-plane that excludes ``-1`` (near crossover), and,
    when the loop has a lower gain limit, outside the circle of radius ``g`` where it passes left of ``-1``.

    The boundary passes through ``-1/g`` and ``exp(j(-180 + phi))``; if that
    line would not protect the phase margin, the vertical line through the
    phase-margin point is used. Applied where ``0.1 <= |L_c| <= 10``. Linear
    parametrizations only (``D = 1``).

    The lower gain limit (``lower=True``, set when a plant is open-loop unstable and a gain margin is
    asked for; a conditionally stable loop of a stable plant is kept out by the half-plane): when the current
    design's Nyquist curve crosses the negative real axis outside the unit circle, the rows with
    ``|L_c| > 1`` within 10 degrees of the negative real axis get ``|L| >= g``, linearized as
    ``Re{L conj(L_c)}/|L_c| >= g`` (an inner approximation, tight at ``L_c``), and the half-plane then
    applies only where ``0.1 <= |L_c| <= 1`` (the curve must be free to encircle ``-1``). Neither part is
    exact: which rows carry which bound follows the current design, and the certificate decides.
    """

    def __init__(self, name: str, points: Points, n_rho: int, gm_db: float | None, pm_deg: float | None,
                 lower: bool = True) -> None:
        self.name, self.points = name, points
        p2 = np.exp(1j * np.radians(-180.0 + pm_deg)) if pm_deg is not None else None
        p1 = -1.0 / magnitude(gm_db) if gm_db is not None else None
        self.g_low = magnitude(gm_db) if gm_db is not None and lower else None
        if p2 is not None and (p1 is None or -p1 >= -p2.real):
            anchor, normal = p2, 1.0 + 0j  # vertical line Re L >= Re p2
        elif p2 is None:
            anchor, normal = p1 + 0j, 1.0 + 0j  # Re L >= -1/g
        else:
            d = p2 - p1
            normal = -1j * d / abs(d)
            if np.real(np.conj(normal) * (-1.0 - p1)) > 0:
                normal = -normal  # -1 must be on the excluded side
            anchor = p1 + 0j
        self.anchor, self.normal = anchor, normal
        self.H = cp.Parameter((points.n, n_rho))
        self.h = cp.Parameter(points.n)
        self.H2 = cp.Parameter((points.n, n_rho))
        self.h2 = cp.Parameter(points.n)

    def constraints(self, rho, slack):
        self._cons = [self.H @ rho - self.h >= -slack]
        if self.g_low is not None:  # without a lower limit the problem is the half-plane's alone
            self._cons.append(self.H2 @ rho - self.h2 >= -slack)
        return self._cons

    def masks(self, L: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(half-plane rows, lower-limit rows) at the design whose loop is ``L``."""
        mag = np.abs(L)
        sector = (mag > 1.0) & (np.real(L) < 0) & (np.abs(np.imag(L)) <= -LOWER_SECTOR * np.real(L))
        lower = np.zeros(L.size, bool)
        if self.g_low is not None and np.any(sector):
            same = self.points.plant_index[1:] == self.points.plant_index[:-1]
            flips = same & (np.sign(np.imag(L[1:])) != np.sign(np.imag(L[:-1]))) & sector[1:] & sector[:-1]
            first = np.concatenate([[True], ~same])  # each plant's lowest frequency: a crossing at w = 0
            on_axis = sector & first & (np.abs(np.imag(L)) <= 0.02 * mag)
            if np.any(flips) or np.any(on_axis):
                lower = sector
        upper = (mag >= 0.1) & (mag <= (1.0 if np.any(lower) else 10.0)) & ~lower
        return upper, lower

    def violation(self, rho):
        L = self.points.N(rho)
        upper, lower = self.masks(L)
        parts = [-np.inf]
        if np.any(upper):
            parts.append(float(np.max(-np.real(np.conj(self.normal) * (L[upper] - self.anchor)))))
        if np.any(lower):
            parts.append(float(np.max(1.0 - np.abs(L[lower]) / self.g_low)))
        return max(parts)

    def update(self, rho_c):
        Lc = self.points.N(rho_c)
        upper, lower = self.masks(Lc)
        nbar = np.conj(self.normal)
        up = upper.astype(float)
        self.H.value = up[:, None] * np.real(nbar * self.points.N.Q)
        self.h.value = up * np.real(nbar * (self.anchor - self.points.N.q0))
        # Re{L conj(L_c)}/|L_c| >= g on the lower rows (L = N, affine in rho)
        u = np.where(lower, np.conj(Lc) / np.maximum(np.abs(Lc), 1e-300), 0.0)
        g = self.g_low if self.g_low is not None else 0.0
        self.H2.value = np.real(u[:, None] * self.points.N.Q)
        self.h2.value = np.where(lower, g - np.real(u * self.points.N.q0), 0.0)


class T0:
    """``|T(0)|`` per plant at a design (1 with integral action; the exact limit where a controller zero at
    the origin meets a plant integrator)."""

    def __init__(self, plants: list[Plant], par: Parametrization) -> None:
        self.plants = plants
        self.par = par

    def value(self, rho: np.ndarray, plant_index: np.ndarray) -> np.ndarray:
        cn, cd = self.par.controller(rho).tf()
        l0 = np.array([dc_value(polymul(cn, p.num), polymul(cd, p.den)) for p in self.plants])
        with np.errstate(divide="ignore", invalid="ignore"):
            t0 = np.where(np.isinf(l0), 1.0, np.abs(l0 / (1.0 + l0)))
        return t0[plant_index]


def sensitivity_form(name: str, pts: Points, n_rho: int, m: float, elastic: bool = True) -> RatioBound:
    """``|S| <= m`` (the form keeps its points and bound in ``sensitivity``)."""
    form = RatioBound(name, pts.D, pts.P, m, n_rho, elastic)
    form.sensitivity = (pts, float(m))
    return form


def without_implied(forms: list[Form], n_rho: int) -> list[Form]:
    """The forms for a problem without elastic slacks, with the stability-keeping rows that another
    ``|S|`` bound implies dropped.

    Without slack, ``|D| <= m Re{P conj P_c}/|P_c|`` at a point implies the same row with any larger
    bound, so the last form (``|S| <= 1/stability_level`` on the design grid) adds nothing where a
    sensitivity requirement with a smaller bound holds on the same plant and frequency (a peak |S|
    requirement covers the whole design grid): the feasible set is unchanged, the cone program smaller.
    """
    keep = forms[-1]
    if not hasattr(keep, "sensitivity") or keep.elastic:
        return forms
    pts, level = keep.sensitivity
    covered: set[tuple[int, float]] = set()
    for f in forms[:-1]:
        if hasattr(f, "sensitivity") and f.active is None and f.sensitivity[1] <= level:
            fp = f.sensitivity[0]
            covered.update(zip(fp.plant_index.tolist(), fp.w.tolist()))
    if not covered:
        return forms
    mask = np.array([(i, w) not in covered for i, w in zip(pts.plant_index.tolist(), pts.w.tolist())], bool)
    if mask.all():
        return forms
    rest = Points(pts.w[mask], pts.plant_index[mask], pts.N.rows(mask), pts.D.rows(mask), pts.X.rows(mask))
    return [*forms[:-1], sensitivity_form(keep.name, rest, n_rho, level, elastic=False)]


def bandwidth_floor(name: str, pts: Points, n_rho: int, t0: T0 | None, tighten: float = 1.0,
                    below: Callable[[], float] | None = None) -> RatioBound:
    """``|T| >= l T0`` (or ``|L| >= 1`` with ``t0=None``: a crossover floor) at the points, or only
    below the frequency returned by ``below()``."""
    if t0 is None:
        U, V, kappa = pts.D, pts.N, tighten
    else:
        U, V = pts.P, pts.N

        def kappa(rho: np.ndarray) -> np.ndarray:
            return tighten / (BANDWIDTH_LEVEL * t0.value(rho, pts.plant_index))
    active = None if below is None else (lambda rho: pts.w <= below())
    return RatioBound(name, U, V, kappa, n_rho, active=active)
