"""The NLP form of each requirement type, registered with ``@nlp_form(Type, exact=...)``.

Each form adds the requirement's constraints on one plant (``b.geq(expr)``: ``expr >= 0``, one entry
per frequency); the table of :mod:`synth.synthesis.nlp` lists them. A requirement type without a form
is a :class:`~synth.errors.SpecError` naming it (docs/extending-requirements.md).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from synth.controllers import Controller
from synth.freqgrid import band_grid
from synth.loop import BANDWIDTH_LEVEL, Loop
from synth.plant import Plant
from synth.requirements import (
    Bandwidth,
    DelayMargin,
    DiskMargin,
    MarginsRequirement,
    NoLimitCycle,
    PeakComplementary,
    PeakControlSensitivity,
    PeakSensitivity,
    Sensitivity,
    SlewRate,
    StaticSensitivity,
    StepResponse,
)
from synth.requirements.base import Requirement, magnitude
from synth.synthesis.form_registry import FormRegistry
from synth.synthesis.nlp_peaks import PEAK_TIGHT, track_peaks
from synth.synthesis.nlp_problem import (
    BACKOFF,
    TIGHT,
    NLPBuilder,
    loop_response,
    phase_crossings,
    t0_squared,
)

__all__ = ["MAX_HELD_CROSSINGS", "NLP_FORMS", "NLPContext", "nlp_form"]


def _between_neighbours(w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For sorted positive frequencies, the interval of each up to half-way (in ``log w``) to its neighbours
    (0 and infinity at the ends): a crossing held in it cannot slide onto another."""
    w = np.asarray(w, float)
    mids = np.sqrt(w[:-1] * w[1:])
    return np.concatenate([[0.0], mids]), np.concatenate([mids, [np.inf]])


def _positive(w: np.ndarray) -> np.ndarray:
    return w[w > 0]


def _band(req: Any, grid: np.ndarray, extra: np.ndarray, per_decade: int) -> np.ndarray:
    auto = (float(grid[0]), float(grid[-1]))
    band = getattr(req, "band", None)
    if band is None:
        return np.unique(np.concatenate([grid, extra]))
    w = _positive(band_grid(band, auto, per_decade))
    inside = extra[(extra >= band[0]) & (extra <= band[1])]
    return np.unique(np.concatenate([w, inside]))


MAX_HELD_CROSSINGS = 40
"""Most crossings of the negative real axis the margins form holds per plant (those closest to -1/g): a long
delay behind a loop gain that fades slowly crosses the axis hundreds of times within 10 dB of the bound; the
others are left to the certificate and to the next round."""

NLP_FORMS = FormRegistry("NLP")
"""The NLP form of each requirement type (filled by :func:`nlp_form` below)."""


def nlp_form(requirement: type[Requirement], *, exact: bool) -> Callable[[Callable], Callable]:
    """Decorator: register ``build(b, req, plant, ctx)`` as the NLP form of ``requirement`` (it adds the
    requirement's constraints on one plant to the problem being built).

    Examples
    --------
    >>> from synth.requirements import DiskMargin, MarginsRequirement
    >>> NLP_FORMS.entry(DiskMargin).exact, NLP_FORMS.entry(MarginsRequirement).exact
    (True, False)
    """
    return NLP_FORMS.register(requirement, exact=exact)


@dataclass
class NLPContext:
    """What every NLP form is built from: the design grid, the extra frequencies found between its
    points, the band density and the design the problem starts from."""

    grid: np.ndarray
    extra: np.ndarray
    per_decade: int
    start: Controller
    track: tuple[Controller, ...] = ()
    """Other designs whose sharp peaks the NLP tracks (the last answer, when it failed between grid points)."""

    def band(self, req: Any) -> tuple[float, float]:
        """The requirement's band, or the design grid's range."""
        band = getattr(req, "band", None)
        lo, hi = (float(self.grid[0]), float(self.grid[-1])) if band is None else (float(band[0]), float(band[1]))
        return max(lo, float(self.grid[0]) * 1e-3), min(hi, float(self.grid[-1]) * 1e3)

    def points(self, req: Any) -> np.ndarray:
        """The requirement's band (the design grid without one), with the extra frequencies inside it."""
        return _band(req, self.grid, self.extra, self.per_decade)


