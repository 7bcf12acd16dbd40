"""The slew-rate Bode bound of the X-4 paper (seed 1, eq. 9-12)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import PositiveFloat

from synth.freqgrid import band_grid, band_grids, batch_peak, crossings, log_grid, peak
from synth.requirements.base import BandMixin, Bound, Requirement, RequirementResult, fmt, register

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = ["SlewRate"]


@register
class SlewRate(BandMixin, Requirement):
    """``max_error * |C(jw)| * w <= rate_limit`` for every ``w`` in ``band``.

    A sinusoidal error of amplitude ``max_error`` (output units) at ``w``
    asks the actuator for a rate ``max_error |C| w`` (input units per second);
    it must stay within ``rate_limit``. Drawn on the Bode plot of ``C G`` as
    ``20 log|CG| <= 20 log(B/De) + 20 log|G| - 20 log w`` (eq. 12).

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3.0}))
    >>> r = SlewRate(type="slew_rate", rate_limit=1e4, max_error=5, band=(0.1, 100)).evaluate(loop)
    >>> round(r.value, 6), r.met, round(r.details["crossing_frequency"], 2)
    (1500.0, True, 666.67)
    """

    type: Literal["slew_rate"] = "slew_rate"
    rate_limit: PositiveFloat
    max_error: PositiveFloat
    title: ClassVar[str] = "slew-rate Bode bound"
    bounds: ClassVar[dict[str, Bound]] = {"rate_limit": Bound("upper", "input units/s")}
    stricter: ClassVar[dict[str, int]] = {"max_error": +1}
    example: ClassVar[dict[str, Any]] = {"type": "slew_rate", "rate_limit": 10000.0, "max_error": 5.0,
                                         "band": (0.1, 100.0)}

    def demand(self, loop: Loop):
        """Rate demand ``max_error |C(jw)| w`` as a function of ``w`` (input units/s)."""
        return lambda w: self.max_error * np.abs(loop.controller.freqresp(w)) * np.asarray(w, float)

    def crossing_frequency(self, loop: Loop) -> float | None:
        """Lowest frequency where the demand reaches the rate limit (searched beyond the band)."""
        lo, hi = loop.frequency_range
        grid = log_grid(min(lo, self.band[1] * 1e-4), max(hi, self.band[1]) * 1e3)
        demand = self.demand(loop)
        cross = crossings(demand, self.rate_limit, grid)
        if cross.size:
            return float(cross[0])
        return float(grid[0]) if demand(grid[:1])[0] > self.rate_limit else None

    def slack(self, loop: Loop, per_decade: int = 80) -> float:
        """The slack of :meth:`evaluate` without the crossing frequency its message quotes."""
        value, _ = peak(self.demand(loop), band_grid(self.band, loop.frequency_range, per_decade))
        return float(np.log(self.rate_limit / value) if value > 0 else np.inf)

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack: every controller's peak rate demand over the band at once."""
        grid = band_grids(self.band, batch.frequency_ranges, per_decade)
        with np.errstate(invalid="ignore"):  # inf * 0 at w = 0 with integral action: nan, as in evaluate
            value, _ = batch_peak(lambda w: self.max_error * np.abs(batch.C(w)) * w, grid)
        with np.errstate(divide="ignore"):
            return np.where(value > 0, np.log(self.rate_limit / np.where(value > 0, value, 1.0)), np.inf)

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        grid = band_grid(self.band, loop.frequency_range, per_decade)
        value, w_peak = peak(self.demand(loop), grid)
        margin = self.rate_limit - value
        slack = np.log(self.rate_limit / value) if value > 0 else np.inf
        w_cross = self.crossing_frequency(loop)
        u = loop.plant.input.unit or "input units"
        y = loop.plant.output.unit or "output units"
        msg = (f"slew-rate bound: a {fmt(self.max_error)} {y} error asks for up to {fmt(value)} {u}/s "
               f"(at {fmt(w_peak)} rad/s) against B = {fmt(self.rate_limit)} {u}/s over "
               f"{fmt(self.band[0])}-{fmt(self.band[1])} rad/s: {'met' if margin >= 0 else 'NOT met'}; "
               f"the demand reaches B at {fmt(w_cross)} rad/s"
               + (f", above the band's top: the verdict rests on the band ending at {fmt(self.band[1])} rad/s"
                  if margin >= 0 and w_cross is not None and np.isfinite(w_cross) and w_cross > self.band[1] else ""))
        return self.result(value=value, bound=self.rate_limit, unit=f"{u}/s", slack=slack, margin=margin,
                           binding_frequency=w_peak, message=msg, crossing_frequency=w_cross,
                           bound_over_error=self.rate_limit / self.max_error)
