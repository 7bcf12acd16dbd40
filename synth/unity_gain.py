"""The frequency where a plant without corner frequencies crosses unity gain: the scale of its loops."""

from __future__ import annotations

import numpy as np

from synth.freqgrid import corner_frequencies

__all__ = ["unity_gain_frequency"]


def unity_gain_frequency(num: np.ndarray, den: np.ndarray) -> float | None:
    """For ``num/den = k s^r`` with every root at the origin and ``r != 0`` (an integrator, a double integrator, a
    differentiator: no corner frequency) the frequency where ``|k| w^r = 1``, where a loop around it crosses over;
    None otherwise.

    Examples
    --------
    >>> unity_gain_frequency(np.array([4.0]), np.array([1.0, 0.0, 0.0]))
    2.0
    >>> unity_gain_frequency(np.array([1.0]), np.array([1.0, 1.0])) is None
    True
    """
    num, den = np.trim_zeros(np.asarray(num, float), "f"), np.trim_zeros(np.asarray(den, float), "f")
    if num.size == 0 or den.size == 0 or num.size == den.size or not np.isnan(corner_frequencies(num, den)[0]):
        return None
    return float(abs(num[0] / den[0]) ** (-1.0 / (num.size - den.size)))
