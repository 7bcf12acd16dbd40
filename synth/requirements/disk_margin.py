"""Disk margin (Seiler, Packard and Gahinet, "An introduction to disk margins", IEEE CSM 2020)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import PositiveFloat, field_validator

from synth.freqgrid import log_grid, peak
from synth.polynomials import value_at_infinity
from synth.requirements.base import Bound, Requirement, RequirementResult, db, fmt, register
from synth.requirements.margins import closed_loop_unstable, unstable_result
from synth.requirements.sensitivity import with_narrow_peaks

if TYPE_CHECKING:
    from synth.loop import Loop

__all__ = ["DiskMargin", "disk_gain_phase", "high_frequency_limit"]


def disk_gain_phase(alpha: float, skew: float = 0.0) -> tuple[float, float, float]:
    """Gain interval ``[g_min, g_max]`` and phase margin (deg) guaranteed by a disk margin ``alpha``.

    The disk ``{(1 + (1 - skew)/2 alpha d)/(1 - (1 + skew)/2 alpha d) : |d| <= 1}`` (Seiler et al. 2020,
    eq. 9); its real-axis ends are the gain interval, the largest phase on its unit-circle arc the
    phase margin.

    Examples
    --------
    >>> g_lo, g_hi, pm = disk_gain_phase(0.6646)
    >>> round(float(20 * np.log10(g_hi)), 3), round(pm, 2)
    (6.0, 36.76)
    """
    if not np.isfinite(alpha):
        return 0.0, float("inf"), 180.0
    a, b = (1 - skew) / 2 * alpha, (1 + skew) / 2 * alpha
    g_hi = (1 + a) / (1 - b) if b < 1 else np.inf
    g_lo = max((1 - a) / (1 + b), 0.0)
    if skew == 0.0:
        return float(g_lo), float(g_hi), float(np.degrees(2 * np.arctan(alpha / 2)))  # the balanced disk
    # the largest phase of F on |F| = 1 lies where the unit circle meets the disk's boundary: scan it
    d = np.exp(1j * np.linspace(0, np.pi, 20001))
    with np.errstate(divide="ignore", invalid="ignore"):
        f = (1 + a * d) / (1 - b * d)
    on = np.abs(np.abs(f) - 1.0)
    on[~np.isfinite(on)] = np.inf
    return float(g_lo), float(g_hi), float(np.degrees(np.abs(np.angle(f[np.argmin(on)]))))


@register
class DiskMargin(Requirement):
    """Disk margin ``alpha = 1 / max_w |S(jw) + (skew - 1)/2|`` at least ``min``.

    The loop stays stable for every simultaneous gain and phase change ``F`` in the disk of size
    ``alpha`` and skew ``skew`` (0: balanced, gain changes up and down alike; ``S - 1/2 = (S - T)/2``).
    ``min = 0.6646`` guarantees +-6 dB together with +-36.9 deg. The peak is searched on a log grid
    of ``per_decade`` points per decade and refined locally (its frequency and the grid are in
    ``details``). On a closed loop that is not stable the requirement is not met.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> r = DiskMargin(min=0.5).evaluate(Loop(Plant.from_string("1/(s+1)^3"), Controller("P", {"kp": 2.0})))
    >>> r.met, round(r.value, 4), round(r.details["gain_margin_db"], 2)
    (True, 0.8093, 7.46)
    """

    type: Literal["disk_margin"] = "disk_margin"
    min: PositiveFloat
    skew: float = 0.0
    title: ClassVar[str] = "disk margin"
    bounds: ClassVar[dict[str, Bound]] = {"min": Bound("lower", "")}
    stricter: ClassVar[dict[str, int]] = {}
    example: ClassVar[dict[str, Any]] = {"type": "disk_margin", "min": 0.6}

    @field_validator("skew")
    @classmethod
    def _skew(cls, skew: float) -> float:
        if not -1.0 <= skew <= 1.0:
            raise ValueError(f"skew must be in [-1, 1], got {skew:g}")
        return skew

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        if closed_loop_unstable(loop):
            return unstable_result(self, loop, "disk margin")
        c = (self.skew - 1.0) / 2.0
        lo, hi = loop.frequency_range
        # with points at the loop's narrow peaks: a mode of damping 0.003 at 1234 rad/s put a disk margin of 0.667
        # between two grid points, and 1.04 was reported (found by a black-box test)
        # with w = 0: a negative DC loop gain near -1 peaks there (0.0255 was reported for 0.00501; a black-box test)
        grid = with_narrow_peaks(np.r_[0.0, log_grid(lo, hi * 10, per_decade)], loop, (0.0, np.inf))
        value, w = peak(lambda w: np.abs(loop.S(w) + c), grid)
        limit = high_frequency_limit(value_at_infinity(loop.num, loop.den), loop.delay, c)
        if limit > value:
            value, w = limit, np.inf
        alpha = 1.0 / value if value > 0 else np.inf
        g_lo, g_hi, pm = disk_gain_phase(alpha, self.skew)
        lo_db, hi_db = db(g_lo), db(g_hi)
        slack = float(np.log(alpha / self.min))
        msg = (f"disk margin {fmt(alpha)} >= {fmt(self.min)}: {'met' if slack >= 0 else 'NOT met'} "
               f"(gain {fmt(lo_db)}/+{fmt(hi_db)} dB with +-{fmt(pm)} deg; "
               f"peak at {fmt(w)} rad/s on {per_decade} points/decade, refined)")
        return self.result(value=alpha, bound=self.min, unit="", slack=slack, margin=alpha - self.min,
                           binding_frequency=w, message=msg, skew=self.skew,
                           gain_margin_db=hi_db, lower_gain_margin_db=lo_db,
                           phase_margin_deg=pm, grid_points_per_decade=per_decade,
                           grid=[float(grid[0]), float(grid[-1])])


def high_frequency_limit(l_inf: float, delay: float, c: float) -> float:
    """The supremum of ``|S + c|`` as ``w -> inf``: ``|1/(1 + L(inf)) + c|``; with a delay, ``L(jw)`` circles at
    radius ``|L(inf)|`` and the supremum is over that circle (3,601 angles).

    Examples
    --------
    >>> high_frequency_limit(0.0, 0.1, -0.5), round(high_frequency_limit(0.5, 0.0, -0.5), 4)
    (0.5, 0.1667)
    >>> round(high_frequency_limit(0.5, 0.1, -0.5), 4)  # 1/(1 - 0.5) - 0.5
    1.5
    """
    if l_inf == 0.0 or delay == 0.0:
        return float(abs(1.0 / (1.0 + l_inf) + c)) if l_inf != -1.0 else float("inf")
    circle = abs(l_inf) * np.exp(1j * np.linspace(0.0, 2.0 * np.pi, 3601))
    with np.errstate(divide="ignore"):
        return float(np.max(np.abs(1.0 / (1.0 + circle) + c)))
