"""The convex form of each requirement type: ``@convex_form(Type, exact=...)`` entries that build, around the
current design, the cones and half-planes of :mod:`synth.synthesis.convex_bounds` (where the inner
approximations and their table live) for the convex-concave procedure of :mod:`synth.synthesis.convex`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.freqgrid import band_grid
from synth.loop import BANDWIDTH_LEVEL
from synth.plant import Plant
from synth.requirements import (
    Bandwidth,
    DelayMargin,
    DiskMargin,
    MarginsRequirement,
    NoLimitCycle,
    PeakComplementary,
    PeakSensitivity,
    Sensitivity,
    SlewRate,
    StaticSensitivity,
    StepResponse,
)
from synth.requirements.base import Requirement
from synth.requirements.control_sensitivity import PeakControlSensitivity
from synth.synthesis.convex_bounds import (
    BACKOFF,
    LOWER_SECTOR,
    T0,
    Form,
    HalfPlane,
    Kappa,
    Points,
    RatioBound,
    bandwidth_floor,
    make_points,
    sensitivity_form,
    without_implied,
)
from synth.synthesis.form_registry import FormRegistry
from synth.synthesis.parametrization import Parametrization

__all__ = [
    "BACKOFF",
    "CONVEX_FORMS",
    "LOWER_SECTOR",
    "T0",
    "Form",
    "FormContext",
    "HalfPlane",
    "Kappa",
    "Points",
    "RatioBound",
    "bandwidth_floor",
    "build_forms",
    "convex_form",
    "make_points",
    "sensitivity_form",
    "without_implied",
]


CONVEX_FORMS = FormRegistry("convex")
"""The convex form of each requirement type (filled by :func:`convex_form` below)."""


def convex_form(requirement: type[Requirement], *, exact: bool) -> Callable[[Callable], Callable]:
    """Decorator: register ``build(ctx, name, req) -> list[Form]`` as the convex form of ``requirement``.

    ``exact``: the form is the requirement's own set on the same frequencies as the NLP form (an inner
    approximation that touches it at the linearization point with the same gradient), so the NLP
    polish cannot improve on a converged convex answer (:func:`synth.synthesis.polish_skip.polish_redundant`).

    Examples
    --------
    >>> from synth.requirements import PeakSensitivity
    >>> CONVEX_FORMS.entry(PeakSensitivity).exact
    True
    """
    return CONVEX_FORMS.register(requirement, exact=exact)


@dataclass
class FormContext:
    """What every convex form is built from: the plants, the parametrization, the design grid."""

    plants: list[Plant]
    par: Parametrization
    grid: np.ndarray
    per_decade: int
    tight: float  # 1 - backoff
    t0: T0

    @property
    def auto(self) -> tuple[float, float]:
        """Span of the design grid (the range a band ``[0, hi]`` starts from)."""
        return float(self.grid[0]), float(self.grid[-1])

    def points(self, req: Any) -> Points:
        """The requirement's band on every plant (the design grid without a band)."""
        band = getattr(req, "band", None)
        w = band_grid(band, self.auto, self.per_decade) if band is not None else self.grid
        return make_points(self.plants, self.par, w)


@convex_form(Sensitivity, exact=True)
@convex_form(PeakSensitivity, exact=True)
def _sensitivity(ctx: FormContext, name: str, req: Sensitivity | PeakSensitivity) -> list[Form]:
    return [sensitivity_form(name, ctx.points(req), ctx.par.size, ctx.tight * req.linear_bound("max_db"))]


@convex_form(StaticSensitivity, exact=False)
def _static_sensitivity(ctx: FormContext, name: str, req: StaticSensitivity) -> list[Form]:
    gains = [req.plant_gain if req.plant_gain is not None else p.dc_gain() for p in ctx.plants]
    w0 = np.array([0.0]) if not ctx.par.has_integrator() else np.array([ctx.grid[0] * 1e-3])
    pts = make_points(ctx.plants, ctx.par, w0, gains)
    return [sensitivity_form(name, pts, ctx.par.size, ctx.tight * req.linear_bound("max_db"))]


@convex_form(PeakComplementary, exact=True)
def _peak_complementary(ctx: FormContext, name: str, req: PeakComplementary) -> list[Form]:
    pts = ctx.points(req)
    return [RatioBound(name, pts.N, pts.P, ctx.tight * req.linear_bound("max_db"), ctx.par.size)]


