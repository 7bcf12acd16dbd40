"""Every loop's closed-loop bandwidth at once: :meth:`synth.loop.Loop.bandwidth` for each row of a
:class:`synth.loop_batch.LoopBatch`, on each row's own grid, in one vectorized search."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from synth.first_crossing import batch_first_crossing
from synth.freqgrid import log_grid_sizes, log_grids

if TYPE_CHECKING:
    from synth.loop_batch import LoopBatch

__all__ = ["batch_bandwidths"]

CHUNK = 256
"""Loops searched together: rows of similar grid lengths (sorted), so that little of the padding is evaluated."""


def batch_bandwidths(batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
    """Each loop's ``Loop.bandwidth(per_decade)``: the first fall of ``|T|`` 3 dB below ``|T(0)|`` on the loop's
    own log grid (its frequency range, widened around its gain crossovers), a dip narrower than the grid
    included; ``nan`` where ``T(0)`` is 0 or not finite, ``inf`` where ``|T|`` does not fall that far.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.loop_batch import LoopBatch
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
    >>> cs = [Controller("PI", {"kp": k, "ki": 2.0 * k}) for k in (0.5, 1.0, 2.0)]
    >>> [round(float(w), 6) for w in batch_bandwidths(LoopBatch(G, cs))]
    [1.880124, 34.310076, 103.578655]
    >>> [round(Loop(G, c).bandwidth(), 6) for c in cs]
    [1.880124, 34.310076, 103.578655]
    """
    from synth.loop import BANDWIDTH_LEVEL, Loop, bandwidth_span
    from synth.loop_batch import LoopBatch

    t0 = batch.T0()
    out = np.full(len(batch), np.nan)
    spans = [bandwidth_span(lo, hi, w) for (lo, hi), w in zip(batch.frequency_ranges, batch.gain_crossovers())]
    lo, hi = np.array(spans, float).reshape(-1, 2).T
    with np.errstate(all="ignore"):
        decades = np.log10(hi / lo)
    measured = (t0 != 0.0) & np.isfinite(t0)
    odd = measured & ~((lo > 0) & np.isfinite(decades))
    for i in np.flatnonzero(odd):  # a grid log_grid refuses: the loop's own answer (its error)
        out[i] = Loop(batch.plant, batch.controllers[i]).bandwidth(per_decade)
    rows = np.flatnonzero(measured & ~odd)
    sizes = np.zeros(len(batch), int)
    sizes[rows] = log_grid_sizes(lo[rows], hi[rows], per_decade)
    if rows.size > CHUNK:
        rows = rows[np.argsort(sizes[rows], kind="stable")]
    for start in range(0, rows.size, CHUNK):
        chunk = rows[start:start + CHUNK]
        part = batch if chunk.size == len(batch) else LoopBatch(batch.plant, [batch.controllers[i] for i in chunk])
        grid = log_grids(lo[chunk], hi[chunk], per_decade)
        with np.errstate(all="ignore"):
            cross, below = batch_first_crossing(lambda w, part=part: np.abs(part.T(w)), t0[chunk] * BANDWIDTH_LEVEL,
                                                grid, sizes[chunk])
        out[chunk] = np.where(below, grid[:, 0], np.where(np.isfinite(cross), cross, np.inf))
    return out
