"""Detect a sustained oscillation (limit cycle) in a simulated signal; its amplitude and period.

The last part of the record (``window`` seconds) is detrended (a straight
line removed, so slow settling does not count) and scanned for crossings of
``+-h`` with hysteresis (``h`` a fraction ``hysteresis`` of the half-amplitude:
0.5 by default, so chatter and noise on a measured signal do not count as
cycles; :data:`SAMPLED_HYSTERESIS` for a simulated, noise-free output, whose
cycles may last only 3 samples). An oscillation is *present* when
there are at least ``min_cycles`` regular cycles (period spread below 35 %),
its half peak-to-peak amplitude exceeds ``min_amplitude`` and the RMS of the
last third of the window is at least ``sustain`` times that of the first
third (a growing oscillation counts; a decaying one does not).

The crossing instants are interpolated between samples. The period is the mean
over every whole cycle in the window; with ``whole_cycles`` the trend is refitted
to the cycles' means and the amplitude is half the peak-to-peak range over all
of them (default: over the last two); each cycle is also measured alone (its length, half its peak-to-peak
range, its largest and smallest value), and the oscillation is *periodic* when
their lengths agree within :data:`REPEAT` (1 %) and their maxima and minima
within 1 % of the amplitude, and the waveform shifted by one period matches
itself (:func:`repetition_error`): a relay or quantizer cycle that never repeats exactly is
present but not periodic, and reports the ranges.
"""

from __future__ import annotations

import itertools
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from synth.jit import jit

__all__ = ["REPEAT", "SAMPLED_HYSTERESIS", "Oscillation", "cycle_table", "detect_oscillation", "repeats",
           "repetition_error"]

REPEAT = 0.01
"""Largest spread (max - min over the mean) of the per-cycle lengths and amplitudes of a periodic oscillation."""
SAMPLED_HYSTERESIS = 0.25
"""Hysteresis (fraction of the half-amplitude) for a noise-free sampled signal: a sine sampled at 3 or more
samples per period reaches beyond 1/2 of its half-amplitude on both sides in every cycle, a sawtooth beyond
1/3, so no cycle is skipped."""


