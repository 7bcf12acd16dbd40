"""A sweep's lowest frequencies from the whole runs: the ratio of their transforms, where the windows are biased.

Every window of the composite (:mod:`synth.ident.spectral_windows`) is tapered (Hann), and a sweep's lowest
frequencies sit at its start, on the taper's slope: with the plant's memory the windowed output is not the
windowed input through the plant, and the estimate is biased near the longest window's limit. On a 0.5-20 rad/s
sweep of 90 s (two runs, 30 dB signal to noise) through ``4.5/((s + 0.45)(s + 2.07))`` the 60 s window was
15.1 deg off at 0.263 rad/s and 4.4 deg at 0.522 rad/s against random errors of 0.14-3 deg, the whole-run ratio
within 0.3 deg (a black-box test: 26 % of the points of the coherent band's lowest fifth within two random
errors over 44 random sweeps).

When every run starts and ends at rest (its output still at both ends and back where it began, its input
back at its first value), the
response of a run from rest is the ratio of the whole run's transforms, without a window:
``H = sum_r Y_r conj(U_r) / sum_r |U_r|^2`` with ``U_r, Y_r`` the sums of ``(u - u_rest) e^{-j w t}`` over the
samples (and the same for ``y``). It replaces the composite below :data:`WHOLE_RUN_PERIODS` periods of the
longest window. Its random error comes from the output noise's spectrum ``Gnn = Gyy (1 - gamma^2)`` of the
composite: the noise part of ``Y_r`` has the variance ``pi fs N_r Gnn`` (a rectangular window of ``N_r``
samples in the composite's scaling), so the normalized error of ``|H|`` (and of the phase in rad) is
``sqrt(pi fs Gnn sum_r N_r |U_r|^2 / 2) / (|H| sum_r |U_r|^2)``. A record that does not end at rest (a sweep cut
at full amplitude, a noise run, an output still moving) keeps the composite, biased there as before.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from synth.data import Record
from synth.ident.noise_floor import noise_sigma

__all__ = ["END_SHARE", "LEVEL_SHARE", "MOVED_SHARE", "STILL_SHARE", "WHOLE_RUN_PERIODS", "at_rest", "rest_level",
           "whole_run_response"]

WHOLE_RUN_PERIODS = 20.0
"""Below this many periods of the longest window the whole-run ratio replaces the composite. On the black-box
helper's 44 random sweep problems (15 of them from rest to rest) the band's lowest fifth had phase errors over
5 deg at 30.7 % of its points with the composite alone, 17.4 % with 10 periods, 14.9 % with 20 or 40; on 44 fresh
ones 29.9 % -> 6.4 % with 20 (within two random errors: 21 -> 57 %; the band's middle 81 -> 89 %)."""

END_SHARE = 0.02
"""Share of a run at each end looked at for rest (at least 10 samples)."""

MOVED_SHARE = 1e-3
"""The input has moved from rest once it is this share of its range away from its first sample."""

STILL_SHARE = 0.05
"""An end of a run is at rest when the output's standard deviation over it (noise and motion) is at most this
share of the run's output range (a sweep's fade-in and fade-out move the input there, and the output a little;
at 21 dB signal to noise the noise alone is about 3 % of the range)."""

LEVEL_SHARE = 0.05
"""The output's mean over each end, and the input's first and last samples, agree within this share of their
range: the run ends where it began."""


def _ends(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    k = max(10, int(END_SHARE * x.size))
    return x[:k], x[-k:]


def at_rest(run: Record) -> bool:
    """Whether the run starts and ends at rest: its output still over each end (:data:`STILL_SHARE`) and at the
    same level there (its mean within :data:`LEVEL_SHARE` of the range, beside the noise's share), its input back
    at its first value (:data:`LEVEL_SHARE`).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 20, 0.01); u = np.where((t > 2) & (t < 15), np.sin(3 * t), 0.0)
    >>> at_rest(record_from_arrays(t, u, np.convolve(u, np.exp(-t[:200]), "full")[:t.size] * 0.01))
    True
    >>> at_rest(record_from_arrays(t, np.sin(3 * t), np.sin(3 * t - 0.3)))
    False
    """
    span_y = float(np.ptp(run.y)) or 1.0
    span_u = float(np.ptp(run.u)) or 1.0
    head, tail = _ends(run.y)
    return bool(np.std(head) <= STILL_SHARE * span_y and np.std(tail) <= STILL_SHARE * span_y
                and abs(np.mean(head) - np.mean(tail)) <= LEVEL_SHARE * span_y + 4.0 * float(np.std(head) + np.std(tail))
                / np.sqrt(head.size)
                and abs(run.u[0] - run.u[-1]) <= LEVEL_SHARE * span_u)


def whole_run_response(runs: Sequence[Record], w: np.ndarray, gnn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``H`` at ``w`` from the whole runs' transforms (module text) and its normalized random error from the output
    noise spectrum ``gnn`` [unit^2/(rad/s)] at ``w``.

    Examples
    --------
    A first-order lag driven from rest by a burst of three sines, noise-free:

    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 60, 0.01); G = Plant.from_string("2/(s+1)")
    >>> u = np.where((t > 1) & (t < 40), np.sin(0.5 * t) + np.sin(1.3 * t) + np.sin(2.9 * t), 0.0)
    >>> H, err = whole_run_response([record_from_arrays(t, u, simulate_plant(G, t, u))], np.array([0.5, 1.3]), np.zeros(2))
    >>> bool(np.all(np.abs(H / G.freqresp(np.array([0.5, 1.3])) - 1) < 0.01)), err.tolist()  # the hold's lag only
    (True, [0.0, 0.0])
    """
    w = np.asarray(w, float)
    sxy = np.zeros(w.size, complex)
    sxx = np.zeros(w.size)
    snn = np.zeros(w.size)
    soff = np.zeros(w.size)
    fs = runs[0].fs
    for run in runs:
        t = run.t - run.t[0]
        rest, rest_var = rest_level(run)
        du, dy = run.u - float(run.u[0]), run.y - rest
        U = np.empty(w.size, complex)
        Y = np.empty(w.size, complex)
        D = np.empty(w.size, complex)
        for i, wi in enumerate(w):  # the transform at the grid's own frequencies, one at a time (long runs)
            kernel = np.exp(-1j * wi * t)
            U[i], Y[i], D[i] = kernel @ du, kernel @ dy, kernel.sum()
        sxy += Y * np.conj(U)
        sxx += np.abs(U) ** 2
        snn += run.t.size * np.abs(U) ** 2
        soff += rest_var * np.abs(D) ** 2 * np.abs(U) ** 2  # the rest level's error, through the samples' sum
    with np.errstate(divide="ignore", invalid="ignore"):
        H = sxy / sxx
        err = np.sqrt(np.pi * fs * np.asarray(gnn, float) * snn / 2.0 + soff) / (np.abs(H) * sxx)
    return H, err


def rest_level(run: Record) -> tuple[float, float]:
    """The output's rest level before a run (mean and variance): its mean over the samples before the input first
    moves by :data:`MOVED_SHARE` of its range, or by four times its noise (at most the run's head,
    :data:`END_SHARE`; at least the first sample).

    Before the input moves the output is at rest whatever the plant; a head that also holds a sweep's fade-in
    does not (its mean 1.2 % of the output's range off on a 0.5-15 rad/s sweep through a lightly damped mode,
    which the transforms' sum over 90 s turned into 16 % at 0.31 rad/s). The variance is the noise's over those
    samples (from their successive differences, which a slow motion does not enter) divided by their number.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0.0, 10.0, 0.1); u = np.where(t >= 1.0, 1.0, 0.0)
    >>> y = 3.0 + np.where(t >= 1.0, 1.0 - np.exp(-(t - 1.0)), 0.0)
    >>> rest_level(record_from_arrays(t, u, y))
    (3.0, 0.0)
    """
    span_u = float(np.ptp(run.u))
    head_y, _ = _ends(run.y)
    head_u = run.u[:head_y.size]
    # a measured input's noise is no motion: its level from the second differences (a smooth start hardly enters)
    noise_u = noise_sigma(head_u) if head_u.size > 4 else 0.0
    level = float(np.median(head_u[:5]))
    moved = np.flatnonzero(np.abs(head_u - level) > max(MOVED_SHARE * span_u, 4.0 * noise_u))
    m = int(moved[0]) if moved.size else head_y.size
    still = run.y[:max(m, 1)]
    if still.size < 3:
        return float(still.mean()), float(np.var(np.diff(head_y)) / 2.0 / still.size)
    return float(still.mean()), float(np.var(np.diff(still)) / 2.0 / still.size)
