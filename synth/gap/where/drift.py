"""Slow drift of the residual, found by a CUSUM change-point test on block medians.

The residual is cut into ``n_blocks`` blocks of equal length and each block
is summarized by the median of its samples, so a fast transient that fills
less than half a block does not move it, while a slow drift does; samples
marked out by ``mask`` (the rise and overshoot of each step, see
:func:`synth.gap.where.time.localize_time`) are left out, and blocks left
with fewer than a quarter of their samples are skipped.

Noise level: ``sigma`` of the block medians is estimated from their
differences (differencing removes the drift): first ``1.4826 MAD(diff(b))``,
then the standard deviation of the differences within 3.5 of those MADs
(the MAD alone is too noisy with a few dozen blocks), divided by
``sqrt(2)``. Blocks much longer than the noise's correlation time make the
medians nearly independent, so coloured noise does not fool the estimate.
``sigma`` is floored at a tenth of the RMS of the whole residual: without
that floor a noise-free residual would turn any slowly decaying tail into a
"drift"; a drift must matter next to the rest of the gap.

Test: the cumulative sum of the deviations from the mean,
``S_k = sum_{i<=k} (b_i - mean(b)) / (sigma sqrt(m))``, behaves like a Brownian
bridge when the level is constant, so ``max |S_k|`` is compared with the
Kolmogorov distribution's ``1 - false_alarm`` quantile (1.358 at 5 %). No
in-control level has to be known. The drift starts at the change point
``argmax |S_k|``; the test is repeated on the blocks after it, and a second
significant change point ends the drift window if the level after it is
back within half the shift of the level before the drift (a bump that
returns; a continuing ramp runs to the end of the record).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.distributions import kolmogorov_ppf
from synth.errors import DataError

__all__ = ["DriftResult", "cusum_drift"]


@dataclass(frozen=True)
class DriftResult:
    """CUSUM drift detection on the residual.

    Attributes
    ----------
    detected : bool
    direction : str or None
        ``"up"`` (the record drifts above the model) or ``"down"``.
    t_start, t_end : float or None
        Estimated start and end of the drift [s].
    size : float or None
        Mean of the block medians in the drift window minus their mean before it (output units).
    statistic, threshold : float
        ``max |S_k|`` and the Kolmogorov quantile it is compared with.
    sigma : float
        Noise level of the block medians.
    block_length : int
        Samples per block.
    t_blocks, cusum : numpy.ndarray
        Block centre times and ``S_k`` (for figures).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 100, 0.1)
    >>> rng = np.random.default_rng(1)
    >>> e = rng.normal(0, 0.1, t.size) + np.where(t > 60, 0.05 * (t - 60), 0.0)
    >>> d = cusum_drift(t, e)
    >>> d.detected, d.direction, 60 < d.t_start < 80
    (True, 'up', True)
    """

    detected: bool
    direction: str | None
    t_start: float | None
    t_end: float | None
    size: float | None
    statistic: float
    threshold: float
    sigma: float
    block_length: int
    t_blocks: np.ndarray = field(repr=False)
    cusum: np.ndarray = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON (without the statistic's samples)."""
        return {"detected": self.detected, "direction": self.direction, "t_start": self.t_start,
                "t_end": self.t_end, "size": self.size, "statistic": self.statistic, "threshold": self.threshold,
                "sigma": self.sigma, "block_length": self.block_length,
                "method": "CUSUM change-point test on block medians (Brownian-bridge / Kolmogorov bound)"}


def _bridge(b: np.ndarray, sigma: float) -> np.ndarray:
    return np.cumsum(b - b.mean()) / (sigma * np.sqrt(b.size))


def cusum_drift(t: np.ndarray, e: np.ndarray, n_blocks: int = 64,
                false_alarm: float = 0.05, mask: np.ndarray | None = None) -> DriftResult:
    """Detect a slow drift of the residual ``e`` (see the module text for the method).

    Parameters
    ----------
    t, e : numpy.ndarray
        Time [s] and residual.
    n_blocks : int
        Number of blocks (fewer if the record is short: at least 4 samples per block).
    false_alarm : float
        Chance of a false alarm in the whole record for white block medians.
    mask : numpy.ndarray of bool, optional
        Samples to use (default all).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 100, 0.1)
    >>> cusum_drift(t, np.random.default_rng(0).normal(0, 1, t.size)).detected
    False
    """
    t = np.asarray(t, float)
    e = np.asarray(e, float)
    if t.shape != e.shape:
        raise DataError("time and residual must have the same length", where="residual")
    if not 0.0 < false_alarm < 1.0:
        raise DataError(f"must be in (0, 1), got {false_alarm!r}", where="false_alarm")
    use = np.ones(e.size, bool) if mask is None else np.asarray(mask, bool)
    if use.shape != e.shape:
        raise DataError("mask must have the residual's length", where="mask")
    m = min(int(n_blocks), e.size // 4)
    if m < 8:
        raise DataError(f"the record is too short for drift detection ({e.size} samples)", where="residual")
    L = e.size // m
    tb_all = t[: m * L].reshape(m, L).mean(axis=1)
    b_list, t_list, first_sample, last_sample = [], [], [], []
    for i in range(m):
        seg = slice(i * L, (i + 1) * L)
        ok = use[seg]
        if np.count_nonzero(ok) * 4 >= L:
            b_list.append(float(np.median(e[seg][ok])))
            t_list.append(float(tb_all[i]))
            first_sample.append(i * L)
            last_sample.append(min((i + 1) * L, t.size) - 1)
    b, tb = np.asarray(b_list), np.asarray(t_list)
    floor = 0.1 * float(np.sqrt(np.mean(e**2)))
    threshold = float(kolmogorov_ppf(1.0 - false_alarm))
    if b.size < 8:
        return DriftResult(False, None, None, None, None, 0.0, threshold, floor, L, tb, 0 * tb)
    d = np.diff(b)
    spread = 1.4826 * float(np.median(np.abs(d - np.median(d))))
    inlier = np.abs(d - np.median(d)) <= 3.5 * spread
    if spread > 0 and np.count_nonzero(inlier) > 5:
        spread = float(np.std(d[inlier]))
    sigma = max(spread / np.sqrt(2.0), floor) or 1e-300
    S = _bridge(b, sigma)
    stat = float(np.max(np.abs(S)))
    if stat <= threshold:
        return DriftResult(False, None, None, None, None, stat, threshold, sigma, L, tb, S)
    k0 = int(np.argmax(np.abs(S))) + 1  # first block after the change
    k1 = b.size
    after = b[k0:]
    if after.size >= 8:
        S2 = _bridge(after, sigma)
        k_back = k0 + int(np.argmax(np.abs(S2))) + 1
        shift = np.mean(b[k0:k_back]) - np.mean(b[:k0])
        back = np.mean(b[k_back:]) - np.mean(b[:k0]) if k_back < b.size else shift
        if np.max(np.abs(S2)) > threshold and abs(back) < 0.5 * abs(shift):  # it came back: a bump, not a ramp
            k1 = k_back
    size = float(np.mean(b[k0:k1]) - np.mean(b[:k0]))
    t_start = float(t[first_sample[k0]]) if k0 < b.size else float(t[-1])
    t_end = float(t[last_sample[k1 - 1]]) if k1 < b.size else float(t[-1])
    return DriftResult(True, "up" if size > 0 else "down", t_start, t_end, size, stat, threshold, sigma, L, tb, S)
