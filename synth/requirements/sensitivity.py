"""Sensitivity requirements: |S| over a band, the seed's static reading, and peak |S| / |T|."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import Field, FiniteFloat, field_validator

from synth.freqgrid import band_grid, band_grids, batch_peak, crossings, log_grid, log_grids, peak
from synth.polynomials import dc_value
from synth.requirements.base import (
    NEPER_PER_DB,
    BandMixin,
    Bound,
    Requirement,
    RequirementResult,
    check_band,
    db,
    db_values,
    fmt,
    register,
)
from synth.requirements.margins import closed_loop_unstable, unstable_result, with_unstable_rows

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = ["FAR", "MAX_DB", "PeakComplementary", "PeakRequirement", "PeakSensitivity", "Sensitivity", "StaticSensitivity",
           "band_text", "with_narrow_peaks"]

MAX_DB = {"max_db": Bound("upper", "dB")}
"""The bound of every requirement here: a magnitude at most ``max_db``."""


def with_narrow_peaks(grid: np.ndarray, loop: Loop, band: tuple[float, float]) -> np.ndarray:
    """``grid`` with the loop's :attr:`~synth.loop.Loop.narrow_peaks` inside ``band`` added (sorted, unique).

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s^2 + 0.001*s + 1)"), Controller("P", {"kp": 0.1}))
    >>> grid = with_narrow_peaks(np.geomspace(0.1, 10.0, 9), loop, (0.0, 10.0))
    >>> grid.size > 9, bool(np.all(np.diff(grid) > 0))
    (True, True)
    """
    extra = loop.narrow_peaks
    extra = extra[(extra >= band[0]) & (extra <= band[1])]
    return np.union1d(grid, extra) if extra.size else grid


def band_text(band: tuple[float, float]) -> str:
    """Where a band is, in words.

    Examples
    --------
    >>> band_text((0, 30)), band_text((1, 10))
    ('below 30 rad/s', 'from 1 to 10 rad/s')
    """
    lo, hi = band
    return f"below {fmt(hi)} rad/s" if lo == 0 else f"from {fmt(lo)} to {fmt(hi)} rad/s"


@register
class Sensitivity(BandMixin, Requirement):
    """``|S(jw)| <= max_db`` for every ``w`` in ``band``, on the full dynamic model.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3.0}))
    >>> r = Sensitivity(type="sensitivity", max_db=-15, band=(0, 30)).evaluate(loop)
    >>> r.met, round(r.details["met_up_to"], 2)
    (False, 10.33)
    >>> r = Sensitivity(type="sensitivity", max_db=-15, band=(0, 5)).evaluate(loop)
    >>> r.met, round(r.details["met_up_to"], 2)  # met: it holds beyond the band, up to the same crossing
    (True, 10.33)
    """

    type: Literal["sensitivity"] = "sensitivity"
    max_db: FiniteFloat
    title: ClassVar[str] = "sensitivity over a band"
    bounds: ClassVar[dict[str, Bound]] = MAX_DB
    example: ClassVar[dict[str, Any]] = {"type": "sensitivity", "max_db": -15.0, "band": (0.0, 5.0)}

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        if closed_loop_unstable(loop):
            return unstable_result(self, loop, f"|S| {band_text(self.band)}", band=list(self.band))
        grid = with_narrow_peaks(band_grid(self.band, loop.frequency_range, per_decade), loop, self.band)
        value, w_peak = peak(lambda w: np.abs(loop.S(w)), grid)
        value_db = db(value)
        margin = self.max_db - value_db
        limit = self.linear_bound("max_db")
        up_to = None  # the highest frequency up to which it holds: None where it fails at the band's low end
        if margin >= 0:  # met: how far beyond the band it holds (inf: at every frequency the loop is checked on)
            grid = band_grid((self.band[0], max(self.band[1], 10 * loop.frequency_range[1])), loop.frequency_range,
                             per_decade)
        if np.abs(loop.S(grid[:1]))[0] <= limit:
            cross = crossings(lambda w: np.abs(loop.S(w)), limit, grid)
            up_to = float(cross[0]) if cross.size else (np.inf if margin >= 0 else None)
        where = band_text(self.band)
        if margin >= 0:
            msg = (f"|S| stays at or below {fmt(self.max_db)} dB {where}: met, "
                   f"peak {value_db:.2f} dB at {fmt(w_peak)} rad/s ({margin:.2f} dB to spare)")
        else:
            held = (f"it holds only up to {fmt(up_to)} rad/s" if up_to is not None
                    else "it fails already at the low end of the band")
            msg = (f"|S| <= {fmt(self.max_db)} dB {where}: NOT met, |S| reaches {value_db:.2f} dB "
                   f"at {fmt(w_peak)} rad/s; {held}")
        return self.result(value=value_db, bound=self.max_db, unit="dB", slack=margin * NEPER_PER_DB,
                           margin=margin, binding_frequency=w_peak, message=msg,
                           met_up_to=up_to, band=list(self.band))

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack: the peak of every loop's ``|S|`` over the band at once."""
        grid = band_grids(self.band, batch.frequency_ranges, per_decade)
        value, _ = batch_peak(lambda w: np.abs(batch.S(w)), grid)
        return with_unstable_rows(self, batch, (self.max_db - db_values(value)) * NEPER_PER_DB)