@dataclass(frozen=True)
class Oscillation:
    """Result of :func:`detect_oscillation`.

    Attributes
    ----------
    present : bool
        A sustained (or growing) oscillation was found.
    amplitude : float or None
        Half peak-to-peak over the last full cycles (signal units).
    period : float or None
        Mean period (s).
    frequency : float or None
        ``2 pi / period`` (rad/s).
    fundamental_amplitude : float or None
        Amplitude of the fundamental (first Fourier coefficient over whole cycles).
    growth : float or None
        RMS of the last third of the window over that of the first third (1 = sustained).
    cycles : int
        Full cycles found in the window.
    center : float or None
        Mean of the signal over the last full cycles.
    reason : str
        Why it is or is not counted as present.
    diverging : bool
        The RMS grows more than threefold over the window (a linearly unstable loop).
    periodic : bool or None
        The whole cycles repeat: their lengths agree within :data:`REPEAT`, their maxima and their
        minima within :data:`REPEAT` of the amplitude (a sampled cycle whose level drifts from cycle
        to cycle does not repeat); None for a growing oscillation.
    amplitude_range : (float, float) or None
        Smallest half peak-to-peak of one whole cycle, and ``amplitude`` (over all of them).
    period_range : (float, float) or None
        Shortest and longest whole cycle (s).
    """

    present: bool
    amplitude: float | None
    period: float | None
    frequency: float | None
    fundamental_amplitude: float | None
    growth: float | None
    cycles: int
    center: float | None
    reason: str
    diverging: bool = False
    periodic: bool | None = None
    amplitude_range: tuple[float, float] | None = None
    period_range: tuple[float, float] | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (``periodic`` and the ranges only when measured).

        Examples
        --------
        >>> d = Oscillation(False, None, None, None, None, None, 0, None, "flat").to_dict()
        >>> d["present"], "periodic" in d
        (False, False)
        """
        out = asdict(self)
        for key in ("periodic", "amplitude_range", "period_range"):
            if out[key] is None:
                del out[key]
        return out


def detect_oscillation(t: Any, x: Any, window: float | None = None, min_amplitude: float = 0.0,
                       min_cycles: int = 3, sustain: float = 0.8, hysteresis: float = 0.5,
                       whole_cycles: bool = False) -> Oscillation:
    """Is there a sustained oscillation at the end of ``x(t)``?

    Parameters
    ----------
    t, x : array_like
        Uniformly sampled time (s) and signal.
    window : float, optional
        Seconds at the end of the record to examine (default: the last half).
    min_amplitude : float
        Smallest half peak-to-peak amplitude that counts (signal units), e.g. one sensor
        quantum; amplitudes below ``1e-9 (1 + |mean|)`` never count.
    min_cycles : int
        Fewest full cycles in the window.
    sustain : float
        Smallest ratio of the RMS of the last third of the window to that of the first third
        that counts as sustained (a growing oscillation has a ratio above 1).
    hysteresis : float
        Crossing hysteresis as a fraction of the half-amplitude (0.5: robust to noise;
        :data:`SAMPLED_HYSTERESIS` for a noise-free simulated output).
    whole_cycles : bool
        Measure over every whole cycle of the window: the trend line refitted to the cycles' means
        (a line fitted over a fraction of a cycle tilts the crossings: a 1 % period error with 5
        cycles), the amplitude half the peak-to-peak range over all of them. Default: the line fitted
        to all samples, the amplitude over the last two cycles.

    Examples
    --------
    >>> t = np.arange(0, 10, 0.001)
    >>> osc = detect_oscillation(t, 3 * np.sin(2 * np.pi * t), whole_cycles=True)
    >>> osc.present, round(osc.amplitude, 3), round(osc.period, 4), osc.periodic
    (True, 3.0, 1.0, True)
    >>> round(detect_oscillation(t, 3 * np.sin(2 * np.pi * t)).period, 4)  # the line over 5 cycles tilts it
    0.988
    >>> beat = detect_oscillation(t, (1 + 0.2 * np.sin(0.7 * t)) * np.sin(2 * np.pi * t), whole_cycles=True)
    >>> beat.present, beat.periodic, [round(a, 2) for a in beat.amplitude_range]
    (True, False, [0.81, 0.94])
    >>> detect_oscillation(t, np.exp(-0.3 * t) * np.sin(2 * np.pi * t)).reason
    'decaying: the last third of the window has 0.37 times the RMS of the first'
    """
    t = np.asarray(t, float)
    x = np.asarray(x, float)
    if t.size != x.size or t.size < 8:
        return Oscillation(False, None, None, None, None, None, 0, None, "record too short")
    if not np.all(np.isfinite(x)):
        return Oscillation(False, float("inf"), None, None, None, float("inf"), 0, None, "signal diverged",
                           diverging=True)
    span = t[-1] - t[0]
    window = span / 2 if window is None else min(float(window), span)
    keep = t >= t[-1] - window
    tw, xw = t[keep], x[keep]
    slope, intercept = np.polyfit(tw - tw[0], xw, 1)
    r = xw - (slope * (tw - tw[0]) + intercept)
    half = 0.5 * (r.max() - r.min())
    floor = max(min_amplitude, 1e-9 * (1.0 + abs(float(np.mean(xw)))))
    if half <= floor:
        return Oscillation(False, float(half), None, None, None, None, 0, float(np.mean(xw)),
                           f"amplitude {half:.3g} is below the threshold {floor:.3g}")
    third = max(1, r.size // 3)
    with np.errstate(over="ignore", invalid="ignore"):
        rms_early, rms_late = np.sqrt(np.mean(r[:third] ** 2)), np.sqrt(np.mean(r[-third:] ** 2))
    if not (np.isfinite(rms_early) and np.isfinite(rms_late)):
        return Oscillation(False, float(half), None, None, None, float("inf"), 0, None, "signal diverged",
                           diverging=True)
    growth = float(rms_late / rms_early) if rms_early > 0 else float("inf")
    dev = xw - np.mean(xw[:third])
    early_dev = max(float(np.max(np.abs(dev[:third]))), floor)
    late_dev = float(np.max(np.abs(dev[-third:])))
    diverging = growth > 3.0 or (late_dev > 10 * early_dev and late_dev > 10 * floor)
    if growth < sustain:
        return Oscillation(False, float(half), None, None, None, growth, 0, float(np.mean(xw)),
                           f"decaying: the last third of the window has {growth:.2g} times the RMS of the first")
    if diverging:
        ups = _up_crossings(tw, r, 0.0)
    else:
        ups = _crossings(tw, xw, r, hysteresis * half) if whole_cycles else _up_crossings(tw, r, hysteresis * half)
    cycles = max(ups.size - 1, 0)
    if cycles < min_cycles:
        why = "growing without oscillating" if diverging else f"only {cycles} full cycles"
        return Oscillation(False, float(half), None, None, None, growth, cycles, float(np.mean(xw)),
                           f"{why} in the last {window:.3g} s", diverging=diverging)
    periods = np.diff(ups)
    period = float((ups[-1] - ups[0]) / cycles)
    w0 = 2 * np.pi / period
    whole = (tw >= ups[0]) & (tw < ups[-1])
    envelope = 0.5 * float(xw[whole].max() - xw[whole].min()) if np.any(whole) else float(half)
    tops, bottoms = _cycle_extremes(tw, xw, ups)
    each = 0.5 * (tops - bottoms)
    ranges = {"amplitude_range": (float(each.min()), envelope), "period_range": (float(periods.min()),
                                                                                   float(periods.max()))}
    scale = REPEAT * float(np.mean(each))
    periodic = bool(np.ptp(periods) <= REPEAT * period and np.ptp(tops) <= scale and np.ptp(bottoms) <= scale
                    and repeats(tw[whole], xw[whole], period))
    if np.std(periods) > 0.35 * period and not diverging:
        return Oscillation(False, float(half), period, w0, None, growth, cycles, float(np.mean(xw)),
                           "irregular: cycle lengths vary by more than 35 %", periodic=False, **ranges)
    if diverging:
        last = tw >= tw[-1] - min(2 * period, window)
    else:
        last = whole if whole_cycles else (tw >= ups[max(0, ups.size - 3)]) & (tw < ups[-1])
    amplitude = 0.5 * float(xw[last].max() - xw[last].min())
    center = float(np.mean(xw[last]))
    coef = 2.0 * np.mean(r[whole] * np.exp(-1j * w0 * tw[whole]))
    present = growth >= sustain
    if diverging:
        reason = f"growing: {cycles} cycles of period {period:.4g} s, RMS x{growth:.3g} over the window"
    elif present and periodic:
        reason = f"sustained: {cycles} cycles of period {period:.4g} s"
    elif present:
        reason = (f"sustained, not periodic: {cycles} cycles of {ranges['period_range'][0]:.4g} to "
                  f"{ranges['period_range'][1]:.4g} s, amplitude {ranges['amplitude_range'][0]:.4g} to "
                  f"{envelope:.4g}")
    else:
        reason = f"decaying: the last third of the window has {growth:.2g} times the RMS of the first"
    return Oscillation(bool(present), amplitude, period, w0, float(abs(coef)), growth, cycles, center, reason,
                       diverging=diverging, periodic=None if diverging else periodic,
                       **({} if diverging else ranges))


def _crossings(t: np.ndarray, x: np.ndarray, r: np.ndarray, h: float) -> np.ndarray:
    """Up-crossings of ``r`` (``x`` less a fitted line) with hysteresis ``h``; the line fitted to the
    samples is tilted by the oscillation itself (a fraction of a cycle in the window), so it is refitted
    to the means of the whole cycles found and the crossings are found again."""
    ups = _up_crossings(t, r, h)
    if ups.size >= 3:
        spans = [(a, max(b, a + 1)) for a, b in itertools.pairwise(np.searchsorted(t, ups))]
        mids = np.array([t[a:b].mean() for a, b in spans]) - t[0]
        means = np.array([x[a:b].mean() for a, b in spans])
        slope, intercept = np.polyfit(mids, means, 1)
        ups = _up_crossings(t, x - (slope * (t - t[0]) + intercept), h)
    return ups


def cycle_table(t: Any, x: Any, hysteresis: float = SAMPLED_HYSTERESIS) -> tuple[np.ndarray, np.ndarray]:
    """Each whole cycle of ``x(t)``: (start time, half its peak-to-peak range), cycles delimited by
    up-crossings as in :func:`detect_oscillation` (over the whole record).

    Examples
    --------
    >>> t = np.arange(0, 10, 0.001)
    >>> starts, halves = cycle_table(t, np.exp(-0.1 * t) * np.sin(2 * np.pi * t))
    >>> starts.size, round(float(halves[0] / halves[-1]), 2)
    (8, 2.01)
    """
    t = np.asarray(t, float)
    x = np.asarray(x, float)
    if t.size < 8 or not np.all(np.isfinite(x)):
        return np.zeros(0), np.zeros(0)
    slope, intercept = np.polyfit(t - t[0], x, 1)
    r = x - (slope * (t - t[0]) + intercept)
    ups = _crossings(t, x, r, hysteresis * 0.5 * float(r.max() - r.min()))
    if ups.size < 2:
        return np.zeros(0), np.zeros(0)
    tops, bottoms = _cycle_extremes(t, x, ups)
    return ups[:-1], 0.5 * (tops - bottoms)


def _cycle_extremes(t: np.ndarray, x: np.ndarray, ups: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Largest and smallest sample of each whole cycle (between consecutive up-crossings)."""
    idx = np.searchsorted(t, ups)
    spans = [(a, max(b, a + 1)) for a, b in itertools.pairwise(idx)]
    return np.array([float(x[a:b].max()) for a, b in spans]), np.array([float(x[a:b].min()) for a, b in spans])