@nlp_form(Sensitivity, exact=True)
@nlp_form(PeakSensitivity, exact=True)
def _sensitivity(b: NLPBuilder, req: Sensitivity | PeakSensitivity, plant: Plant, ctx: NLPContext) -> None:
    m2 = req.linear_bound("max_db") ** 2 * TIGHT
    _, L = loop_response(b.ctrl, plant, ctx.points(req))
    b.geq(m2 * (1.0 + L).abs2() - 1.0)
    track_peaks(b, plant, [ctx.start, *ctx.track], "S", req.linear_bound("max_db"), ctx.band(req), PEAK_TIGHT)


@nlp_form(StaticSensitivity, exact=True)
def _static_sensitivity(b: NLPBuilder, req: StaticSensitivity, plant: Plant, ctx: NLPContext) -> None:
    parts = b.ctrl.dc_parts()
    if parts is not None:  # |1 + g n/d| >= 1/m written as (d + g n)^2 >= d^2 / m^2: no division where d reaches 0
        n, d = parts
        g = req.plant_gain if req.plant_gain is not None else plant.dc_gain()
        b.geq(TIGHT / req.linear_bound("max_db") ** 2 * (d + g * n) ** 2 - d**2)


@nlp_form(PeakComplementary, exact=True)
def _peak_complementary(b: NLPBuilder, req: PeakComplementary, plant: Plant, ctx: NLPContext) -> None:
    _, L = loop_response(b.ctrl, plant, ctx.points(req))
    b.geq((1.0 + L).abs2() - L.abs2() / (req.linear_bound("max_db") ** 2 * TIGHT))
    track_peaks(b, plant, [ctx.start, *ctx.track], "T", req.linear_bound("max_db"), ctx.band(req), PEAK_TIGHT)


@nlp_form(PeakControlSensitivity, exact=True)
def _peak_control_sensitivity(b: NLPBuilder, req: PeakControlSensitivity, plant: Plant, ctx: NLPContext) -> None:
    C, L = loop_response(b.ctrl, plant, ctx.points(req))
    b.geq((1.0 + L).abs2() - C.abs2() / (req.linear_bound("max_db") ** 2 * TIGHT))
    track_peaks(b, plant, [ctx.start, *ctx.track], "KS", req.linear_bound("max_db"), ctx.band(req), PEAK_TIGHT)


@nlp_form(SlewRate, exact=True)
def _slew_rate(b: NLPBuilder, req: SlewRate, plant: Plant, ctx: NLPContext) -> None:
    w = ctx.points(req)
    C, _ = loop_response(b.ctrl, plant, w)
    b.geq(TIGHT - (req.max_error * w / req.rate_limit) ** 2 * C.abs2())


@nlp_form(Bandwidth, exact=True)
def _bandwidth(b: NLPBuilder, req: Bandwidth, plant: Plant, ctx: NLPContext) -> None:
    t02 = t0_squared(b.ctrl, plant)
    grid, extra = ctx.grid, ctx.extra
    if req.min is not None:
        pts = np.concatenate([grid[grid < req.min], extra[extra < req.min], [req.min]])
        _, L = loop_response(b.ctrl, plant, np.unique(pts))
        b.geq(TIGHT * L.abs2() - BANDWIDTH_LEVEL**2 * t02 * (1.0 + L).abs2())
    if req.max is not None:
        _, L = loop_response(b.ctrl, plant, float(req.max))
        b.geq(TIGHT * BANDWIDTH_LEVEL**2 * t02 * (1.0 + L).abs2() - L.abs2())