@register
class StaticSensitivity(Requirement):
    """The seed's static reading ``S = 1/(1 + C(0) * plant_gain) <= max_db``.

    ``plant_gain`` defaults to the plant's own DC gain; the X-4 paper uses 1.8
    while its eq. 5 model has 1.908.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3.0}))
    >>> r = StaticSensitivity(type="sensitivity_static", max_db=-15, plant_gain=1.8).evaluate(loop)
    >>> round(r.value, 2), r.met
    (-16.12, True)
    """

    type: Literal["sensitivity_static"] = "sensitivity_static"
    max_db: FiniteFloat
    plant_gain: FiniteFloat | None = Field(default=None, description="low-frequency plant gain")
    title: ClassVar[str] = "static sensitivity"
    bounds: ClassVar[dict[str, Bound]] = MAX_DB
    stricter: ClassVar[dict[str, int]] = {"plant_gain": -1}
    example: ClassVar[dict[str, Any]] = {"type": "sensitivity_static", "max_db": -15.0, "plant_gain": 1.8}

    @field_validator("plant_gain")
    @classmethod
    def _nonzero_gain(cls, gain: float | None) -> float | None:
        if gain == 0.0:
            raise ValueError("plant_gain must be non-zero (the plant's low-frequency gain; leave it out to use the "
                             "model's)")
        return gain

    def gain(self, loop: Loop) -> float:
        """Plant gain used: the stated one or the model's DC gain."""
        return float(self.plant_gain) if self.plant_gain is not None else loop.plant.dc_gain()

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        g = self.gain(loop)
        c0 = loop.controller.dc_gain()
        # the model's L(0) exactly (a zero of C at s = 0 meets an integrating plant's pole: a finite limit)
        l0 = c0 * g if self.plant_gain is not None else dc_value(loop.num, loop.den)
        value_db = -np.inf if np.isinf(l0) else db(1.0 / (1.0 + l0)) if l0 != -1 else np.inf
        margin = self.max_db - value_db
        source = "stated" if self.plant_gain is not None else "model DC"
        if np.isinf(c0):
            msg = (f"static sensitivity: integral action makes S(0) = 0 (-inf dB) <= {fmt(self.max_db)} dB: met")
        else:
            msg = (f"static sensitivity 1/(1 + C(0)*{fmt(g)}) = {value_db:.2f} dB "
                   f"{'<=' if margin >= 0 else '>'} {fmt(self.max_db)} dB: "
                   f"{'met' if margin >= 0 else 'NOT met'} ({source} plant gain {fmt(g)}, C(0) = {fmt(c0)})")
        return self.result(value=value_db, bound=self.max_db, unit="dB", slack=margin * NEPER_PER_DB,
                           margin=margin, binding_frequency=0.0, message=msg, plant_gain=g,
                           controller_dc_gain=c0,
                           minimum_dc_gain=(1.0 / self.linear_bound("max_db") - 1) / g if g != 0 else float("inf"))

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack: the same closed form for every controller's DC gain."""
        g = float(self.plant_gain) if self.plant_gain is not None else batch.plant.dc_gain()
        if not np.isfinite(g) or g == 0.0:  # L(0) is a limit of C(s) G(s): one loop at a time, exactly
            return Requirement.batch_slack(self, batch, per_decade)
        l0 = batch.controller_dc_gains() * g
        with np.errstate(divide="ignore", invalid="ignore"):
            value_db = np.where(np.isinf(l0), -np.inf, np.where(l0 == -1, np.inf, db_values(1.0 / (1.0 + l0))))
        return (self.max_db - value_db) * NEPER_PER_DB


FAR = 1e6
"""An unbanded peak also looks at ``FAR`` times the top of the loop's frequency range: the supremum over all
frequencies can be the limit ``w -> inf`` (``|C S| -> |C(inf)|`` for a biproper controller), which a grid that
ends where ``|L|`` is small but not 0 misses by ``|1 + L|``. It looks at ``w = 0`` too: a loop whose DC gain is
negative and near -1 has its peak there, above every point of a grid that starts at the loop's slowest corner
over a hundred (peak |S| 31.9 dB "met" at 0.01 rad/s where |S(0)| is 46.0 dB; a black-box test)."""


