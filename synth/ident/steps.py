"""Step trains: find the input steps, cut and align the responses, average them.

Two ways of averaging, chosen from the edges found:

- ``"cycle"``: the input is a periodic square wave (up and down steps
  alternate, every period and every high time the same to one sample). Whole
  periods are cut, each starting at the down step before an up step, and
  averaged; every period holds one up and one down step, so both are averaged
  with their sign kept, and the average is one period of a periodic signal.
  The first period (the one holding the record's first step) is dropped: the
  plant enters the train from its earlier state, not from the periodic regime
  a periodic fit assumes.
- ``"edge"``: any other train. A window around each step (``pre`` samples
  before it, as many after as the shortest gap to the next step allows) is cut,
  its pre-step level subtracted, and down steps are sign-flipped, so every
  window is a rising step from 0; the windows are averaged. This assumes the
  plant is at rest before each step (make the gaps long enough).

Signal-to-noise ratio (the definition used everywhere here)
------------------------------------------------------------
``SNR = 20 log10(step / sigma)`` in dB, with ``step`` the output step size of
the averaged response (mean over the last 10 % of the high part minus the mean
over the last 10 % of the low part before it, in ``"cycle"`` mode; the mean
over the last 10 % of the window minus the pre-step mean, in ``"edge"`` mode)
and ``sigma`` the standard deviation of the noise:

- before averaging, ``sigma`` is estimated from the spread of the single
  windows about their mean, ``sum((y_i - mean)^2) / ((N - 1) L)`` over ``N``
  windows of ``L`` samples (for one window: ``std(diff(y))/sqrt(2)``, white noise);
- after averaging, ``sigma`` is measured, not assumed: the windows are split
  into even and odd ones, ``sigma_after = std(mean_even - mean_odd) /
  sqrt(1/N_even + 1/N_odd) / sqrt(N)``. For noise independent from window to
  window this equals ``sigma_before / sqrt(N)`` (10 log10 N dB of gain);
  correlated noise or drift shows up as less gain.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import pairwise
from typing import Any

import numpy as np

from synth.data.gaps import gap_mask
from synth.data.record import Record, record_from_arrays
from synth.errors import DataError
from synth.plant import Signal

__all__ = ["StepAverage", "Steps", "average_steps", "find_steps", "late_steps"]


@dataclass(frozen=True)
class Steps:
    """Steps found in the input: where, which way, between which levels.

    Attributes
    ----------
    index : numpy.ndarray
        Sample index of the first sample past the switching threshold.
    direction : numpy.ndarray
        ``+1`` for an up step, ``-1`` for a down step.
    low, high : float
        Input levels (medians of the input in the low and high state).
    """

    index: np.ndarray
    direction: np.ndarray
    low: float
    high: float

    @property
    def count(self) -> int:
        """Number of steps."""
        return int(self.index.size)

    def to_dict(self) -> dict[str, Any]:
        """JSON summary.

        Examples
        --------
        >>> Steps(np.array([3, 6]), np.array([1, -1]), 0.0, 1.0).to_dict()["up"]
        1
        """
        return {"count": self.count, "up": int(np.sum(self.direction > 0)), "down": int(np.sum(self.direction < 0)),
                "low": self.low, "high": self.high}


def find_steps(record: Record, hysteresis: float = 0.2) -> Steps:
    """Find the steps of a two-level input.

    The input is compared with a Schmitt trigger at ``low + (0.5 +- hysteresis)
    (high - low)`` of its range, so noise on the input does not make extra steps. A step is at the first
    sample past the trigger, or at the one before when that sample has left the old level (by more than a tenth
    of the range) and the one before it had not: an edge inside a sample interval (a resampled record holds the
    interval's mean command there), whose window must not count that sample as before the step.

    Parameters
    ----------
    record : Record
    hysteresis : float
        Half-width of the dead band as a fraction of the input range (0 to 0.5).

    Raises
    ------
    DataError
        If the input never crosses its mid-range (no step).

    Examples
    --------
    >>> t = np.arange(10) * 0.1
    >>> r = record_from_arrays(t, [0, 0, 1, 1, 1, 0, 0, 1, 1, 1], t ** 2)
    >>> s = find_steps(r)
    >>> s.index.tolist(), s.direction.tolist()
    ([2, 5, 7], [1, -1, 1])
    """
    if not 0 <= hysteresis < 0.5:
        raise DataError(f"hysteresis must be in [0, 0.5), got {hysteresis}")
    u = record.u
    lo, hi = float(np.min(u)), float(np.max(u))
    if not hi > lo:  # both thresholds would be the one level: the search below would never advance
        raise DataError(f"column '{record.input.name}': the input is constant ({lo:g}): no step in it",
                        where=record.source)
    upper, lower = lo + (0.5 + hysteresis) * (hi - lo), lo + (0.5 - hysteresis) * (hi - lo)
    state = u[0] > 0.5 * (lo + hi)
    index, direction = [], []
    above, below = u >= upper, u <= lower
    near_low, near_high = u <= lo + 0.1 * (hi - lo), u >= hi - 0.1 * (hi - lo)
    k = 0
    n = u.size
    while k < n:
        nxt = np.flatnonzero(below[k:] if state else above[k:])
        if not nxt.size:
            break
        k += int(nxt[0])
        old_level = near_high if state else near_low
        edge = k
        if k >= 2 and not old_level[k - 1] and old_level[k - 2] and (not index or k - 1 > index[-1]):
            edge = k - 1  # one sample already off the old level: the edge is inside its interval (e.g. resampled)
        state = not state
        index.append(edge)
        direction.append(1 if state else -1)
        k += 1  # the next level change comes after this sample (a sample on both thresholds counts once)
    if not index:
        raise DataError(f"column '{record.input.name}': no step found in the input", where=record.source)
    high_mask = u > 0.5 * (lo + hi)
    return Steps(np.asarray(index), np.asarray(direction), float(np.median(u[~high_mask])),
                 float(np.median(u[high_mask])))


@dataclass(frozen=True, eq=False)
class StepAverage:
    """Aligned and averaged step responses.

    Attributes
    ----------
    mode : str
        ``"cycle"`` (one averaged period of a periodic train) or ``"edge"``
        (one averaged, sign-normalized rising step).
    t : numpy.ndarray
        Time [s] in the window, 0 at the (up) step.
    u, y : numpy.ndarray
        Averaged input and output over the window.
    count : int
        Number of windows averaged.
    up, down : int
        Up and down steps inside the averaged windows.
    dropped : int
        Windows not used (the first period in ``"cycle"`` mode; in ``"edge"`` mode a last step closer to the
        record's end than the shortest time between two steps; in both, windows that hold a gap in the log).
    step_size : float
        Output step size of the averaged response (see the module docstring).
    noise_std_before, noise_std_after : float
        Noise standard deviation of one window and of the average.
    snr_before_db, snr_after_db : float
        ``20 log10(step_size / noise_std)``.
    periodic : bool
        ``True`` in ``"cycle"`` mode: fit the average with a periodic initial state.
    steps : Steps
        The steps found in the record.
    first_window : int
        Sample of the record where the first averaged window starts (``"cycle"`` mode; 0 otherwise).
    noise_factor : float
        The record's :attr:`~synth.data.Record.noise_factor`, carried to :meth:`record`.
    in_gaps : int
        Windows left out because they hold samples a gap in the log made up (:mod:`synth.data.gaps`; counted in
        ``dropped`` too).
    noise_correlation : tuple of float
        The record's :attr:`~synth.data.Record.noise_correlation`, carried to :meth:`record` (averaging windows of
        independent noise keeps it).
    """

    mode: str
    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    count: int
    up: int
    down: int
    dropped: int
    step_size: float
    noise_std_before: float
    noise_std_after: float
    snr_before_db: float
    snr_after_db: float
    periodic: bool
    steps: Steps
    input: Signal = field(default_factory=lambda: Signal("u", ""))
    output: Signal = field(default_factory=lambda: Signal("y", ""))
    source: str = "arrays"
    up_index: int = 0
    first_window: int = 0
    noise_factor: float = 1.0
    in_gaps: int = 0
    noise_correlation: tuple[float, ...] = ()

    def record(self) -> Record:
        """The averaged window as a :class:`~synth.data.Record` (time starting at the window's start).

        Examples
        --------
        >>> from synth.ident.x4_record import x4_step_train
        >>> avg = average_steps(x4_step_train(periods=3))
        >>> avg.record().n
        6000
        """
        return record_from_arrays(self.t, self.u, self.y, self.input, self.output,
                                  source=f"{self.source} (average of {self.count} {self.mode}s)",
                                  noise_factor=self.noise_factor, noise_correlation=self.noise_correlation)

    def to_dict(self) -> dict[str, Any]:
        """JSON summary (no samples).

        Examples
        --------
        >>> from synth.ident.x4_record import x4_step_train
        >>> d = average_steps(x4_step_train(periods=3)).to_dict()
        >>> d["mode"], d["count"], d["up"], d["down"]
        ('cycle', 2, 2, 2)
        """
        return {"mode": self.mode, "count": self.count, "up": self.up, "down": self.down, "dropped": self.dropped,
                "window": float(self.t[-1] - self.t[0] + (self.t[1] - self.t[0])), "samples": int(self.t.size),
                "step_size": self.step_size, "noise_std_before": self.noise_std_before,
                "noise_std_after": self.noise_std_after, "snr_before_db": self.snr_before_db,
                "snr_after_db": self.snr_after_db, "snr_gain_db": self.snr_after_db - self.snr_before_db,
                "periodic": self.periodic, "steps": self.steps.to_dict(), "in_gaps": self.in_gaps}


def _is_periodic(steps: Steps, late: np.ndarray) -> tuple[int, int] | None:
    """``(period, high samples)`` if the steps alternate at a constant period (to one sample), not counting the
    intervals that end or start at a step marked ``late`` (its edge hidden in a gap of the log, :func:`late_steps`)."""
    d, i = steps.direction, steps.index
    if np.sum(d > 0) < 2 or np.any(d[1:] == d[:-1]):
        return None
    up = np.flatnonzero(d > 0)
    periods = [int(i[b] - i[a]) for a, b in pairwise(up) if not (late[a] or late[b])]
    high_times = [int(i[k + 1] - i[k]) for k in range(i.size - 1) if d[k] > 0 and not (late[k] or late[k + 1])]
    if not periods or not high_times or np.ptp(periods) > 1 or np.ptp(high_times) > 1:
        return None
    return int(np.min(periods)), int(np.min(high_times))


def late_steps(record: Record, steps: Steps) -> np.ndarray:
    """Steps whose edge a gap in the log hid: the sample before the step was made up by the gap
    (:func:`synth.data.gaps.gap_mask`), so the step shows at the gap's end, late by up to the gap.

    Examples
    --------
    >>> t = np.r_[np.arange(0, 1, 0.01), np.arange(1.3, 3, 0.01)]
    >>> rec = record_from_arrays(t, ((t > 1.1) & (t < 2)) * 1.0, np.sin(t))
    >>> late_steps(rec, find_steps(rec)).tolist()   # the up step hidden in the gap, the down step on time
    [True, False]
    """
    made_up = gap_mask(record.t, record.gaps)
    return made_up[np.maximum(steps.index - 1, 0)]


def _clear(record: Record, starts: np.ndarray, length: int) -> np.ndarray:
    """Windows ``[start, start + length)`` that hold no sample a gap in the log made up."""
    made_up = np.concatenate([[0], np.cumsum(gap_mask(record.t, record.gaps))])
    lo, hi = np.clip(starts, 0, record.n), np.clip(starts + length, 0, record.n)
    return made_up[hi] - made_up[lo] == 0


def _noise(windows: np.ndarray) -> tuple[float, float]:
    n = windows.shape[0]
    if n == 1:
        sigma = float(np.std(np.diff(windows[0])) / np.sqrt(2.0))
        return sigma, sigma
    mean = windows.mean(axis=0)
    before = float(np.sqrt(np.sum((windows - mean) ** 2) / ((n - 1) * windows.shape[1])))
    even, odd = windows[0::2].mean(axis=0), windows[1::2].mean(axis=0)
    ne, no = windows[0::2].shape[0], windows[1::2].shape[0]
    after = float(np.std(even - odd) / np.sqrt(1.0 / ne + 1.0 / no) / np.sqrt(n))
    return before, after


def _snr(step: float, sigma: float) -> float:
    return float(20.0 * np.log10(abs(step) / sigma)) if sigma > 0 else float("inf")


def average_steps(record: Record, steps: Steps | None = None, mode: str = "auto", pre: float | None = None,
                  direction: int = 0, settle: float = 0.0, post: int | None = None) -> StepAverage:
    """Cut, align and average the step responses of a record.

    Parameters
    ----------
    record : Record
    steps : Steps, optional
        From :func:`find_steps` (found here if not given).
    mode : {"auto", "cycle", "edge"}
        ``"auto"`` picks ``"cycle"`` for a periodic square wave, else ``"edge"``.
    pre : float, optional
        ``"edge"`` mode: seconds kept before each step (default a tenth of the
        window, at most the time before the first step).
    direction : {0, 1, -1}
        ``"edge"`` mode: average every step (0), only the up steps (1) or only the down
        steps (-1, sign-flipped); the windows are as long as with all steps. A direction
        other than 0 implies ``"edge"``.
    settle : float
        ``"cycle"`` mode: average only the periods that start this long [s] after the first step.
    post : int, optional
        ``"edge"`` mode: samples kept from each step on (default the shortest time between two of ``steps``; give
        it when ``steps`` leaves out steps of the record, whose windows must end before the next step).

    Returns
    -------
    StepAverage

    Raises
    ------
    DataError
        No step, ``"cycle"`` asked for a non-periodic train, or windows too short.

    Examples
    --------
    >>> from synth.ident.x4_record import x4_step_train
    >>> avg = average_steps(x4_step_train())
    >>> avg.mode, avg.count, avg.dropped, round(avg.snr_before_db), round(avg.snr_after_db)
    ('cycle', 69, 1, 39, 57)
    >>> average_steps(x4_step_train(), settle=10.0).count          # periods from 10 s after the first step
    67
    >>> down = average_steps(x4_step_train(), direction=-1)
    >>> down.mode, down.count, (down.up, down.down), down.step_size > 0
    ('edge', 69, (0, 69), True)
    """
    if mode not in ("auto", "cycle", "edge"):
        raise DataError(f"mode must be 'auto', 'cycle' or 'edge', got {mode!r}")
    if direction not in (0, 1, -1):
        raise DataError(f"direction must be 0 (all steps), 1 (up) or -1 (down), got {direction!r}")
    steps = steps or find_steps(record)
    if direction:
        if mode == "cycle":
            raise DataError("a periodic average holds both directions; average one direction with mode='edge'")
        if not np.any(steps.direction == direction):
            raise DataError(f"no {'up' if direction > 0 else 'down'} step in the input", where=record.source)
        return _average_edges(record, steps, pre, direction, post)
    periodic = _is_periodic(steps, late_steps(record, steps))
    if mode == "cycle" and periodic is None:
        raise DataError("the input is not a periodic square wave (steps must alternate at a constant period); "
                        "use mode='edge'", where=record.source)
    if mode == "cycle" or (mode == "auto" and periodic is not None):
        return _average_cycles(record, steps, *periodic, settle)  # type: ignore[misc]
    return _average_edges(record, steps, pre, window=post)


def _average_cycles(record: Record, steps: Steps, period: int, high: int, settle: float = 0.0) -> StepAverage:
    low_time = period - high
    ups = steps.index[steps.direction > 0]
    starts = ups - low_time
    keep = (starts >= 0) & (starts + period <= record.n)
    first = int(np.argmax(keep)) if np.any(keep) else 0
    keep &= starts - steps.index[0] >= settle / record.dt - 1e-9
    clear = _clear(record, starts, period)
    in_gaps = int(np.sum(keep & ~clear))
    keep &= clear
    use = [s for j, s in enumerate(starts) if keep[j] and j > first]  # drop the period holding the first step
    if not use and np.count_nonzero(keep) == 1:
        raise DataError("only one complete period in the record; a periodic average needs two", where=record.source)
    if not use:
        held = f" without a gap in the log ({in_gaps} hold one)" if in_gaps else ""
        raise DataError(f"no complete period of the step train in the record{held}", where=record.source)
    idx = np.asarray(use)[:, None] + np.arange(period)[None, :]
    yw, uw = record.y[idx], record.u[idx]
    y, u = yw.mean(axis=0), uw.mean(axis=0)
    tail = max(1, high // 10)
    low_tail = max(1, low_time // 10)
    step = float(np.mean(y[period - tail:]) - np.mean(y[low_time - low_tail:low_time]))
    before, after = _noise(yw)
    t = (np.arange(period) - low_time) * record.dt
    return StepAverage("cycle", t, u, y, len(use), len(use), len(use), int(ups.size) - len(use), step, before, after,
                       _snr(step, before), _snr(step, after), True, steps, record.input, record.output, record.source,
                       low_time, int(use[0]), record.noise_factor, in_gaps, record.noise_correlation)


def _average_edges(record: Record, steps: Steps, pre: float | None, direction: int = 0, window: int | None = None
                   ) -> StepAverage:
    # the window is the shortest time between two steps; a last step closer to the record's end than that is
    # left out (its window would run past the end) rather than shortening every window to what is left of it
    late = late_steps(record, steps)
    between = np.diff(steps.index)[~late[:-1]]  # the interval after a late step is shorter than the plant's was
    tail = record.n - int(steps.index[-1])
    post = window if window is not None else int(np.min(between)) if between.size else tail
    keep = steps.direction == direction if direction else np.ones(steps.count, bool)
    cut = 0
    if tail < post:
        cut = int(keep[-1])
        keep[-1] = False
        if not np.any(keep):
            post = tail  # the only step of its direction: its window is what the record has
            keep[-1], cut = True, 0
    if pre is None:
        n_pre = min(max(1, post // 10), int(steps.index[0]))
    else:
        n_pre = round(pre / record.dt)
    clear = _clear(record, steps.index - n_pre, n_pre + post)
    in_gaps = int(np.sum(keep & ~clear))
    keep &= clear
    if not np.any(keep):
        raise DataError(f"every step window holds samples that a gap in the log made up ({in_gaps} windows): none is "
                        "left to average; fit the record as it is (average='none')", where=record.source)
    idx, dirs = steps.index[keep], steps.direction[keep]
    if n_pre < 1 or n_pre > idx[0]:
        raise DataError(f"need at least one sample before the first step (at t = {record.t[idx[0]]:g} s) and pre "
                        f"<= the time before it", where=record.source)
    if post < 10:
        raise DataError(f"steps are only {post} samples apart; too short to average", where=record.source)
    win = idx[:, None] + np.arange(-n_pre, post)[None, :]
    sign = dirs[:, None].astype(float)
    yw = record.y[win]
    uw = record.u[win]
    yw = sign * (yw - yw[:, :n_pre].mean(axis=1, keepdims=True))
    uw = sign * (uw - uw[:, :n_pre].mean(axis=1, keepdims=True))
    y, u = yw.mean(axis=0), uw.mean(axis=0)
    tail = max(1, post // 10)
    step = float(np.mean(y[-tail:]) - np.mean(y[:n_pre]))
    before, after = _noise(yw)
    t = np.arange(-n_pre, post) * record.dt
    ups = int(np.sum(dirs > 0))
    return StepAverage("edge", t, u, y, int(idx.size), ups, int(idx.size) - ups, cut + in_gaps, step, before, after,
                       _snr(step, before), _snr(step, after), False, steps, record.input, record.output, record.source,
                       n_pre, 0, record.noise_factor, in_gaps, record.noise_correlation)
