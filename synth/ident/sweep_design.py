"""Frequency-sweep test design: from the frequency range to periods, run length and an input signal.

The recipe (the NASA Bell 214ST sweep report, sections 2 and 6.1)
------------------------------------------------------------------
- The lowest frequency sets the longest period, ``T_max = 2 pi / w_min``: the
  Bell 214 roll sweeps used ``w_min = 0.4 rad/s``, so ``T_max = 15.7 s`` (the
  report rounds to 16 s; 20 s in heave). The highest, ``f_max = w_max / 2 pi``
  (about 2 Hz there, kept below the 12 rad/s rotor-pylon mode).
- Each run starts with two low-frequency cycles of period ``T_max`` and then
  increases the frequency gradually (no jump to high frequency) up to ``w_max``;
  it starts and ends at trim.
- A run lasts 90 s (experience on the XV-15: an even spread of frequency content
  between the low- and high-frequency cycles); 3 runs are flown per axis and the
  best 2 are concatenated for the spectral analysis.

What this module adds (design choices, not the report's): the run length is
``max(90 s, 4.5 T_max)``: the report's two cases have 90/15.7 = 5.7 and 90/20 =
4.5 periods of ``T_max`` per run; the spectral analysis needs windows of
``2 T_max`` (:func:`synth.ident.spectral_windows.required_window`), which fit at least
three times, overlapped by half, into such a run. The generated input is the
exponential sweep ``w(t) = w_min + C2 (w_max - w_min)(exp(C1 t/T) - 1)`` with
``C1 = 4``, ``C2 = 1 / (exp(C1) - 1)`` after the two ``T_max`` cycles (``T`` is the
time it takes to reach ``w_max``), with a raised-cosine fade-in over the first low
cycle and a raised-cosine fade-out at the end.

What the sweep covers (issue 16)
--------------------------------
The whole requested band ``[w_min, w_max]`` is swept at full amplitude: the input's
energy per rad/s follows the sweep law, ``dt/dw = T / (C1 (w - w_min + C2 (w_max -
w_min)))`` (close to equal time per decade once ``w`` is well above ``w_min``), right
up to ``w_max``, and ``w_min`` gets in addition the two low cycles. The fade-out
lies *above* the band: when the sweep reaches ``w_max`` the amplitude is still full,
and during the fade-out the same law carries the frequency on to ``w_end``
(:class:`SweepTiming`; typically 1.05-1.4 ``w_max``). It lasts at least the time the
sweep needs to pass ``w_max`` cleanly, ``sqrt(2 pi / r)`` with ``r`` the sweep rate
[rad/s^2] at ``w_max`` (a sweep cut off at ``w_max`` leaves ``w_max`` itself 6 dB
short, and a fade-out that ends at ``w_max``, as before issue 16, left the top tenth
of the band 3-20 dB short). The run still starts and ends at rest: zero input and
zero slope.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.errors import DataError
from synth.ident.spectral_windows import default_windows

__all__ = ["MIN_PERIODS_PER_RUN", "SEED_RUN_LENGTH", "SweepDesign", "SweepTiming", "design_sweep"]

#: run length the report recommends [s]
SEED_RUN_LENGTH = 90.0
#: least run length in periods of T_max (the report's heave sweeps: 90 s / 20 s)
MIN_PERIODS_PER_RUN = 4.5


@dataclass(frozen=True)
class SweepTiming:
    """When one run of a sweep does what (:meth:`SweepDesign.timing`).

    Attributes
    ----------
    fade_in, fade_out : float
        Raised-cosine fade-in at the start and fade-out at the end [s].
    t_low : float
        End of the low-frequency cycles at ``w_min`` [s].
    t_top : float
        Time the sweep reaches ``w_max`` at full amplitude; the fade-out starts here [s].
    w_end : float
        Frequency the fade-out carries the sweep on to, at the end of the run [rad/s].

    Examples
    --------
    >>> tm = design_sweep(0.4, 12.0).timing()
    >>> round(tm.fade_in, 2), round(tm.fade_out, 2), round(tm.t_top, 1), round(tm.w_end, 1)
    (3.93, 2.72, 87.3, 14.5)
    """

    fade_in: float
    fade_out: float
    t_low: float
    t_top: float
    w_end: float

    def to_dict(self) -> dict[str, float]:
        """JSON-ready timing with units in the keys.

        Examples
        --------
        >>> sorted(design_sweep(0.4, 12.0).timing().to_dict())
        ['fade_in_s', 'fade_out_s', 'low_cycles_end_s', 'w_end_rad_s', 'w_max_reached_s']
        """
        return {"fade_in_s": self.fade_in, "fade_out_s": self.fade_out, "low_cycles_end_s": self.t_low,
                "w_max_reached_s": self.t_top, "w_end_rad_s": self.w_end}


@dataclass(frozen=True)
class SweepDesign:
    """A frequency-sweep test plan.

    Attributes
    ----------
    w_min, w_max : float
        Frequency range [rad/s].
    t_max : float
        Longest period ``2 pi / w_min`` [s].
    f_max : float
        Highest input frequency [Hz].
    run_length : float
        Recommended length of one run [s].
    runs_flown, runs_used : int
        Runs to record and to concatenate (3 and 2 in the report).
    low_cycles : int
        Cycles at ``T_max`` at the start of each run.
    sample_rate : float
        Suggested sample rate [Hz]: at least 25 samples per period of ``w_max``.
    windows : tuple of float
        Composite analysis windows [s] (:func:`synth.ident.spectral_windows.default_windows`).

    Examples
    --------
    >>> d = design_sweep(0.4, 12.0)
    >>> round(d.t_max, 1), d.run_length, d.runs_flown, d.runs_used, round(d.f_max, 2)
    (15.7, 90.0, 3, 2, 1.91)
    """

    w_min: float
    w_max: float
    t_max: float
    f_max: float
    run_length: float
    runs_flown: int
    runs_used: int
    low_cycles: int
    sample_rate: float
    windows: tuple[float, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready plan with units in the keys.

        Examples
        --------
        >>> design_sweep(0.4, 12.0).to_dict()["run_length_s"]
        90.0
        """
        return {"w_min_rad_s": self.w_min, "w_max_rad_s": self.w_max, "t_max_s": self.t_max,
                "f_max_hz": self.f_max, "run_length_s": self.run_length, "runs_flown": self.runs_flown,
                "runs_used": self.runs_used, "low_cycles": self.low_cycles,
                "sample_rate_hz": self.sample_rate, "windows_s": list(self.windows)}

    def timing(self, fade: float | None = None, fade_out: float | None = None, c1: float = 4.0) -> SweepTiming:
        """Fades, the time ``w_max`` is reached and the frequency the fade-out ends at (module text).

        Parameters
        ----------
        fade : float, optional
            Raised-cosine fade-in [s]; default a quarter of ``T_max``. Also the least fade-out.
        fade_out : float, optional
            Raised-cosine fade-out [s], above ``w_max``; default the longer of ``fade`` (when given) and
            the time the sweep needs to pass ``w_max`` cleanly, ``sqrt(2 pi / r)`` at the sweep rate ``r``
            there (solved together with the sweep's length), but at least two periods of ``w_max``.
        c1 : float
            Exponential rate of the sweep.

        Returns
        -------
        SweepTiming

        Raises
        ------
        DataError
            If a fade is negative or the fade-out leaves no time for the sweep after the low cycles.

        Examples
        --------
        >>> d = design_sweep(1.0, 100.0)
        >>> tm = d.timing()
        >>> round(tm.fade_out, 2), round(tm.w_end / d.w_max, 2)   # the fade-out lies above the band
        (1.09, 1.06)
        >>> round(d.timing(fade=2.0).w_end / d.w_max, 2)          # a longer fade-out reaches further up
        1.11
        """
        fade_in = 0.25 * self.t_max if fade is None else float(fade)
        if not (np.isfinite(fade_in) and fade_in >= 0) or (fade_out is not None and not
                                                          (np.isfinite(fade_out) and fade_out >= 0)):
            raise DataError(f"fades must be non-negative numbers of seconds, got {fade!r} and {fade_out!r}")
        t_low = self.low_cycles * self.t_max
        room = self.run_length - t_low              # the sweep plus the fade-out
        w_top = self.w_max + self.w_max / np.expm1(c1) - self.w_min * np.exp(c1) / np.expm1(c1)  # w_max + a
        if fade_out is None:
            k = 2.0 * np.pi / (c1 * w_top)          # pass time t solves t^2 = k (room - t): r = c1 w_top / sweep
            t_pass = 0.5 * (np.sqrt(k * k + 4.0 * k * max(room, 0.0)) - k)
            fade_out = max(t_pass, 4.0 * np.pi / self.w_max, 0.0 if fade is None else fade_in)
        fade_out = float(fade_out)
        sweep = room - fade_out
        if not sweep > 0:
            raise DataError(f"the fade-out ({fade_out:.4g} s) leaves no time to sweep from w_min to w_max after the "
                            f"low cycles ({max(room, 0.0):.4g} s of the {self.run_length:g} s run remain)")
        w_end = self.w_min + (self.w_max - self.w_min) / np.expm1(c1) * np.expm1(c1 * room / sweep)
        return SweepTiming(fade_in, fade_out, t_low, t_low + sweep, float(w_end))

    def signal(self, amplitude: float = 1.0, sample_rate: float | None = None, fade: float | None = None,
               c1: float = 4.0, reduce_above: float | None = None,
               reduce_to: float = 0.5, fade_out: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Generate one run of the sweep input.

        Parameters
        ----------
        amplitude : float
            Peak input amplitude (input units).
        sample_rate : float, optional
            [Hz]; default :attr:`sample_rate`. Must exceed twice the highest frequency, ``w_end``.
        fade : float, optional
            Raised-cosine fade-in length [s]; default a quarter of ``T_max``; also the least fade-out.
        c1 : float
            Exponential rate of the sweep (4 in the common recipe; larger dwells
            longer at low frequency).
        reduce_above : float, optional
            [rad/s] From this instantaneous frequency on, the amplitude is reduced to ``reduce_to`` of
            its value (the report's pilots did so above 1.5 Hz to spare a structural mode); the change is
            a raised cosine over the half octave below it, so no step enters the input.
        reduce_to : float
            The reduced amplitude as a fraction (0 < reduce_to <= 1).
        fade_out : float, optional
            Raised-cosine fade-out length [s], which starts when the sweep reaches ``w_max``
            (:meth:`timing`).

        Returns
        -------
        t, u : numpy.ndarray
            Time [s] from 0 to :attr:`run_length`, input samples. ``w_min`` .. ``w_max`` is swept at
            full amplitude; the fade-out carries the sweep on above ``w_max``; ``u`` starts and ends at
            rest (zero value and slope) when ``fade > 0``.

        Examples
        --------
        >>> t, u = design_sweep(0.4, 12.0).signal(amplitude=1.5, sample_rate=50)
        >>> float(t[-1]), round(float(abs(u).max()), 2), float(u[0]), round(abs(float(u[-1])), 12)
        (90.0, 1.5, 0.0, 0.0)
        >>> t, u = design_sweep(0.4, 12.0).signal(sample_rate=50, reduce_above=2 * np.pi * 1.5, reduce_to=0.4)
        >>> round(float(abs(u[t < 40]).max()), 2), round(float(abs(u[t > 88]).max()), 2) <= 0.4  # above 9.4 rad/s
        (1.0, True)
        """
        fs = float(sample_rate or self.sample_rate)
        if not fs > 2.0 * self.f_max:
            raise DataError(f"sample rate {fs:g} Hz must exceed 2 f_max = {2 * self.f_max:.3g} Hz")
        if not amplitude > 0:
            raise DataError(f"amplitude must be positive, got {amplitude:g}")
        tm = self.timing(fade, fade_out, c1)
        if not fs > tm.w_end / np.pi:
            raise DataError(f"sample rate {fs:g} Hz must exceed 2 f_end = {tm.w_end / np.pi:.3g} Hz: the fade-out "
                            f"carries the sweep on to {tm.w_end:.4g} rad/s above w_max (a shorter fade does less)")
        t = np.arange(round(self.run_length * fs) + 1) / fs
        sweep = tm.t_top - tm.t_low
        c2 = 1.0 / np.expm1(c1)
        tau = np.clip(t - tm.t_low, 0.0, None)
        dw = self.w_max - self.w_min
        phase = self.w_min * t + c2 * dw * (sweep / c1 * np.expm1(c1 * tau / sweep) - tau)
        u = np.sin(phase)
        for ramp_time, dist in ((tm.fade_in, t), (tm.fade_out, t[-1] - t)):
            if ramp_time > 0:
                u = u * 0.5 * (1.0 - np.cos(np.pi * np.clip(dist / ramp_time, 0.0, 1.0)))
        peak = float(np.max(np.abs(u)))  # before any reduction, so that a reduced start is not scaled back up
        if reduce_above is not None:
            if not (np.isfinite(reduce_above) and reduce_above > 0 and 0 < reduce_to <= 1):
                raise DataError(f"amplitude reduction needs a frequency > 0 and a fraction in (0, 1], got "
                                f"{reduce_above!r} rad/s and {reduce_to!r}")
            w_now = self.w_min + c2 * dw * np.expm1(c1 * tau / sweep)   # instantaneous frequency d(phase)/dt
            x = np.clip(np.log2(np.maximum(w_now, 1e-300) / reduce_above) / 0.5 + 1.0, 0.0, 1.0)
            u = u * (1.0 - (1.0 - reduce_to) * 0.5 * (1.0 - np.cos(np.pi * x)))
        return t, amplitude * u / peak


def design_sweep(w_min: float, w_max: float, runs_used: int = 2) -> SweepDesign:
    """Plan a frequency sweep for the range ``w_min`` .. ``w_max`` [rad/s] (the report's recipe).

    Parameters
    ----------
    w_min, w_max : float
        Lowest and highest frequency of interest [rad/s].
    runs_used : int
        Runs to concatenate (2 in the report); one more is flown as a spare.

    Returns
    -------
    SweepDesign

    Raises
    ------
    DataError
        If the range is not ``0 < w_min < w_max``.

    Examples
    --------
    >>> d = design_sweep(2 * np.pi / 20, 9.4)     # heave: T_max = 20 s
    >>> d.t_max, d.run_length
    (20.0, 90.0)
    >>> design_sweep(0.1, 5).run_length          # T_max = 62.8 s: 4.5 periods
    282.8
    """
    if not (np.isfinite(w_min) and np.isfinite(w_max) and 0 < w_min < w_max):
        raise DataError(f"need 0 < w_min < w_max in rad/s, got w_min = {w_min!r}, w_max = {w_max!r}")
    if runs_used < 1:
        raise DataError(f"runs_used must be at least 1, got {runs_used}")
    t_max = 2.0 * np.pi / w_min
    run = max(SEED_RUN_LENGTH, float(np.ceil(MIN_PERIODS_PER_RUN * t_max * 10.0) / 10.0))
    f_max = w_max / (2.0 * np.pi)
    rate = float(np.ceil(25.0 * f_max))
    return SweepDesign(float(w_min), float(w_max), float(round(t_max, 12)), f_max, run, runs_used + 1, runs_used, 2,
                       rate, default_windows(w_min))
