"""Slow drift of the residual, found by a two-sided CUSUM on block medians.

The residual is cut into ``n_blocks`` blocks of equal length and each block
is summarized by the median of its samples, so a fast transient that fills
less than half a block does not move it, while a slow drift does; samples
marked out by ``mask`` (the rise and overshoot of each step, see
:func:`synth.gap.where_time.localize_time`) are left out, and blocks left
with fewer than a quarter of their samples are skipped. The
noise level of the block medians is estimated robustly from their
differences: ``sigma = 1.4826 MAD(diff(b)) / sqrt(2)`` (differencing removes
the drift, the MAD ignores the few blocks a transient does move; blocks much
longer than the noise's correlation time make the medians nearly
independent, so coloured noise does not fool the estimate). It is floored
at a tenth of the RMS of the whole residual: without that floor a noise-free
residual would turn any slowly decaying tail into a "drift"; a drift must
matter next to the rest of the gap. The in-control level is the median of
the first quarter of the blocks.

With ``z_i = clip((b_i - level) / sigma, -3, 3)`` (clipping bounds the weight of
a single outlying block), the statistics are
``g+_i = max(0, g+_{i-1} + z_i - k)`` and ``g-_i = max(0, g-_{i-1} - z_i - k)``
with reference ``k = 0.5``. The threshold ``h`` is chosen with Siegmund's
approximation of the in-control average run length,
``ARL0 = (exp(2 k b) - 2 k b - 1) / (2 k^2)`` with ``b = h + 1.166``, so that
``ARL0 = 2 n_blocks / false_alarm``: for white block medians the chance of a
false alarm anywhere in the record is about ``false_alarm``. A drift starts at
the last block before the alarm where the alarming statistic was zero and
ends where that statistic peaks.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import brentq

from synth.errors import DataError

CLIP = 3.0


def siegmund_threshold(k: float, arl0: float) -> float:
    """CUSUM threshold ``h`` (in standard deviations) whose in-control run length is ``arl0`` samples.

    Examples
    --------
    >>> h = siegmund_threshold(0.5, 1000.0)
    >>> round(h, 3)
    5.0
    """
    if arl0 <= 1.0 or k <= 0.0:
        raise DataError(f"need arl0 > 1 and k > 0, got arl0={arl0!r}, k={k!r}", where="cusum")

    def arl(h: float) -> float:
        b = 2.0 * k * (h + 1.166)
        return (np.exp(b) - b - 1.0) / (2.0 * k * k)

    return float(brentq(lambda h: np.log(arl(h)) - np.log(arl0), 0.0, 200.0))


@dataclass(frozen=True)
class DriftResult:
    """CUSUM drift detection on the residual.

    Attributes
    ----------
    detected : bool
    direction : str or None
        ``"up"`` (the record drifts above the model) or ``"down"``.
    t_start, t_alarm, t_end : float or None
        Estimated start, time of the alarm and end of the drift [s].
    size : float or None
        Mean of the block medians over the drift minus the in-control level (output units).
    level, sigma, threshold : float
        In-control level, noise level of the block medians, threshold ``h`` [sigma].
    block_length : int
        Samples per block.
    t_blocks, g_plus, g_minus : numpy.ndarray
        Block centre times and the two CUSUM statistics (for figures).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 100, 0.1)
    >>> rng = np.random.default_rng(1)
    >>> e = rng.normal(0, 0.1, t.size) + np.where(t > 60, 0.05 * (t - 60), 0.0)
    >>> d = cusum_drift(t, e)
    >>> d.detected, d.direction, 55 < d.t_start < 70
    (True, 'up', True)
    """

    detected: bool
    direction: str | None
    t_start: float | None
    t_alarm: float | None
    t_end: float | None
    size: float | None
    level: float
    sigma: float
    threshold: float
    block_length: int
    t_blocks: np.ndarray = field(repr=False)
    g_plus: np.ndarray = field(repr=False)
    g_minus: np.ndarray = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON (without the statistics' samples)."""
        return {"detected": self.detected, "direction": self.direction, "t_start": self.t_start,
                "t_alarm": self.t_alarm, "t_end": self.t_end, "size": self.size, "level": self.level,
                "sigma": self.sigma, "threshold": self.threshold, "block_length": self.block_length,
                "method": "two-sided CUSUM on block medians, k = 0.5 sigma, h from Siegmund's ARL approximation"}


def cusum_drift(t: np.ndarray, e: np.ndarray, n_blocks: int = 64, k: float = 0.5,
                false_alarm: float = 0.05, mask: np.ndarray | None = None) -> DriftResult:
    """Detect a slow drift of the residual ``e`` (see the module text for the method).

    Parameters
    ----------
    t, e : numpy.ndarray
        Time [s] and residual.
    n_blocks : int
        Number of blocks (fewer if the record is short: at least 4 samples per block).
    k : float
        CUSUM reference value [sigma].
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
    if b.size < 8:
        return DriftResult(False, None, None, None, None, None, 0.0, floor, float("inf"), L, tb, 0 * tb, 0 * tb)
    m = b.size
    d = np.diff(b)
    sigma = max(1.4826 * float(np.median(np.abs(d - np.median(d)))) / np.sqrt(2.0), floor) or 1e-300
    level = float(np.median(b[: max(3, m // 4)]))
    z = np.clip((b - level) / sigma, -CLIP, CLIP)
    h = siegmund_threshold(k, 2.0 * m / false_alarm)
    gp, gm = np.zeros(m), np.zeros(m)
    for i in range(m):
        prev_p = gp[i - 1] if i else 0.0
        prev_m = gm[i - 1] if i else 0.0
        gp[i] = max(0.0, prev_p + z[i] - k)
        gm[i] = max(0.0, prev_m - z[i] - k)
    alarm_p = np.flatnonzero(gp > h)
    alarm_m = np.flatnonzero(gm > h)
    first = [(int(a[0]), g, name) for a, g, name in ((alarm_p, gp, "up"), (alarm_m, gm, "down")) if a.size]
    if not first:
        return DriftResult(False, None, None, None, None, None, level, sigma, h, L, tb, gp, gm)
    i_alarm, g, direction = min(first)
    zeros = np.flatnonzero(g[:i_alarm] == 0.0)
    i0 = int(zeros[-1]) + 1 if zeros.size else 0
    run_end = np.flatnonzero(g[i_alarm:] == 0.0)
    i_last = i_alarm + int(run_end[0]) - 1 if run_end.size else m - 1
    i1 = i0 + int(np.argmax(g[i0: i_last + 1]))
    size = float(np.mean(b[i0: i1 + 1]) - level)
    t_start = float(t[first_sample[i0]])
    t_end = float(t[last_sample[i1]]) if i1 < m - 1 else float(t[-1])
    return DriftResult(True, direction, t_start, float(tb[i_alarm]), t_end, size, level, sigma, h, L, tb, gp, gm)
