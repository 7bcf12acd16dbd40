"""Detect a sustained oscillation (limit cycle) in a simulated signal; its amplitude and period.

The last part of the record (``window`` seconds) is detrended (a straight
line removed, so slow settling does not count) and scanned for crossings of
``+-h`` with hysteresis (``h`` half the half-amplitude, so quantization
chatter and noise do not count as cycles). An oscillation is *present* when
there are at least ``min_cycles`` regular cycles (period spread below 25 %),
its half peak-to-peak amplitude exceeds ``min_amplitude`` and the RMS of the
last third of the window is at least ``sustain`` times that of the first
third (a growing oscillation counts; a decaying one does not).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from synth.sim._jit import jit

__all__ = ["Oscillation", "detect_oscillation"]


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

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict.

        Examples
        --------
        >>> Oscillation(False, None, None, None, None, None, 0, None, "flat").to_dict()["present"]
        False
        """
        return asdict(self)


def detect_oscillation(t: Any, x: Any, window: float | None = None, min_amplitude: float = 0.0,
                       min_cycles: int = 3, sustain: float = 0.8) -> Oscillation:
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

    Examples
    --------
    >>> t = np.arange(0, 10, 0.001)
    >>> osc = detect_oscillation(t, 3 * np.sin(2 * np.pi * t))
    >>> osc.present, round(osc.amplitude, 3), round(osc.period, 4)
    (True, 3.0, 1.0)
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
    ups = _up_crossings(tw, r, 0.5 * half) if not diverging else _up_crossings(tw, r, 0.0)
    cycles = max(ups.size - 1, 0)
    if cycles < min_cycles:
        why = "growing without oscillating" if diverging else f"only {cycles} full cycles"
        return Oscillation(False, float(half), None, None, None, growth, cycles, float(np.mean(xw)),
                           f"{why} in the last {window:.3g} s", diverging=diverging)
    periods = np.diff(ups)
    period = float(np.mean(periods))
    w0 = 2 * np.pi / period
    if np.std(periods) > 0.35 * period and not diverging:
        return Oscillation(False, float(half), period, w0, None, growth, cycles, float(np.mean(xw)),
                           "irregular: cycle lengths vary by more than 35 %")
    last = tw >= tw[-1] - min(2 * period, window) if diverging else \
        (tw >= ups[max(0, ups.size - 3)]) & (tw < ups[-1])
    amplitude = 0.5 * float(xw[last].max() - xw[last].min())
    center = float(np.mean(xw[last]))
    whole = (tw >= ups[0]) & (tw < ups[-1])
    coef = 2.0 * np.mean(r[whole] * np.exp(-1j * w0 * tw[whole]))
    present = growth >= sustain
    if diverging:
        reason = f"growing: {cycles} cycles of period {period:.4g} s, RMS x{growth:.3g} over the window"
    elif present:
        reason = f"sustained: {cycles} cycles of period {period:.4g} s"
    else:
        reason = f"decaying: the last third of the window has {growth:.2g} times the RMS of the first"
    return Oscillation(bool(present), amplitude, period, w0, float(abs(coef)), growth, cycles, center, reason,
                       diverging=diverging)

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
