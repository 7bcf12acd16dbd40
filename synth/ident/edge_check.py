"""Whether an edge average's model explains the whole record.

Edge windows assume the plant at rest before each step and its response inside the window. A delay longer than
the windows breaks both, and the edge fit can then be a confident wrong model that settles within its windows
(a 30 %-duty train of 1.6 s behind 2.05 s: ``K = -0.63``, no delay, exit 0; a black-box test). The model's
response from rest over the whole record, against the record's own noise level (:func:`noise_sigma`), tells.
"""

from __future__ import annotations

import numpy as np

from synth.data.record import Record
from synth.ident.noise_floor import noise_sigma
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["EDGE_MISFIT", "edge_misfit"]

EDGE_MISFIT = 10.0
"""Ratio of the whole record's residual RMS under the edge model to the record's noise level above which the
edge fit does not stand alone (the whole record is then fitted from it and from its own start). A model that
is right leaves the noise (about 1); a direction-dependent plant fitted by its average, or coloured noise, a few
times it; an alias of a long delay, the step itself."""


def edge_misfit(record: Record, model: Plant, weights: np.ndarray | None) -> float:
    """RMS of ``y - model u`` over the weighted samples (the model from rest at the first input, its output offset
    fitted), over the record's white-noise level; ``inf`` when the noise level is 0.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 40, 0.01); u = ((t % 4) >= 2).astype(float)
    >>> y = simulate_plant(Plant.from_string("1/(0.1*s+1)", delay=2.5), t, u, initial="zero")
    >>> rec = record_from_arrays(t, u, y + 0.01 * np.random.default_rng(0).normal(size=t.size))
    >>> round(float(edge_misfit(rec, Plant.from_string("1/(0.1*s+1)", delay=2.5), None)), 1)
    1.0
    >>> edge_misfit(rec, Plant.from_string("-1/(0.1*s+1)", delay=0.5), None) > EDGE_MISFIT  # its alias: the start differs
    True
    """
    w = np.ones(record.y.size) if weights is None else np.asarray(weights, float)
    yhat = simulate_plant(model, record.t, record.u - record.u[0], initial="zero")
    r = record.y - yhat
    r = r - float(np.dot(w, r) / w.sum())
    rms = float(np.sqrt(np.dot(w, r * r) / w.sum()))
    floor = noise_sigma(record.y)
    return float(rms / floor) if floor > 0 else float("inf")
