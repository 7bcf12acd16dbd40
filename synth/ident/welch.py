"""One-sided Welch power spectral density of one or several signals (seed 1, section 5).

Conventions (as :mod:`synth.sim.signals`): one-sided PSD in ``unit^2/(rad/s)`` on ``w`` in rad/s,
so that the variance is ``integral_0^inf S(w) dw``; in dB, ``10 log10(S)`` re 1 ``unit^2/(rad/s)``.

Hann window, 50 % overlap, mean removed per segment; several records (same sample interval) are
averaged segment by segment. The DC bin is dropped. The estimate is ``scipy.signal.welch``'s (periodic
Hann window, whole segments only, density scaling, mean over segments), computed here with numpy's FFT:
importing ``scipy.signal`` costs about 0.5 s, more than the seed paper's section it serves in the design
command (``tests/test_welch.py`` holds the two together).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from synth.errors import DataError

__all__ = ["effective_dof", "unit_squared", "welch_psd"]

#: correlation of adjacent 50 %-overlapped Hann segments' estimates (Welch 1967), for the degrees of freedom
_HANN_OVERLAP_CORRELATION = 0.167


def unit_squared(unit: str) -> str:
    """``unit^2`` written unambiguously (parentheses around a compound unit).

    Examples
    --------
    >>> unit_squared("rad/s"), unit_squared("V"), unit_squared("")
    ('(rad/s)^2', 'V^2', 'unit^2')
    """
    unit = unit or "unit"
    return f"({unit})^2" if any(c in unit for c in "/* ") else f"{unit}^2"


def welch_psd(signals: Sequence[np.ndarray], dt: float, segment: float | None = None,
              w_min: float | None = None, detrend: str = "constant") -> tuple[np.ndarray, np.ndarray, int]:
    """One-sided Welch PSD [unit^2/(rad/s)] on ``w`` [rad/s] of one or several signals, averaged.

    Parameters
    ----------
    signals : sequence of numpy.ndarray
        Signals with the sample interval ``dt``.
    dt : float
        Sample interval [s].
    segment : float, optional
        Segment length [s]. Default: long enough that the bin spacing is half of ``w_min``
        (``4 pi / w_min``), or an eighth of the shortest signal.
    w_min : float, optional
        Lowest frequency of interest [rad/s].
    detrend : {"constant", "linear"}
        What is removed from each segment.

    Returns
    -------
    w : numpy.ndarray
        Frequencies [rad/s], DC left out.
    S : numpy.ndarray
        PSD [unit^2/(rad/s)].
    segments : int
        Number of segments averaged over all signals.

    Raises
    ------
    DataError
        A signal shorter than one segment (too short for ``w_min``).

    Examples
    --------
    >>> x = np.random.default_rng(0).normal(size=40000)
    >>> w, S, k = welch_psd([x], 0.001)
    >>> round(float(np.mean(S) * np.pi / 0.001), 2)  # white noise of variance 1: S = dt/pi
    1.0
    """
    if detrend not in ("constant", "linear"):
        raise DataError(f"detrend must be 'constant' or 'linear', got {detrend!r}", where="psd")
    shortest = min(np.asarray(x).size for x in signals)
    if segment is not None:
        nper = round(segment / dt)
    elif w_min is not None:
        nper = int(np.ceil(4 * np.pi / (w_min * dt)))
    else:
        nper = max(16, shortest // 8)
    if nper < 8:
        raise DataError(f"segment of {nper} samples is too short; give a longer segment", where="psd")
    if shortest < nper:
        need = nper * dt
        what = f"the lowest frequency {w_min:g} rad/s needs" if w_min is not None and segment is None else "needs"
        raise DataError(f"a record holds {shortest} samples ({shortest * dt:.4g} s); {what} segments of "
                        f"{need:.4g} s", where="psd")
    total, count = None, 0
    for x in signals:
        p, k = _periodogram_mean(np.asarray(x, float), dt, nper, detrend)
        total = p * k if total is None else total + p * k
        count += k
    f = np.fft.rfftfreq(nper, dt)
    S = total / count / (2 * np.pi)
    return 2 * np.pi * f[1:], S[1:], count


def _periodogram_mean(x: np.ndarray, dt: float, nper: int, detrend: str) -> tuple[np.ndarray, int]:
    """One-sided PSD [unit^2/Hz] of ``x``: the mean of the periodograms of its whole ``nper``-sample segments
    (hop ``nper - nper // 2``), each detrended and Hann-windowed (periodic window), and their count."""
    segments = np.lib.stride_tricks.sliding_window_view(x, nper)[::nper - nper // 2]
    if detrend == "linear":
        n = np.arange(nper, dtype=float)
        basis = np.column_stack([n - n.mean(), np.ones(nper)])
        segments = segments - (basis @ np.linalg.lstsq(basis, segments.T, rcond=None)[0]).T
    else:
        segments = segments - segments.mean(axis=1, keepdims=True)
    window = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(nper) / nper)
    spectra = np.abs(np.fft.rfft(segments * window, axis=1)) ** 2 * (dt / np.sum(window**2))
    spectra[:, 1:-1 if nper % 2 == 0 else None] *= 2.0
    return spectra.mean(axis=0), segments.shape[0]


def effective_dof(segments: int) -> float:
    """Degrees of freedom of a Welch estimate over ``segments`` 50 %-overlapped Hann segments (Welch 1967).

    Examples
    --------
    >>> effective_dof(1), round(effective_dof(10), 3)
    (2.0, 19.044)
    """
    c2 = _HANN_OVERLAP_CORRELATION**2
    return 2.0 * segments / (1.0 + 2.0 * c2 * (segments - 1) / max(segments, 1))
