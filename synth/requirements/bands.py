"""A frequency band in rad/s, as requirements give one: ``[low, high]`` with ``0 <= low < high``, both finite."""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, field_validator

__all__ = ["BandMixin", "check_band"]


class BandMixin(BaseModel):
    """A frequency band ``[low, high]`` in rad/s with ``0 <= low < high``."""

    band: tuple[float, float]

    @field_validator("band")
    @classmethod
    def _check_band(cls, band: tuple[float, float]) -> tuple[float, float]:
        return check_band(band)


def check_band(band: tuple[float, float]) -> tuple[float, float]:
    """``band`` if it is ``[low, high]`` with ``0 <= low < high`` finite (rad/s), else ValueError.

    Examples
    --------
    >>> check_band((0.0, 30.0))
    (0.0, 30.0)
    """
    lo, hi = band
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise ValueError(f"band must be finite, got [{lo:g}, {hi:g}]")
    if lo < 0 or hi <= 0:
        raise ValueError(f"band must be non-negative frequencies in rad/s, got [{lo:g}, {hi:g}]")
    if hi <= lo:
        raise ValueError(f"band must be [low, high] with low < high, got [{lo:g}, {hi:g}]")
    return band