@convex_form(PeakControlSensitivity, exact=True)
def _peak_control_sensitivity(ctx: FormContext, name: str, req: PeakControlSensitivity) -> list[Form]:
    pts = ctx.points(req)
    return [RatioBound(name, pts.X, pts.P, ctx.tight * req.linear_bound("max_db"), ctx.par.size)]


@convex_form(SlewRate, exact=True)
def _slew_rate(ctx: FormContext, name: str, req: SlewRate) -> list[Form]:
    w = band_grid(req.band, ctx.auto, ctx.per_decade)
    pts = make_points(ctx.plants[:1], ctx.par, w[w > 0])
    return [RatioBound(name, pts.X, pts.D, ctx.tight * req.rate_limit / (req.max_error * pts.w), ctx.par.size)]


@convex_form(Bandwidth, exact=False)
def _bandwidth(ctx: FormContext, name: str, req: Bandwidth) -> list[Form]:
    forms: list[Form] = []
    grid, t0, tight = ctx.grid, ctx.t0, ctx.tight
    if req.min is not None:
        w = np.unique(np.concatenate([grid[grid < req.min], [req.min]]))
        forms.append(bandwidth_floor(name, make_points(ctx.plants, ctx.par, w), ctx.par.size, t0, tight))
    if req.max is not None:
        pts = make_points(ctx.plants, ctx.par, np.array([req.max]))

        def kappa(rho: np.ndarray, pts: Points = pts) -> np.ndarray:
            return tight * BANDWIDTH_LEVEL * t0.value(rho, pts.plant_index)
        forms.append(RatioBound(name, pts.N, pts.P, kappa, ctx.par.size))
    return forms


@convex_form(MarginsRequirement, exact=False)
def _margins(ctx: FormContext, name: str, req: MarginsRequirement) -> list[Form]:
    # a delay margin (and rational-controller margins) have no convex form here: the NLP stage and the
    # certificate enforce them
    if ctx.par.ctype == "rational" or (req.gain_margin_db is None and req.phase_margin_deg is None):
        return []
    unstable = any(np.any(np.roots(p.den).real > 0) for p in ctx.plants if len(p.den) > 1)
    return [HalfPlane(name, make_points(ctx.plants, ctx.par, ctx.grid), ctx.par.size,
                      None if req.gain_margin_db is None else req.gain_margin_db / ctx.tight,
                      None if req.phase_margin_deg is None else req.phase_margin_deg / ctx.tight, lower=unstable)]


def build_forms(requirements: list[Requirement], names: list[str], plants: list[Plant],
                par: Parametrization, grid: np.ndarray, per_decade: int,
                stability_level: float, backoff: float = BACKOFF) -> list[Form]:
    """One form per requirement, from :data:`CONVEX_FORMS` (plus the stability-keeping form), in spec
    order; a requirement type without a convex form is a :class:`~synth.errors.SpecError`."""
    ctx = FormContext(plants, par, grid, per_decade, 1.0 - backoff, T0(plants, par))
    forms: list[Form] = []
    for name, req in zip(names, requirements):
        forms += CONVEX_FORMS.entry(req).build(ctx, name, req)
    forms.append(sensitivity_form("stability (kept along the iterations)", make_points(plants, par, grid),
                                  par.size, 1.0 / stability_level, elastic=False))
    return forms


@convex_form(DiskMargin, exact=True)
def _disk_margin(ctx: FormContext, name: str, req: DiskMargin) -> list[Form]:
    # |S + c| <= 1/alpha with S + c = ((1 + c) D + c N)/(D + N): a ratio of affine parts
    c = (req.skew - 1.0) / 2.0
    pts = make_points(ctx.plants, ctx.par, ctx.grid)
    U = pts.D.scaled(np.full(pts.n, 1.0 + c)) + pts.N.scaled(np.full(pts.n, c))
    return [RatioBound(name, U, pts.P, ctx.tight / req.min, ctx.par.size)]


@convex_form(DelayMargin, exact=False)
@convex_form(StepResponse, exact=False)
@convex_form(NoLimitCycle, exact=False)
def _no_convex_form(ctx: FormContext, name: str, req: Requirement) -> list[Form]:
    # no convex form: the NLP stage (delay margin) and the certificate inside the design loop enforce them
    # (the certificate re-checks every requirement exactly; a design that fails it is not reported)
    return []
