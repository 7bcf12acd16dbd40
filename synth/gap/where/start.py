"""A residual that starts large and decays: the record does not start at rest at its first command.

The model is simulated from rest at the record's first command (:func:`synth.ident.simulate.simulate_plant`,
``initial="steady"``). A record that starts in motion (a reference step at its first sample, a loop still
settling) leaves the model's own transient in the residual, which then reads as a gap and a drift. The
transient decays with the model's slowest pole, so it is seen in the first five of its time constants.
"""

from __future__ import annotations

import numpy as np

from synth.gap.where.residual import ModelResidual
from synth.plant import Plant

__all__ = ["start_transient_warning"]


def start_transient_warning(plant: Plant, residual: ModelResidual, ratio: float = 3.0) -> str:
    """A sentence when the residual's first five slowest time constants hold a decaying transient, else "".

    The window's residual must be ``ratio`` times the rest's rms and its first third ``ratio`` times its
    last third (a decay, not a gap that lasts). The window is at most a quarter of the record; not judged (""):
    a model without a stable slowest pole, or a record whose quarter holds fewer than two slowest time constants.

    Parameters
    ----------
    plant : Plant
        The nominal model.
    residual : ModelResidual
        Its residual on the record (:func:`synth.gap.where.residual.model_residual`).
    ratio : float
        The factor both tests need.

    Returns
    -------
    str

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.gap.where.residual import model_residual
    >>> from synth.ident.simulate import simulate_plant
    >>> G = Plant.from_string("1/(s+1)")
    >>> t = np.arange(0, 40, 0.01); u = np.where(t % 8 < 4, 1.0, -1.0)
    >>> noise = 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> y = simulate_plant(G, t, u, initial="zero") + noise  # at rest at zero input, the command 1 at once
    >>> start_transient_warning(G, model_residual(G, record_from_arrays(t, u, y)))[:49]
    'the residual in the first 5 s is 32 times its rms'
    >>> start_transient_warning(G, model_residual(G, record_from_arrays(t, u, simulate_plant(G, t, u) + noise)))
    ''
    """
    poles = plant.poles()
    if poles.size == 0 or np.max(poles.real) >= 0.0:
        return ""
    tau = 1.0 / float(np.min(np.abs(poles.real)))
    t = residual.t - residual.t[0]
    window = min(5.0 * tau, 0.25 * t[-1])  # a record of 20 time constants or less: its first quarter
    first = t < window
    if window < 2.0 * tau or np.count_nonzero(first) < 9:
        return ""
    e = residual.e - np.median(residual.e[~first])
    rest = float(np.sqrt(np.mean(e[~first] ** 2)))
    head = float(np.sqrt(np.mean(e[first] ** 2)))
    thirds = np.array_split(np.abs(e[first]), 3)
    if head <= ratio * rest or np.mean(thirds[0]) <= ratio * np.mean(thirds[2]):
        return ""
    moved = np.flatnonzero(np.abs(residual.u - residual.u[0]) > 1e-9 * max(float(np.ptp(residual.u)), 1e-300))
    still = int(moved[0]) if moved.size else residual.u.size
    if still >= 5 and float(np.sqrt(np.mean(e[:still] ** 2))) <= ratio * rest:
        return ""  # quiet until the first command change: the transient is the model's answer to it, not the start's
    return (f"the residual in the first {window:.3g} s is {head / max(rest, 1e-300):.2g} times its rms after, "
            "and decays: the record may not start at rest at its first command, which the model assumes; "
            f"a transient there reads as a gap and a drift (give --burn-in {window:.3g} or a record that starts "
            "at rest)")