@nlp_form(MarginsRequirement, exact=False)
def _margins(b: NLPBuilder, req: MarginsRequirement, plant: Plant, ctx: NLPContext) -> None:
    # phase and delay margins at each gain crossover, the upper gain limit at each phase crossover inside the
    # unit circle, the lower gain limit at the crossing outside it: exact at those crossings, which are
    # variables and move with the design; a crossing that appears away from the start design's is left to
    # the certificate (hence exact=False)
    loop = Loop(plant, ctx.start)
    ctrl = b.ctrl
    crossovers = loop.gain_crossovers()
    for wc, lo, hi in zip(crossovers, *_between_neighbours(crossovers)):
        v = b.var("wc", float(wc), max(wc / 3.0, lo), min(3.0 * wc, hi))
        _, L = loop_response(ctrl, plant, v)
        b.eq(L.abs2() - 1.0)
        if req.phase_margin_deg is not None:
            b.geq((1.0 + L).abs2() - 4 * np.sin(np.radians(req.phase_margin_deg * (1 + BACKOFF)) / 2) ** 2)
            # the margin is 180 deg plus the phase wrapped to [-180, 180) (as the check, python-control and
            # MATLAB's allmargin take it): a crossing in the upper half-plane has a negative one, however far
            # from -1 it is, so the crossing stays below the real axis (a rational controller's polish, seed 17
            # #48 of the design benchmark, walked seven rounds along crossings at +85 deg the check rejected)
            b.geq(-L.im)
        if req.delay_margin is not None:
            tau = req.delay_margin * (1 + 10 * BACKOFF)  # tightened as the delay_margin requirement's form
            b.geq((1.0 + L).abs2() - 4 * ca.sin(ca.fmin(v * tau, np.pi) / 2) ** 2)
    if req.gain_margin_db is not None:
        g = magnitude(req.gain_margin_db * (1 + BACKOFF))
        # the upper gain limit: crossings inside the unit circle stay right of -1/g; held are those within 10 dB
        # of that bound (the closest MAX_HELD_CROSSINGS), each between its neighbouring zeros of Im L
        crossing, below, above = phase_crossings(loop, 1.0 / (g * np.sqrt(10.0)))
        closest = np.sort(np.argsort(-np.abs(loop.L(crossing)), kind="stable")[:MAX_HELD_CROSSINGS])
        for wp, lo, hi in zip(crossing[closest], below[closest], above[closest]):
            v = b.var("wp", float(wp), max(wp / 3.0, lo), min(3.0 * wp, hi))
            _, L = loop_response(ctrl, plant, v)
            b.eq(L.im)
            b.geq(L.re + 1.0 / g)
        k_lo, _, w_lo, _ = loop.gain_factors
        if k_lo > 0 and w_lo is not None:  # the lower gain limit (open-loop unstable or conditionally stable
            # loop): the crossing of the negative real axis outside the unit circle stays left of -g
            if w_lo > 0:
                v = b.var("wl", float(w_lo), w_lo / 3.0, 3.0 * w_lo)
                _, L = loop_response(ctrl, plant, v)
                b.eq(L.im)
                b.geq(-L.re - g)
            elif ctrl.dc() is not None:  # at w = 0: the static loop gain (e.g. an unstable pole under P control)
                b.geq(-ctrl.dc() * plant.dc_gain() - g)
            # else: a start without integral action whose lower crossing sits at w = 0, in a structure with an
            # integrator (its crossing leaves w = 0 as soon as ki > 0): left to the certificate


@nlp_form(DiskMargin, exact=True)
def _disk_margin(b: NLPBuilder, req: DiskMargin, plant: Plant, ctx: NLPContext) -> None:
    # |1 + c (1 + L)| <= |1 + L| / alpha, squared
    c = (req.skew - 1.0) / 2.0
    _, L = loop_response(b.ctrl, plant, ctx.points(req))
    b.geq(TIGHT * (1.0 + L).abs2() / req.min**2 - (L * c + (1.0 + c)).abs2())


@nlp_form(DelayMargin, exact=False)
def _delay_margin(b: NLPBuilder, req: DelayMargin, plant: Plant, ctx: NLPContext) -> None:
    # at each gain crossover of the start design: |1 + L| >= 2 sin(wc tau / 2), i.e. PM >= wc tau
    # (the crossovers move with the design; the certificate checks the exact margin), tightened so that
    # a design on the bound passes the exact check
    tightened = MarginsRequirement(delay_margin=req.min * (1 + 10 * BACKOFF))
    NLP_FORMS.entry(MarginsRequirement).build(b, tightened, plant, ctx)


@nlp_form(StepResponse, exact=False)
@nlp_form(NoLimitCycle, exact=False)
def _certified_only(b: NLPBuilder, req: StepResponse | NoLimitCycle, plant: Plant, ctx: NLPContext) -> None:
    # no NLP form: the certificate inside the design loop checks the step response and the describing
    # function exactly, and a design that fails it is not reported as a solution
    return None
