"""Frequencies where a closed-loop pole near the imaginary axis makes a peak narrower than a log grid's spacing.

A closed-loop pole ``sigma + j w0`` puts a peak of width about ``|sigma|`` into ``|S|``, ``|T|`` and ``|KS|`` at
``w0``. Where an open-loop pole or zero sits next to it, the two nearly cancel and nothing of the peak shows
more than ``|sigma|`` away from ``w0``: a rational controller with poles at ``0.008 +- 26.41j`` around
``0.705 / ((s + 0.173)(s + 0.627)) e^(-0.102 s)`` closes the loop with poles at ``-0.0008 +- 26.405j``, and
``|S|`` reaches 21.5 dB within 0.002 rad/s of 26.405 rad/s while a grid of 1600 points per decade (0.04 rad/s
apart there) saw 1.9 dB (design benchmark, seed 8 #88). The peak requirements add these frequencies to their
grids; the grid's local maxima are then refined as usual.
"""

from __future__ import annotations

import numpy as np

__all__ = ["LIGHT_DAMPING", "OFFSETS", "narrow_peak_frequencies"]

LIGHT_DAMPING = 0.01
"""Closed-loop poles damped below this get points of their own (a log grid of 80 points per decade, 2.9 % apart,
resolves a peak of relative width ``2 zeta`` down to about this)."""

OFFSETS = np.array([0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0])
"""Points at ``w0 +- k |sigma|`` for these ``k``."""


def narrow_peak_frequencies(poles: np.ndarray) -> np.ndarray:
    """Sorted positive frequencies around every closed-loop pole in ``poles`` damped below :data:`LIGHT_DAMPING`
    (:meth:`synth.loop.Loop.narrow_peaks` passes the loop's, with a delay the dominant ones); empty when there is
    none.

    Examples
    --------
    >>> w = narrow_peak_frequencies(np.array([-0.0008 + 26.405j, -0.0008 - 26.405j, -0.19 + 0j]))
    >>> bool(np.any(np.abs(w - 26.405) < 1e-9)), float(w.min().round(4)), float(w.max().round(4))
    (True, 26.3922, 26.4178)
    >>> narrow_peak_frequencies(np.array([-1.0 + 1.0j, -1.0 - 1.0j])).size
    0
    """
    poles = np.asarray(poles, complex)
    poles = poles[np.isfinite(poles) & (poles.imag > 0)]
    light = poles[np.abs(poles.real) < LIGHT_DAMPING * np.abs(poles)]
    if light.size == 0:
        return np.zeros(0)
    width = np.maximum(np.abs(light.real), 1e-9 * np.abs(light))
    offsets = np.concatenate([-OFFSETS[::-1], OFFSETS[1:]])
    points = (light.imag[:, None] + width[:, None] * offsets[None, :]).ravel()
    return np.unique(points[points > 0])
