"""Measure a limit cycle found by :func:`synth.sim.verdict.judge`: periodic or not, and its ranges.

A sustained oscillation is *periodic* when the record repeats itself: shifted by one period, the
waveform differs by at most :data:`~synth.sim.limitcycle.REPEAT` (1 %) RMS of its own RMS and no
sample moves by more than 10 % of its range (:func:`~synth.sim.limitcycle.repeats`), and its whole
cycles have the same length, maximum and minimum (:func:`~synth.sim.limitcycle.detect_oscillation`).
The period is found, in order, from the crossings of the mean (a simple waveform, two crossings
per period) or from the autocorrelation (:func:`autocorrelation_period`: a waveform crossing its
mean more than twice per period; a sampled cycle locked onto a pattern of several differing cycles
is reported as not periodic cycle by cycle); the amplitude of a cycle found to repeat by the
autocorrelation is half the range of its last whole repeat, so that the drift of a centre still
settling is not counted in it. A cycle that repeats by neither is *oscillating but not periodic*
(quasi-periodic or chaotic relay and quantizer cycles): its amplitude is half the peak-to-peak range
of the window, reported with the smallest cycle's, and its period is the mean length of its cycles,
reported with the shortest and longest.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from synth.sim.limitcycle import REPEAT, Oscillation, cycle_table, repeats

__all__ = ["autocorrelation_period", "measure_cycle"]


def autocorrelation_period(t: np.ndarray, y: np.ndarray, min_amplitude: float = 0.0,
                           threshold: float = 0.98) -> tuple[float, float] | None:
    """(period, half peak-to-peak) when ``y`` repeats itself: the normalized autocorrelation reaches
    ``threshold`` at a lag holding 3 or more repeats in the record; the period is the *first* lag
    whose autocorrelation comes within 0.01 of the best one (a multiple of the period repeats as well
    as the period itself), refined between samples by a parabola. None otherwise.

    Examples
    --------
    >>> t = np.arange(0, 30, 0.01)
    >>> wave = np.sin(2 * np.pi * t / 2.5) + 0.8 * np.sin(3 * 2 * np.pi * t / 2.5)  # 6 mean crossings a period
    >>> p, half = autocorrelation_period(t, wave)
    >>> round(p, 2), round(half, 2)
    (2.5, 1.35)
    """
    r = y - np.mean(y)
    half = 0.5 * float(np.ptp(y))
    if half <= max(min_amplitude, 1e-9 * (1.0 + abs(float(np.mean(y))))) or r.size < 16:
        return None
    n = r.size
    f = np.fft.rfft(r, 2 * n)
    ac = np.fft.irfft(f * np.conj(f))[: n // 3]
    ac = ac / (ac[0] * (1 - np.arange(ac.size) / n))
    below = np.nonzero(ac < 0.5)[0]
    if below.size == 0:
        return None
    k0 = int(below[0])
    if k0 >= ac.size - 1 or float(np.max(ac[k0:])) < threshold:
        return None
    peak = k0 + int(np.argmax(ac[k0:] >= max(threshold, float(np.max(ac[k0:])) - 0.01)))
    while peak < ac.size - 1 and ac[peak + 1] > ac[peak]:
        peak += 1
    if peak >= ac.size - 1:
        return None
    a, b, c = ac[peak - 1], ac[peak], ac[peak + 1]
    shift = 0.5 * (a - c) / (a - 2 * b + c) if (a - 2 * b + c) != 0 else 0.0
    return float((peak + shift) * (t[1] - t[0])), half


def _repeating_lag(t: np.ndarray, y: np.ndarray, first: float) -> float | None:
    """The shortest multiple of ``first`` (at most 50 of them and half the record) after which
    ``y`` repeats (:func:`~synth.sim.limitcycle.repeats`); None when none does."""
    for k in range(1, min(50, int((t[-1] - t[0]) / 2 / first)) + 1):
        if repeats(t, y, k * first):
            return k * first
    return None


def _repeat_halves(t: np.ndarray, y: np.ndarray, pattern: float) -> np.ndarray:
    """Half the peak-to-peak range of each whole repeat of length ``pattern`` in the window, counted back from its
    end (the last one last): the cycle's own amplitude, without the drift of its centre across the window (seed
    108 loop 70 of benchmarks/sim_verdicts.py: a quantizer's chattering 0.000593 high, its centre still settling by
    0.00012 over the window, whose half range was 0.000619)."""
    count = max(1, int((t[-1] - t[0]) / pattern + 1e-9))
    starts = np.searchsorted(t, t[-1] - pattern * np.arange(count, 0, -1) - 1e-9 * pattern)  # each repeat's first
    top, bottom = np.maximum.reduceat(y, starts), np.minimum.reduceat(y, starts)  # sample (the next one's ends it)
    return 0.5 * (top - bottom)


def measure_cycle(t: np.ndarray, y: np.ndarray, osc: Oscillation, cycles: int,
                  min_amplitude: float = 0.0) -> Oscillation:
    """The limit cycle of the window ``t, y`` (already judged sustained), measured: ``osc`` is
    :func:`~synth.sim.limitcycle.detect_oscillation` on that window. Returns ``osc`` when it is
    periodic; otherwise a copy marked periodic when the record repeats after the period found by
    :func:`autocorrelation_period` (a complex waveform: the period is the pattern's), or marked not
    periodic with the ranges of its cycles (a sampled cycle that repeats only every k > 1 cycles of
    different lengths or amplitudes says so, with their mean length as its period).

    Examples
    --------
    >>> from synth.sim.limitcycle import detect_oscillation
    >>> t = np.arange(0, 40, 0.01)
    >>> y = np.sin(2 * np.pi * t) * (1 + 0.1 * np.sin(2 * np.pi * t / np.sqrt(50)))  # beats: never repeats
    >>> m = measure_cycle(t, y, detect_oscillation(t, y, window=40), 40)
    >>> m.periodic, round(m.period, 3), [round(a, 2) for a in m.amplitude_range]
    (False, 1.0, [0.9, 1.1])
    """
    if osc.present and osc.periodic:
        return osc
    found = autocorrelation_period(t, y, min_amplitude)
    pattern = _repeating_lag(t, y, found[0]) if found is not None else None
    if pattern is not None and osc.present and osc.period:  # regular cycles, repeating every k of them
        k = max(1, round(pattern / osc.period))
        halves = _repeat_halves(t, y, pattern)
        half = float(halves[-1])
        period = osc.period if abs(pattern / k - osc.period) <= REPEAT * osc.period else pattern
        how = (f"{'periodic' if k == 1 else 'not periodic cycle by cycle'}: the record repeats every {pattern:.4g} s "
               f"({k} cycles) within {100 * REPEAT:g} % RMS, no sample off by 10 %"
               f"{'' if k == 1 else ', its cycles differ'}; period the mean length of the cycles ({osc.reason})")
        shape = {"periodic": k == 1, "amplitude_range": (float(np.min(halves)), float(np.max(halves))) if k == 1
                 else osc.amplitude_range or (half, half), "period_range": osc.period_range or (period, period)}
    elif pattern is not None:  # a complex waveform (more than two mean crossings a period)
        period, half = pattern, float(_repeat_halves(t, y, pattern)[-1])
        starts, _ = cycle_table(t, y)  # the window's whole cycles, delimited as the cycle detector delimits them
        ups = round(period * (starts.size - 1) / (starts[-1] - starts[0])) if starts.size >= 2 else 0
        how = (f"periodic: the record repeats every {period:.4g} s within {100 * REPEAT:g} % RMS (autocorrelation); "
               + (f"it crosses its mean upwards {ups} times in each repeat (every {period / ups:.4g} s on average); "
                  if ups >= 2 else "") + f"its mean crossings: {osc.reason}")
        shape = {"periodic": True, "amplitude_range": (half, half), "period_range": (period, period)}
    else:
        half = 0.5 * float(np.ptp(y))
        period = osc.period if osc.period else (found[0] if found else float("nan"))
        low = osc.amplitude_range[0] if osc.amplitude_range else half
        lengths = osc.period_range or (period, period)  # cycle lengths; not the lag at which the record best
        # repeats, which may span several cycles (a range of 0.1 to 1.09 s for cycles of 0.1-0.11 s)
        how = (f"not periodic: shifted by any period the record differs by more than {100 * REPEAT:g} % RMS "
               "or 10 % at a sample; "
               f"amplitude half the peak-to-peak range of the window, period the mean length of its cycles "
               f"({osc.reason})")
        shape = {"periodic": False, "amplitude_range": (min(low, half), half), "period_range": lengths}
    return dataclasses.replace(osc, present=True, amplitude=half, period=period, frequency=2 * np.pi / period,
                               cycles=cycles, center=float(np.mean(y)), reason=how, **shape)