def _up_crossings(t: np.ndarray, r: np.ndarray, h: float) -> np.ndarray:
    """Times where ``r`` rises through 0 after having been below ``-h``, before reaching ``+h``."""
    return _up_crossings_jit(np.ascontiguousarray(t), np.ascontiguousarray(r), float(h))


@jit
def _up_crossings_jit(t, r, h):
    out = np.empty(r.size)
    count = 0
    armed = False
    last_below = -1
    for i in range(r.size):
        if r[i] < -h or (h == 0.0 and r[i] < 0.0):
            armed = True
            last_below = i
        elif armed and r[i] > h:
            j = last_below
            while j < i and r[j + 1] < 0:
                j += 1
            f = -r[j] / (r[j + 1] - r[j]) if r[j + 1] != r[j] else 0.0
            out[count] = t[j] + f * (t[j + 1] - t[j])
            count += 1
            armed = False
    return out[:count]


def repetition_error(t: Any, x: Any, period: float, worst: bool = False) -> float:
    """How far ``x(t)`` is from repeating with ``period``: the RMS of ``x(t) - x(t - period)``
    (``x`` interpolated linearly between samples) over the record less its first period, divided by
    the RMS of ``x`` about its mean (``worst``: the largest ``|x(t) - x(t - period)|`` divided by the
    peak-to-peak range of ``x``); ``inf`` when the record is shorter than two periods.

    Examples
    --------
    >>> t = np.arange(0, 20, 0.001)
    >>> round(repetition_error(t, np.sin(2 * np.pi * t), 1.0), 6)
    0.0
    >>> round(repetition_error(t, np.sin(2 * np.pi * t) + 0.3 * np.sin(2 * np.pi * t / np.sqrt(5)), 1.0), 2)
    0.57
    """
    t = np.asarray(t, float)
    x = np.asarray(x, float)
    if not (np.isfinite(period) and period > 0) or t.size < 4 or t[-1] - t[0] < 2 * period:
        return float("inf")
    later = t >= t[0] + period
    d = x[later] - np.interp(t[later] - period, t, x)
    if worst:
        return float(np.max(np.abs(d)) / np.ptp(x)) if np.ptp(x) > 0 else 0.0
    spread = float(np.sqrt(np.mean((x - np.mean(x)) ** 2)))
    return float(np.sqrt(np.mean(d**2)) / spread) if spread > 0 else 0.0


def repeats(t: Any, x: Any, period: float) -> bool:
    """``x(t)`` repeats with ``period``: :func:`repetition_error` at most :data:`REPEAT` (1 % RMS), and
    no sample farther than 10 REPEAT (10 %) of the peak-to-peak range from its value one period before
    (the RMS alone lets through a record whose sparse switching instants move from cycle to cycle).

    Examples
    --------
    >>> t = np.arange(0, 20, 0.01)
    >>> repeats(t, np.sin(2 * np.pi * t), 1.0), repeats(t, np.sign(np.sin(2 * np.pi * t * 1.0003)), 1.0)
    (True, False)
    """
    return repetition_error(t, x, period) <= REPEAT and repetition_error(t, x, period, worst=True) <= 10 * REPEAT
