"""Convex constraints for each requirement around the current design (convex-concave procedure).

At frequency ``w`` on plant ``G`` the loop is affine in ``rho``:
``L(rho) = G(jw) phi(jw)^T rho = A rho``. Around the current design
``rho_c`` with ``u = 1 + A rho_c``,

    E(rho) = Re{(1 + A rho) conj(u)} / |u|  <=  |1 + A rho|

is a linear lower bound of ``|1 + L|``, tight at ``rho_c`` (Hast, Astrom,
Bernhardsson, Boyd 2013). Replacing ``|1 + L|`` by ``E`` in a constraint that
needs ``|1 + L|`` large gives a convex *inner* approximation: whatever
satisfies it satisfies the true constraint. Likewise
``Re{L conj(L_c)}/|L_c| <= |L|``.

=====================  ===================================================  ===========
requirement            convex form (per frequency, per plant)               kind
=====================  ===================================================  ===========
sensitivity, peak |S|  E(rho) >= 1/m                                        linear
peak |T| <= M          |A rho| <= M E(rho)                                  SOC
peak |KS| <= M         |phi rho| <= M E(rho)                                SOC
slew rate              |phi rho| <= B / (De w)                              SOC (exact)
static sensitivity     E at w = 0 with G = plant gain                       linear
bandwidth >= wb        l |1 + A rho| <= Re{A rho conj(L_c)}/|L_c|, w <= wb  SOC
bandwidth <= wb        |A rho| <= l E(rho) at wb                            SOC
margins                Re{conj(n) (A rho - p1)} >= 0 near crossover          linear
stability kept         E(rho) >= delta at every frequency                   linear
=====================  ===================================================  ===========

Every bound is tightened by :data:`BACKOFF` (1e-4 relative) so that a design
that is tight on the grid still meets the exact requirement between grid
points. Every form takes an elastic slack ``s >= 0`` (zero in the normal problem)
measured in the same normalized units, used to diagnose infeasible specs.
Constants that change with ``rho_c`` are cvxpy Parameters, so the problem is
compiled once (DPP) and re-solved with new values at each iteration.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import cvxpy as cp
import numpy as np

from synth.freqgrid import band_grid
from synth.loop import BANDWIDTH_LEVEL
from synth.plant import Plant
from synth.requirements import (
    Bandwidth,
    MarginsRequirement,
    PeakComplementary,
    PeakSensitivity,
    Sensitivity,
    SlewRate,
    StaticSensitivity,
)
from synth.requirements.base import Requirement
from synth.requirements.control_sensitivity import PeakControlSensitivity
from synth.synthesis.parametrization import LinearParametrization


@dataclass
class Points:
    """Frequency points of one form on every plant: ``A[i] = G_p(j w_i) phi(j w_i)``."""

    w: np.ndarray          # (n,)
    plant_index: np.ndarray  # (n,)
    A: np.ndarray          # (n, n_rho) complex, loop per unit rho
    phi: np.ndarray        # (n, n_rho) complex, controller per unit rho

    @property
    def n(self) -> int:
        return self.w.size


def make_points(plants: list[Plant], par: LinearParametrization, w: np.ndarray) -> Points:
    """Stack the frequencies ``w`` over every plant.

    Frequencies where the basis is infinite (``w = 0`` with integral action, where
    ``|1 + L|`` is infinite too) are left out.
    """
    w = np.asarray(w, dtype=float)
    phi = par.basis(w)
    finite = np.all(np.isfinite(phi), axis=1)
    w, phi = w[finite], phi[finite]
    A, idx, ws, phis = [], [], [], []
    for i, plant in enumerate(plants):
        G = plant.freqresp(w)
        A.append(G[:, None] * phi)
        idx.append(np.full(w.size, i))
        ws.append(w)
        phis.append(phi)
    return Points(np.concatenate(ws), np.concatenate(idx), np.concatenate(A), np.concatenate(phis))


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

    def slack_coefficient(self) -> Any:
        """How the elastic slack enters each constraint row (1 when it is added as is)."""
        return 1.0

    def price(self) -> float:
        """Dual price of this requirement after an elastic solve: the rate at which the total violation
        would fall per unit relaxation of this requirement (same normalized units for every one)."""
        total = 0.0
        for c in getattr(self, "_cons", []):
            if c.dual_value is not None:
                total += float(np.sum(np.abs(c.dual_value) * self.slack_coefficient()))
        return total


class _Linearization:
    """Parameters of ``E(rho) = c + R rho`` (lower bound of |1 + A rho| scaled by ``scale``)."""

    def __init__(self, points: Points, n_rho: int) -> None:
        self.points = points
        self.R = cp.Parameter((points.n, n_rho))
        self.c = cp.Parameter(points.n)

    def set(self, rho_c: np.ndarray, scale: np.ndarray | float = 1.0) -> np.ndarray:
        u = 1.0 + self.points.A @ rho_c
        mag = np.maximum(np.abs(u), 1e-12)
        self.R.value = (np.real(np.conj(u)[:, None] * self.points.A) / mag[:, None]) * np.reshape(scale, (-1, 1))
        self.c.value = np.real(u) / mag * scale
        return u


class LowerBoundOnReturnDifference(Form):
    """``|1 + L| >= 1/m`` at given points: sensitivity bands, peak |S|, static sensitivity, stability."""

    def __init__(self, name: str, points: Points, n_rho: int, level: float, elastic: bool = True) -> None:
        self.name, self.points, self.level, self.elastic = name, points, level, elastic
        self.lin = _Linearization(points, n_rho)

    def constraints(self, rho, slack):
        e = self.lin.c + self.lin.R @ rho
        self._cons = [e >= self.level * (1 - slack)] if self.elastic else [e >= self.level]
        return self._cons

    def update(self, rho_c):
        self.lin.set(rho_c)

    def violation(self, rho):
        if self.points.n == 0:
            return -np.inf
        return float(np.max(self.level - np.abs(1.0 + self.points.A @ rho)) / self.level)

    def slack_coefficient(self):
        return self.level


class UpperBoundOnRatio(Form):
    """``|N rho| <= M |1 + A rho|`` via ``|N rho| <= M E(rho)``: peak |T| (N = A) and |KS| (N = phi)."""

    def __init__(self, name: str, points: Points, numerator: np.ndarray, n_rho: int, level: float) -> None:
        self.name, self.points, self.level = name, points, level
        self.Nre, self.Nim = np.real(numerator), np.imag(numerator)
        self.lin = _Linearization(points, n_rho)

    def constraints(self, rho, slack):
        mag = cp.norm(cp.vstack([self.Nre @ rho, self.Nim @ rho]), 2, axis=0)
        self._cons = [mag <= self.lin.c + self.lin.R @ rho + slack]
        return self._cons

    def update(self, rho_c):
        self.lin.set(rho_c, scale=self.level)

    def set_level(self, level: float) -> None:
        """Move the bound ``M`` (used when the objective bisects on it)."""
        self.level = level

    def violation(self, rho):
        num = np.abs(np.complex128(self.Nre + 1j * self.Nim) @ rho)
        return float(np.max(num - self.level * np.abs(1.0 + self.points.A @ rho)) / self.level)


class SlewForm(Form):
    """``De |C(jw)| w <= B``: exact second-order cones (no linearization)."""

    def __init__(self, name: str, w: np.ndarray, phi: np.ndarray, limit: np.ndarray) -> None:
        self.name = name
        self.Pre, self.Pim, self.limit = np.real(phi), np.imag(phi), limit

    def constraints(self, rho, slack):
        mag = cp.norm(cp.vstack([self.Pre @ rho, self.Pim @ rho]), 2, axis=0)
        self._cons = [mag <= self.limit * (1 + slack)]
        return self._cons

    def violation(self, rho):
        mag = np.abs((self.Pre + 1j * self.Pim) @ rho)
        return float(np.max((mag - self.limit) / self.limit)) if mag.size else -np.inf

    def slack_coefficient(self):
        return self.limit


class BandwidthFloor(Form):
    """``|T(jw)| >= l T0`` for every ``w <= wb`` via ``l T0 |1 + A rho| <= Re{A rho conj(L_c)}/|L_c|``."""

    def __init__(self, name: str, points: Points, n_rho: int, t0: T0) -> None:
        self.name, self.points, self.t0 = name, points, t0
        self.Q = cp.Parameter((points.n, n_rho))
        self.Are, self.Aim = np.real(points.A), np.imag(points.A)

    def constraints(self, rho, slack):
        mag = cp.norm(cp.vstack([1 + self.Are @ rho, self.Aim @ rho]), 2, axis=0)
        self._cons = [mag <= self.Q @ rho + slack]
        return self._cons

    def update(self, rho_c):
        Lc = self.points.A @ rho_c
        mag = np.maximum(np.abs(Lc), 1e-12)
        level = BANDWIDTH_LEVEL * self.t0.value(rho_c, self.points.plant_index)
        self.Q.value = np.real(np.conj(Lc)[:, None] * self.points.A) / (mag * level)[:, None]

    def violation(self, rho):
        L = self.points.A @ rho
        level = BANDWIDTH_LEVEL * self.t0.value(rho, self.points.plant_index)
        return float(np.max(level * np.abs(1.0 + L) - np.abs(L)))


class MovingFloor(Form):
    """A floor whose frequency is bisected by the objective: bandwidth (``|T| >= l T0`` for ``w <= wb``)
    or, with ``t0 = None``, crossover (``|L| >= 1`` for ``w <= wc``, via ``Re{A rho conj(L_c)}/|L_c| >= 1``).
    """

    def __init__(self, name: str, points: Points, n_rho: int, t0: T0 | None) -> None:
        self.name, self.points, self.t0 = name, points, t0
        self.mask = cp.Parameter(points.n, nonneg=True)
        self.Q = cp.Parameter((points.n, n_rho))
        self.Are, self.Aim = np.real(points.A), np.imag(points.A)
        self.level = float(points.w.min())

    def set_level(self, w: float) -> None:
        """Move the frequency below which the floor holds."""
        self.level = w

    def constraints(self, rho, slack):
        if self.t0 is None:
            self._cons = [self.mask <= self.Q @ rho + slack]
        else:
            mag = cp.norm(cp.vstack([1 + self.Are @ rho, self.Aim @ rho]), 2, axis=0)
            self._cons = [cp.multiply(self.mask, mag) <= self.Q @ rho + slack]
        return self._cons

    def update(self, rho_c):
        Lc = self.points.A @ rho_c
        mag = np.maximum(np.abs(Lc), 1e-12)
        active = (self.points.w <= self.level).astype(float)
        self.mask.value = active
        level = np.ones(self.points.n) if self.t0 is None else (
            BANDWIDTH_LEVEL * self.t0.value(rho_c, self.points.plant_index))
        self.Q.value = active[:, None] * np.real(np.conj(Lc)[:, None] * self.points.A) / (mag * level)[:, None]

    def violation(self, rho):
        L = self.points.A @ rho
        active = self.points.w <= self.level
        if not np.any(active):
            return -np.inf
        if self.t0 is None:
            return float(np.max(1.0 - np.abs(L[active])))
        level = BANDWIDTH_LEVEL * self.t0.value(rho, self.points.plant_index)
        return float(np.max((level * np.abs(1.0 + L) - np.abs(L))[active]))


class BandwidthCeiling(Form):
    """``|T(j wb)| <= l T0`` (the -3 dB crossing happens before ``wb``)."""

    def __init__(self, name: str, points: Points, n_rho: int, t0: T0) -> None:
        self.name, self.points, self.t0 = name, points, t0
        self.Are, self.Aim = np.real(points.A), np.imag(points.A)
        self.lin = _Linearization(points, n_rho)

    def constraints(self, rho, slack):
        mag = cp.norm(cp.vstack([self.Are @ rho, self.Aim @ rho]), 2, axis=0)
        self._cons = [mag <= self.lin.c + self.lin.R @ rho + slack]
        return self._cons

    def update(self, rho_c):
        level = BANDWIDTH_LEVEL * self.t0.value(rho_c, self.points.plant_index)
        self.lin.set(rho_c, scale=level)

    def violation(self, rho):
        L = self.points.A @ rho
        level = BANDWIDTH_LEVEL * self.t0.value(rho, self.points.plant_index)
        return float(np.max(np.abs(L) - level * np.abs(1.0 + L)))


class HalfPlane(Form):
    """Gain and phase margins: ``L(jw)`` stays in a half-plane that excludes ``-1`` (near crossover).

    The boundary passes through ``-1/g`` and ``exp(j(-180 + phi))``; if that
    line would not protect the phase margin, the vertical line through the
    phase-margin point is used. Applied where ``0.1 <= |L_c| <= 10``.
    """

    def __init__(self, name: str, points: Points, n_rho: int, gm_db: float | None, pm_deg: float | None) -> None:
        self.name, self.points = name, points
        p2 = np.exp(1j * np.radians(-180.0 + pm_deg)) if pm_deg is not None else None
        p1 = -10 ** (-gm_db / 20) if gm_db is not None else None
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

    def constraints(self, rho, slack):
        self._cons = [self.H @ rho - self.h >= -slack]
        return self._cons

    def violation(self, rho):
        L = self.points.A @ rho
        mask = (np.abs(L) >= 0.1) & (np.abs(L) <= 10.0)
        if not np.any(mask):
            return -np.inf
        return float(np.max(-np.real(np.conj(self.normal) * (L[mask] - self.anchor))))

    def update(self, rho_c):
        Lc = self.points.A @ rho_c
        mask = ((np.abs(Lc) >= 0.1) & (np.abs(Lc) <= 10.0)).astype(float)
        nbar = np.conj(self.normal)
        self.H.value = mask[:, None] * np.real(nbar * self.points.A)
        self.h.value = mask * np.real(nbar * self.anchor)


class T0:
    """``|T(0)|`` per plant at the current design (1 with integral action), times ``1 + backoff``."""

    def __init__(self, plants: list[Plant], par: LinearParametrization, backoff: float = 0.0) -> None:
        self.gains = np.array([p.dc_gain() for p in plants])
        self.dc = par.dc_basis()
        self.factor = 1.0 + backoff

    def value(self, rho: np.ndarray, plant_index: np.ndarray) -> np.ndarray:
        if self.dc is None:
            return np.full(plant_index.size, self.factor)
        l0 = self.gains[plant_index] * float(self.dc @ rho)
        return self.factor * np.abs(l0 / (1.0 + l0))


def _requirement_points(req: Any, plants: list[Plant], par: LinearParametrization, grid: np.ndarray,
                        auto: tuple[float, float], per_decade: int) -> Points:
    band = getattr(req, "band", None)
    w = band_grid(band, auto, per_decade) if band is not None else grid
    return make_points(plants, par, w)


BACKOFF = 1e-4
"""Relative tightening of every convex bound (about 0.001 dB), so that designs that are tight on the
grid still meet the exact requirement between grid points."""


def build_forms(requirements: list[Requirement], names: list[str], plants: list[Plant],
                par: LinearParametrization, grid: np.ndarray, per_decade: int,
                stability_level: float, backoff: float = BACKOFF) -> list[Form]:
    """One form per requirement (plus the stability-keeping form), in spec order."""
    auto = (float(grid[0]), float(grid[-1]))
    forms: list[Form] = []
    t0 = T0(plants, par, backoff)
    up, down = 1.0 + backoff, 1.0 - backoff
    for name, req in zip(names, requirements):
        if isinstance(req, (Sensitivity, PeakSensitivity)):
            pts = _requirement_points(req, plants, par, grid, auto, per_decade)
            forms.append(LowerBoundOnReturnDifference(name, pts, par.size, up * 10 ** (-req.max_db / 20)))
        elif isinstance(req, StaticSensitivity):
            w0 = np.array([0.0]) if par.dc_basis() is not None else np.array([grid[0] * 1e-3])
            phi = par.basis(w0)
            gains = [req.plant_gain if req.plant_gain is not None else p.dc_gain() for p in plants]
            A = np.concatenate([g * phi for g in gains])
            pts = Points(np.repeat(w0, len(plants)), np.arange(len(plants)), A,
                         np.concatenate([phi] * len(plants)))
            forms.append(LowerBoundOnReturnDifference(name, pts, par.size, up * 10 ** (-req.max_db / 20)))
        elif isinstance(req, PeakComplementary):
            pts = _requirement_points(req, plants, par, grid, auto, per_decade)
            forms.append(UpperBoundOnRatio(name, pts, pts.A, par.size, down * 10 ** (req.max_db / 20)))
        elif isinstance(req, PeakControlSensitivity):
            pts = _requirement_points(req, plants, par, grid, auto, per_decade)
            forms.append(UpperBoundOnRatio(name, pts, pts.phi, par.size, down * 10 ** (req.max_db / 20)))
        elif isinstance(req, SlewRate):
            w = band_grid(req.band, auto, per_decade)
            w = w[w > 0]
            forms.append(SlewForm(name, w, par.basis(w), down * req.rate_limit / (req.max_error * w)))
        elif isinstance(req, Bandwidth):
            if req.min is not None:
                w = np.unique(np.concatenate([grid[grid < req.min], [req.min]]))
                forms.append(BandwidthFloor(name, make_points(plants, par, w), par.size, t0))
            if req.max is not None:
                forms.append(BandwidthCeiling(name, make_points(plants, par, np.array([req.max])), par.size,
                                              T0(plants, par, -backoff)))
        elif isinstance(req, MarginsRequirement):
            if req.gain_margin_db is not None or req.phase_margin_deg is not None:
                forms.append(HalfPlane(name, make_points(plants, par, grid), par.size,
                                       None if req.gain_margin_db is None else req.gain_margin_db * up,
                                       None if req.phase_margin_deg is None else req.phase_margin_deg * up))
            # a delay margin has no convex form here: the NLP stage and the certificate enforce it
        else:
            raise TypeError(f"no convex form for requirement type {req.type}")
    forms.append(LowerBoundOnReturnDifference("stability (kept along the iterations)",
                                              make_points(plants, par, grid), par.size, stability_level,
                                              elastic=False))
    return forms
