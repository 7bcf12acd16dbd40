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

__all__ = ["effective_dof", "segment_spectra", "unit_squared", "welch_coherence", "welch_density", "welch_psd"]

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
    option = "--segment" if segment is not None else "--w-min" if w_min is not None else "psd"  # what set the length
    if nper < 8:
        raise DataError(f"a segment of {nper} samples of {dt:.4g} s is too short (8 at least); give a longer segment "
                        "or a lower frequency", where=option)
    if shortest < nper:
        need = nper * dt
        what = f"the lowest frequency {w_min:g} rad/s needs" if w_min is not None and segment is None else "needs"
        raise DataError(f"a record holds {shortest} samples ({shortest * dt:.4g} s); {what} segments of "
                        f"{need:.4g} s", where=option)
    total, count = None, 0
    for x in signals:
        x = np.asarray(x, float)
        _, p = welch_density(x, dt, nper, nper - nper // 2, detrend)
        k = 1 + (x.size - nper) // (nper - nper // 2)  # whole segments
        total = p * k if total is None else total + p * k
        count += k
    f = np.fft.rfftfreq(nper, dt)
    S = total / count / (2 * np.pi)
    return 2 * np.pi * f[1:], S[1:], count


def segment_spectra(x: np.ndarray, dt: float, nper: int, hop: int, detrend: str = "constant") -> np.ndarray:
    """FFTs of the whole ``nper``-sample segments of ``x`` that start ``hop`` samples apart (one row each),
    each segment detrended and Hann-windowed (periodic window), scaled so that ``|X|^2`` is the segment's
    two-sided periodogram [unit^2/Hz] on ``numpy.fft.rfftfreq(nper, dt)``.

    Examples
    --------
    >>> x = np.random.default_rng(0).normal(size=4096)
    >>> X = segment_spectra(x, 0.001, 256, 128)
    >>> X.shape, round(float(np.mean(np.abs(X) ** 2)) / 0.001, 1)  # white, variance 1: two-sided S = dt
    ((31, 129), 1.0)
    """
    segments = np.lib.stride_tricks.sliding_window_view(np.asarray(x, float), nper)[::hop]
    if detrend == "linear":
        n = np.arange(nper, dtype=float)
        basis = np.column_stack([n - n.mean(), np.ones(nper)])
        segments = segments - (basis @ np.linalg.lstsq(basis, segments.T, rcond=None)[0]).T
    else:
        segments = segments - segments.mean(axis=1, keepdims=True)
    window = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(nper) / nper)
    return np.fft.rfft(segments * window, axis=1) * np.sqrt(dt / np.sum(window**2))


def _one_sided(two_sided: np.ndarray, nper: int) -> np.ndarray:
    """Fold a two-sided density on ``rfftfreq(nper)`` into the one-sided one (every bin but DC and Nyquist
    doubled)."""
    out = np.array(two_sided, float)
    out[1:-1 if nper % 2 == 0 else None] *= 2.0
    return out


def welch_density(x: np.ndarray, dt: float, nper: int, hop: int, detrend: str = "constant",
                  ) -> tuple[np.ndarray, np.ndarray]:
    """One-sided Welch PSD [unit^2/Hz] of ``x`` on ``f`` [Hz] (DC included), segments of ``nper`` samples
    ``hop`` apart, each detrended: ``scipy.signal.welch``'s density with a Hann window.

    Examples
    --------
    >>> x = np.random.default_rng(1).normal(size=20000)
    >>> f, p = welch_density(x, 0.01, 500, 250)
    >>> float(f[1]), round(float(np.mean(p[1:-1])) / (2 * 0.01), 1)  # white, variance 1: p = 2 dt
    (0.2, 1.0)
    """
    spectra = segment_spectra(x, dt, nper, hop, detrend)
    return np.fft.rfftfreq(nper, dt), _one_sided(np.mean(np.abs(spectra) ** 2, axis=0), nper)


def welch_coherence(x: np.ndarray, y: np.ndarray, dt: float, nper: int, hop: int) -> tuple[np.ndarray, np.ndarray]:
    """Magnitude-squared coherence of ``x`` and ``y`` on ``f`` [Hz] from Welch averages (Hann segments of
    ``nper`` samples ``hop`` apart, mean removed): ``scipy.signal.coherence``'s estimate. A bin where a
    signal has no power gives NaN.

    Examples
    --------
    >>> rng = np.random.default_rng(2)
    >>> u = rng.normal(size=8000)
    >>> f, g = welch_coherence(u, u + 0.1 * rng.normal(size=8000), 0.01, 400, 400)
    >>> bool(np.all(g[1:] > 0.95))
    True
    """
    X, Y = segment_spectra(x, dt, nper, hop), segment_spectra(y, dt, nper, hop)
    pxy = np.mean(np.conj(X) * Y, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.abs(pxy) ** 2 / (np.mean(np.abs(X) ** 2, axis=0) * np.mean(np.abs(Y) ** 2, axis=0))
    return np.fft.rfftfreq(nper, dt), g


def effective_dof(segments: int) -> float:
    """Degrees of freedom of a Welch estimate over ``segments`` 50 %-overlapped Hann segments (Welch 1967).

    Examples
    --------
    >>> effective_dof(1), round(effective_dof(10), 3)
    (2.0, 19.044)
    """
    c2 = _HANN_OVERLAP_CORRELATION**2
    return 2.0 * segments / (1.0 + 2.0 * c2 * (segments - 1) / max(segments, 1))