class PeakRequirement(Requirement):
    """Peak of a closed-loop magnitude over a band (default: all frequencies): the base of the peak types.

    A subclass names its ``type``, ``symbol`` and ``title`` and its :meth:`curve`.

    Examples
    --------
    >>> PeakSensitivity(max_db=6).linear_bound("max_db") > 1.99
    True
    """

    max_db: FiniteFloat
    band: tuple[float, float] | None = None
    symbol: ClassVar[str] = "|S|"
    bounds: ClassVar[dict[str, Bound]] = MAX_DB

    @field_validator("band")
    @classmethod
    def _check_band(cls, band: tuple[float, float] | None) -> tuple[float, float] | None:
        return None if band is None else check_band(band)

    def curve(self, loop: Loop) -> Callable[[np.ndarray], np.ndarray]:  # pragma: no cover - overridden
        """The magnitude whose peak is bounded, as a function of ``w``."""
        raise NotImplementedError

    def batch_curve(self, batch: LoopBatch) -> Callable[[np.ndarray], np.ndarray] | None:
        """The vectorized :meth:`curve` (frequencies ``(n, m)`` to magnitudes ``(n, m)``), or None
        when the type has none (its :meth:`batch_slack` then falls back to one loop at a time)."""
        return None

    @classmethod
    def has_batch_form(cls) -> bool:
        """Whether the type's :meth:`batch_curve` is given."""
        return cls.batch_curve is not PeakRequirement.batch_curve

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack from :meth:`batch_curve`: every loop's peak at once."""
        curve = self.batch_curve(batch)
        if curve is None:
            return Requirement.batch_slack(self, batch, per_decade)
        if self.band is not None:
            grid = band_grids(self.band, batch.frequency_ranges, per_decade)
        else:
            ranges = batch.frequency_ranges
            grid = log_grids(ranges[:, 0], ranges[:, 1] * 10, per_decade)
            # w = 0 (a negative DC loop gain near -1 peaks there) and the limit w -> inf (|KS| -> |C(inf)|)
            grid = np.column_stack([np.zeros(len(ranges)), grid, ranges[:, 1] * FAR])
        value, _ = batch_peak(curve, grid)
        return with_unstable_rows(self, batch, (self.max_db - db_values(value)) * NEPER_PER_DB)

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        if closed_loop_unstable(loop):
            return unstable_result(self, loop, f"peak {self.symbol}",
                                   band=None if self.band is None else list(self.band))
        if self.band is not None:  # checked when the spec was read
            grid = with_narrow_peaks(band_grid(self.band, loop.frequency_range, per_decade), loop, self.band)
            where = band_text(self.band)
        else:
            lo, hi = loop.frequency_range
            grid = np.r_[0.0, log_grid(lo, hi * 10, per_decade), hi * FAR]  # w = 0 and the limit w -> inf
            grid = with_narrow_peaks(grid, loop, (0.0, np.inf))
            where = "over all frequencies"
        value, w_peak = peak(self.curve(loop), grid)
        value_db = db(value)
        margin = self.max_db - value_db
        msg = (f"peak {self.symbol} {where} is {value_db:.2f} dB at {fmt(w_peak)} rad/s "
               f"{'<=' if margin >= 0 else '>'} {fmt(self.max_db)} dB: {'met' if margin >= 0 else 'NOT met'}")
        return self.result(value=value_db, bound=self.max_db, unit="dB", slack=margin * NEPER_PER_DB,
                           margin=margin, binding_frequency=w_peak, message=msg, linear_peak=value)


@register
class PeakSensitivity(PeakRequirement):
    """Peak ``|S|`` (Ms) at most ``max_db``.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s+1)^3"), Controller("P", {"kp": 4.0}))
    >>> r = PeakSensitivity(type="peak_sensitivity", max_db=6).evaluate(loop)
    >>> round(r.value, 2), r.met
    (9.54, False)
    """

    type: Literal["peak_sensitivity"] = "peak_sensitivity"
    title: ClassVar[str] = "peak sensitivity"
    example: ClassVar[dict[str, Any]] = {"type": "peak_sensitivity", "max_db": 6.0}

    def curve(self, loop: Loop) -> Callable[[np.ndarray], np.ndarray]:
        """``|S|`` as a function of ``w``."""
        return lambda w: np.abs(loop.S(w))

    def batch_curve(self, batch: LoopBatch) -> Callable[[np.ndarray], np.ndarray]:
        """``|S|`` of every loop."""
        return lambda w: np.abs(batch.S(w))


@register
class PeakComplementary(PeakRequirement):
    """Peak ``|T|`` (Mt) at most ``max_db``.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s+1)^3"), Controller("P", {"kp": 4.0}))
    >>> round(PeakComplementary(type="peak_complementary", max_db=3).evaluate(loop).value, 2)
    7.66
    """

    type: Literal["peak_complementary"] = "peak_complementary"
    symbol: ClassVar[str] = "|T|"
    title: ClassVar[str] = "peak complementary sensitivity"
    example: ClassVar[dict[str, Any]] = {"type": "peak_complementary", "max_db": 3.0}

    def curve(self, loop: Loop) -> Callable[[np.ndarray], np.ndarray]:
        """``|T|`` as a function of ``w``."""
        return lambda w: np.abs(loop.T(w))

    def batch_curve(self, batch: LoopBatch) -> Callable[[np.ndarray], np.ndarray]:
        """``|T|`` of every loop."""
        return lambda w: np.abs(batch.T(w))
