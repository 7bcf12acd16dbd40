"""Gaps in a log's time stamps: where they are, what they hid, which resampled samples they made up.

A logger that drops out for a while leaves an interval between two time stamps many times the usual one.
Resampling onto a uniform grid fills that interval: the output by a straight line between the two logged
samples, the command held at its level before the gap. Neither is a measurement: an output sample inside
a gap is made up, and a command that changed inside the gap shows its edge late, at the gap's end (the log
does not say when it came). A fit or an average that takes those samples at face value is biased (a 0.3 s
dropout hiding one edge of a 40 s step train put the gain 3 % off, 44 of its standard errors). Gaps are found
here, kept on the :class:`~synth.data.record.Record`, and given weight 0 (:func:`gap_weights`) or left out of
an average.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["GAP_FACTOR", "find_gaps", "gap_mask", "gap_weights", "hidden_changes"]

GAP_FACTOR = 5.0
"""An interval between time stamps this many times the median is a gap in the log."""


def find_gaps(tt: np.ndarray) -> tuple[tuple[float, float], ...]:
    """The gaps of increasing time stamps ``tt``: the stamps ``(before, after)`` around each interval longer
    than :data:`GAP_FACTOR` times the median interval.

    Examples
    --------
    >>> t = np.r_[np.arange(0, 1, 0.01), np.arange(1.3, 2, 0.01)]
    >>> [(round(a, 2), round(b, 2)) for a, b in find_gaps(t)]
    [(0.99, 1.3)]
    >>> find_gaps(np.arange(0, 1, 0.01))
    ()
    """
    tt = np.asarray(tt, float)
    return tuple((float(tt[k]), float(tt[k + 1])) for k in _gap_index(tt))


def _gap_index(tt: np.ndarray) -> np.ndarray:
    """Index ``k`` of each gap ``tt[k]``-``tt[k + 1]``."""
    if tt.size < 3:
        return np.zeros(0, dtype=int)
    steps = np.diff(tt)
    return np.flatnonzero(steps > GAP_FACTOR * np.median(steps))


def gap_mask(t: np.ndarray, gaps: Sequence[tuple[float, float]]) -> np.ndarray:
    """Samples of the grid ``t`` that a gap made up: strictly inside a gap, or at its end when that is not a
    logged stamp's time to rounding (the grid's own sample there, the first the log holds again, is kept).

    Examples
    --------
    >>> t = np.arange(0, 2, 0.1)
    >>> np.flatnonzero(gap_mask(t, [(0.5, 0.9)])).tolist()
    [6, 7, 8]
    """
    t = np.asarray(t, float)
    out = np.zeros(t.size, dtype=bool)
    tol = _tolerance(t)
    for before, after in gaps:
        out |= (t > before + tol) & (t < after - tol)
    return out


def gap_weights(t: np.ndarray, u: np.ndarray, gaps: Sequence[tuple[float, float]], settle: float = 0.0,
                weights: np.ndarray | None = None) -> np.ndarray | None:
    """0/1 weights of a fit that leave out what gaps made up: the samples inside each gap, and after a gap across
    which the command ``u`` changed (its edge came at an unknown time inside), or one longer than the command's
    shortest hold (it may hide a change and its return), the next ``settle`` seconds too, while the response to
    what it hid differs from the simulated one. ``weights``, if given, are multiplied in. ``None`` when there is
    nothing to leave out and no ``weights``.

    Examples
    --------
    >>> t = np.arange(0, 3, 0.1); u = (t >= 1.0) * 1.0
    >>> w = gap_weights(t, u, [(0.7, 1.0)], settle=0.5)
    >>> np.flatnonzero(w == 0).tolist()   # 0.8, 0.9 made up; the edge at 1.0 late by up to 0.3 s: to 1.5 s
    [8, 9, 10, 11, 12, 13, 14]
    >>> gap_weights(t, u, []) is None
    True
    """
    if not gaps:
        return weights
    t, u = np.asarray(t, float), np.asarray(u, float)
    keep = ~gap_mask(t, gaps)
    tol = _tolerance(t)
    changes = t[np.flatnonzero(np.diff(u) != 0) + 1]
    shortest = float(np.min(np.diff(changes))) if changes.size > 1 else np.inf  # the command's shortest hold
    for before, after in gaps:
        k0, k1 = np.searchsorted(t, [before, after], side="left")
        k1 = min(int(k1), t.size - 1)
        # a change shows as a different level at the gap's ends; a gap longer than a hold may hide two
        if u[k1] != u[min(int(k0), t.size - 1)] or after - before > shortest:
            keep &= ~((t > before + tol) & (t < after + settle - tol))
    out = keep.astype(float)
    return out if weights is None else out * np.asarray(weights, float)


def _tolerance(t: np.ndarray) -> float:
    """Times within this of a logged stamp are that stamp (a grid rebuilt by ``linspace`` differs by rounding)."""
    return 1e-9 * max(1.0, float(np.max(np.abs(t)))) if t.size else 0.0


def hidden_changes(tt: np.ndarray, arrays: dict[str, np.ndarray], held: list[str]) -> tuple[str, ...]:
    """A note for each held column (the command) that changed across a gap in the time stamps ``tt``: the record
    does not say when.

    Examples
    --------
    >>> t = np.r_[np.arange(0, 1, 0.01), np.arange(1.3, 2, 0.01)]; u = (t > 1.1) * 1.0
    >>> hidden_changes(t, {"u": u}, ["u"])[0][:60]
    "'u' changed inside a 0.31 s gap in the time stamps (t = 0.99"
    """
    gaps, out = _gap_index(tt), []
    for h in held:
        hidden = [k for k in gaps if arrays[h][k + 1] != arrays[h][k]]
        if hidden:
            k = hidden[0]
            more = f" (and {len(hidden) - 1} more)" if len(hidden) > 1 else ""
            out.append(f"'{h}' changed inside a {tt[k + 1] - tt[k]:.3g} s gap in the time stamps (t = {tt[k]:.6g}-"
                       f"{tt[k + 1]:.6g} s){more}: the record does not say when; the command as logged holds its old "
                       "level to the gap's end, so that edge shows late: averages leave out the steps around it, and "
                       "fits give its gap and the settling after it a weight of 0")
    return tuple(out)
