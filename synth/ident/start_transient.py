"""A whole-record fit that misses the record's start: the plant was not at rest at the first input.

A whole-record fit assumes that before the first sample the input was the first sample's value and the plant had
settled there (:mod:`synth.ident.sim_error_problem`). A record that begins just after a step (the input already at
its new level, the output still at the old one) breaks that: the model cannot follow the first transient, and the
least-squares fit bends every parameter to soften the miss. The check compares the residuals over the fitted
model's settling time from the start with those after it; far larger residuals there make the fit a failure, with
what to try instead.
"""

from __future__ import annotations

import numpy as np

__all__ = ["START_FACTOR", "start_transient_failure"]

#: the start's residual RMS over the rest's above which the fit misses the start
START_FACTOR = 3.0


def start_transient_failure(t: np.ndarray, y: np.ndarray, yhat: np.ndarray, settle: float) -> str:
    """Why a whole-record fit misses its start, or ``""``.

    Parameters
    ----------
    t, y, yhat : numpy.ndarray
        Time [s], the measured and the fitted output.
    settle : float
        The fitted model's settling time [s]: the start window (at most a quarter of the record).

    Examples
    --------
    >>> t = np.arange(0.0, 20.0, 0.01)
    >>> y = np.where(t < 2.0, -np.exp(-t), 0.0) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> start_transient_failure(t, y, np.zeros(t.size), 2.0)[:60]
    "the model misses the record's first 2 s by 50 times its resi"
    >>> start_transient_failure(t, y - np.where(t < 2.0, -np.exp(-t), 0.0), np.zeros(t.size), 2.0)
    ''
    """
    if not np.isfinite(settle) or settle <= 0:
        return ""
    window = min(settle, 0.25 * float(t[-1] - t[0]))
    head = (t - t[0]) < window
    if np.count_nonzero(head) < 20 or np.count_nonzero(~head) < 20:
        return ""
    r = y - yhat
    first, rest = float(np.sqrt(np.mean(r[head] ** 2))), float(np.sqrt(np.mean(r[~head] ** 2)))
    if not first > START_FACTOR * rest:
        return ""
    return (f"the model misses the record's first {window:.3g} s by {first / rest:.2g} times its residual after "
            f"them (RMS {first:.3g} against {rest:.3g}): the plant was not at rest at the first input sample (a step "
            "at or just before the start?), which a whole-record fit assumes, so every parameter is biased; cut the "
            "record to start at rest, or fit the steps from rest (--average edge)")

