"""Disturbance records with uneven time stamps, for the Welch spectrum of :mod:`synth.ident.psd`.

Linear interpolation onto a uniform grid low-passes a spectrum; stamps that only jitter about a uniform grid are
used as they are on it, and other uneven stamps keep the interpolation with its attenuation stated.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

import numpy as np

from synth.data.disturbance import DisturbanceRecord, disturbance_from_arrays, read_disturbance_columns
from synth.ident.welch import welch_psd

__all__ = ["GAP_FACTOR", "load_psd_record", "load_psd_records", "psd_record", "split_at_gaps"]

GAP_FACTOR = 5.0
"""A time-stamp interval this many times the median interval or longer is a gap the spectrum is not interpolated
across: the record is split there and its pieces are averaged as separate records (a 0.5 s hole in 80 s of white
noise and a 50 Hz tone, interpolated, gave a -1.8 dB/decade trend and a bandwidth suggestion of 320 rad/s)."""


def psd_record(t: np.ndarray, x: np.ndarray, name: str = "y", unit: str = "", source: str = "arrays",
               time_name: str = "time", notes: tuple[str, ...] = ()) -> tuple[DisturbanceRecord, float]:
    """A disturbance record for the Welch spectrum from samples at the logged stamps ``t``, and the variance (mean
    square about the mean) of those samples [unit^2].

    Even stamps give the record :func:`synth.data.disturbance.disturbance_from_arrays` gives. Uneven ones are
    resampled there by linear interpolation, which low-passes the spectrum: a grid value a fraction ``p`` of the
    way between two stamps one interval apart is ``(1-p) x_k + p x_{k+1}``, which passes
    ``1 - 2 p (1-p) (1 - cos w dt)`` of the power at ``w`` (a third at the Nyquist frequency, two thirds of a
    white signal's power, for ``p`` spread evenly). So:

    - stamps that jitter around a uniform grid (every stamp within 45 % of an interval of its slot on the grid
      fitted to them by least squares, strictly increasing) give the samples as they are on that grid, not
      interpolated. The jitter ``e`` only keeps ``|mean(exp(j w e))|^2`` of a component at ``w`` coherent
      (the rest becomes a white floor); the note states it at the Nyquist frequency;
    - other uneven stamps (gaps) keep the interpolated record, and the note states the attenuation, measured
      by interpolating white noise at the same stamps (Welch PSD over the white level), at half the Nyquist
      frequency and near it, and where it exceeds 1 dB.

    ``notes`` (the file's) come first in the record's notes.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(4000) * 0.002 + rng.uniform(-0.0004, 0.0004, 4000); x = rng.normal(size=4000)
    >>> r, var = psd_record(t, x)
    >>> bool(np.all(r.x == x)), round(var, 3) == round(float(np.var(x)), 3), "not interpolated" in r.notes[-1]
    (True, True, True)
    """
    t, x = np.asarray(t, float), np.asarray(x, float)
    record = disturbance_from_arrays(t, x, name, unit, source, time_name)
    raw_var = float(np.var(x))
    stamps = t[np.r_[np.diff(t) > 0, True]]  # one per time stamp, as the resampling keeps
    if record.t.size == stamps.size and np.array_equal(record.t, stamps):  # the logged times: nothing interpolated
        return replace(record, notes=(*notes, *record.notes)), raw_var
    n = t.size
    steps = np.diff(t)
    if np.all(steps > 0):
        # the grid fitted to all the stamps (least squares): one through the first and the last stamp carries
        # their own jitter, and stamps jittered uniformly by +-30 % of an interval then strayed 60 % from it
        dt, t0 = (float(c) for c in np.polyfit(np.arange(n, dtype=float), t, 1))
        dev = t - (t0 + np.arange(n) * dt)
        if float(np.max(np.abs(dev))) < 0.45 * dt:
            w_nyq = math.pi / dt
            coherent = float(np.abs(np.mean(np.exp(1j * w_nyq * dev))) ** 2)
            note = (f"time stamps jitter around a uniform {dt:.4g} s grid (rms {np.std(dev):.3g} s, "
                    f"{100 * np.std(dev) / dt:.2g} % of the interval; at most {100 * np.max(np.abs(dev)) / dt:.2g} %): "
                    "the samples are used as they are on that grid, not interpolated (linear interpolation "
                    "would attenuate the spectrum, by up to 4.8 dB at the Nyquist frequency); the jitter keeps "
                    f"{10 * math.log10(max(coherent, 1e-300)):.2g} dB of a component at the Nyquist frequency "
                    f"{w_nyq:.4g} rad/s coherent (less below it) and spreads the rest as white noise")
            on_grid = disturbance_from_arrays(t0 + np.arange(n) * dt, x, name, unit, source, time_name)
            return replace(on_grid, notes=(*notes, *on_grid.notes, note)), raw_var
    grid, dt = record.t, record.dt
    made_up = max(0.0, 1.0 - stamps.size / grid.size)  # grid points without a logged sample of their own
    record = replace(record, made_up=made_up)
    w_nyq = math.pi / dt
    # what the interpolation does to a white signal at these very stamps, measured: its Welch PSD over the white level
    rng = np.random.default_rng(0)
    zs = [rng.normal(size=stamps.size) for _ in range(4)]  # 4 white signals, 64-sample segments: within ~0.1 dB
    wz, Sz, _ = welch_psd([np.interp(grid, stamps, z) for z in zs], dt, segment=64 * dt)
    kept = Sz / (float(np.mean([np.var(z) for z in zs])) * dt / math.pi)

    def kept_db(w: float) -> float:
        return float(10 * np.log10(max(float(np.interp(w, wz, kept)), 1e-300)))

    below = np.flatnonzero(kept < 10 ** (-1.0 / 10))
    w1 = float(wz[below[0]]) if below.size else None
    where = (f"more than 1 dB above about {w1:.4g} rad/s, so a roll-off toward the Nyquist frequency, and a share "
             "frequency or bandwidth suggestion drawn from it, may be the interpolation's own" if w1 is not None
             else "less than 1 dB everywhere")
    note = (f"time stamps are uneven (intervals {steps.min():.4g}-{steps.max():.4g} s, not a jittered uniform grid): "
            f"resampled onto a uniform {dt:.4g} s grid by linear interpolation; linear interpolation attenuates the "
            f"spectrum (measured on white noise at these stamps): {kept_db(w_nyq / 2):.2g} dB at half the Nyquist "
            f"frequency ({w_nyq / 2:.4g} rad/s), {kept_db(w_nyq * 0.95):.2g} dB near the Nyquist frequency "
            f"({w_nyq:.4g} rad/s); {where}. The variance of the raw samples is {raw_var:.4g}, of the "
            f"interpolated ones {float(np.var(record.x)):.4g}")
    if made_up > 0.0:
        note += (f"; {100 * made_up:.2g} % of the grid's samples are made up across dropped stamps (a tone interpolated "
                 "across them spreads its error over every frequency)")
    return replace(record, notes=(*notes, *record.notes, note)), raw_var


def split_at_gaps(t: np.ndarray, x: np.ndarray) -> tuple[list[tuple[np.ndarray, np.ndarray]], str | None]:
    """The pieces of a record between gaps of its time stamps (intervals of :data:`GAP_FACTOR` median intervals or
    more), pieces shorter than an eighth of the longest left out, and a note (None without a gap).

    Examples
    --------
    >>> t = np.r_[np.arange(1000), np.arange(1500, 2500)] * 0.001
    >>> pieces, note = split_at_gaps(t, np.sin(t))
    >>> [p[0].size for p in pieces], note[:40]
    ([1000, 1000], '1 gap(s) in the time stamps of 5 interva')
    """
    steps = np.diff(t)
    positive = steps[steps > 0]
    if positive.size == 0:
        return [(t, x)], None
    cuts = np.flatnonzero(steps >= GAP_FACTOR * float(np.median(positive)))
    if cuts.size == 0:
        return [(t, x)], None
    pieces = np.split(np.arange(t.size), cuts + 1)
    longest = max(p.size for p in pieces)
    keep = [p for p in pieces if p.size >= max(16, longest // 8)]
    left = sum(p.size for p in pieces) - sum(p.size for p in keep)
    note = (f"{cuts.size} gap(s) in the time stamps of {GAP_FACTOR:g} intervals or more (the longest "
            f"{float(steps[cuts].max()):.4g} s): the record is split there and its {len(keep)} piece(s) are averaged "
            "as separate records, nothing interpolated across a gap")
    if left:
        note += (f"; {len(pieces) - len(keep)} piece(s) shorter than an eighth of the longest ({100 * left / t.size:.2g} % "
                 "of the samples) left out")
    return [(t[p], x[p]) for p in keep], note


def load_psd_records(path: str | Path, time: str | None, signal: str, unit: str = "", dt: float | None = None,
                     columns: Mapping[str, str] | None = None) -> list[tuple[DisturbanceRecord, float]]:
    """:func:`load_psd_record` with the record split at gaps of its time stamps (:func:`split_at_gaps`): each
    piece, and the variance of the whole file's raw samples (the same for every piece).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "d.csv"
    >>> t = np.r_[np.arange(200), np.arange(400, 600)] * 0.001
    >>> _ = p.write_text("t,x\\n" + "".join(f"{a},{(-1) ** k}\\n" for k, a in enumerate(t)))
    >>> [r.x.size for r, _ in load_psd_records(p, "t", "x")]
    [200, 200]
    """
    raw = read_disturbance_columns(path, time, signal, unit, dt, columns)
    pieces, note = split_at_gaps(raw.t, raw.x)
    raw_var = float(np.var(raw.x))
    out = []
    for t, x in pieces:
        record, _ = psd_record(t, x, raw.column, raw.unit, raw.source, raw.time_name,
                               (*raw.notes, *([note] if note else [])))
        out.append((replace(record, name=raw.name), raw_var))
    return out


def load_psd_record(path: str | Path, time: str | None, signal: str, unit: str = "", dt: float | None = None,
                    columns: Mapping[str, str] | None = None) -> tuple[DisturbanceRecord, float]:
    """:func:`synth.data.disturbance.load_disturbance` for a spectrum: the file read once, uneven time stamps
    handled by :func:`psd_record`.

    Returns the record and the variance (mean square about the mean) of the raw samples [unit^2].

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "d.csv"
    >>> _ = p.write_text("t,x\\n" + "".join(f"{k * 0.001},{(-1) ** k}\\n" for k in range(20)))
    >>> r, var = load_psd_record(p, "t", "x")
    >>> r.dt, var
    (0.001, 1.0)
    """
    raw = read_disturbance_columns(path, time, signal, unit, dt, columns)
    record, raw_var = psd_record(raw.t, raw.x, raw.column, raw.unit, raw.source, raw.time_name, raw.notes)
    return replace(record, name=raw.name), raw_var
