"""How much a fit's white-noise uncertainty understates the truth on an output interpolated onto a uniform grid.

A record with uneven time stamps is resampled (:func:`synth.data.record.uniform_columns`): the output at a grid
time ``g`` between the logged samples ``i`` and ``i + 1`` is ``(1 - f) y_i + f y_(i+1)``. The logged noise (white,
variance ``sigma^2``) becomes ``e = W n`` on the grid, ``W`` the interpolation weights. A least-squares fit on the
grid estimates the noise variance from its residuals, about ``kappa sigma^2`` with ``kappa`` the mean over the grid
of ``(1 - f)^2 + f^2`` (2/3 for positions spread evenly over the intervals), and reports ``s^2 (J^T J)^-1``. The
estimates' covariance is ``sigma^2 (J^T J)^-1 J^T W W^T J (J^T J)^-1``; where the model's sensitivities ``J`` change
little over one logged interval, ``J^T W W^T J`` is about ``sum_i c_i^2 J_i J_i^T`` and ``J^T J`` about
``sum_i c_i J_i J_i^T``, ``c_i`` the total weight logged sample ``i`` carries on the grid. With ``c`` spread evenly
over the record, the covariance is the reported one times ``(sum c^2 / sum c) / kappa``:
:func:`interpolation_noise_factor`. Averaging windows of such a record (independent noise) scales both alike.
"""

from __future__ import annotations

import numpy as np

__all__ = ["interpolation_noise_correlation", "interpolation_noise_factor"]


def _weights(native: np.ndarray, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The logged times (one per stamp), and for each grid time the logged sample ``i`` before it and its
    fraction ``f`` of the way to ``i + 1``: the grid value is ``(1 - f) y_i + f y_(i+1)``. None where the grid is
    the logged times themselves (or too few were logged to interpolate)."""
    native = np.asarray(native, float)
    native = native[np.r_[np.diff(native) > 0, True]]  # one per time stamp
    grid = np.asarray(grid, float)
    if native.size < 2 or (grid.size == native.size and np.array_equal(grid, native)):
        return None
    i = np.clip(np.searchsorted(native, grid, side="right") - 1, 0, native.size - 2)
    f = np.clip((grid - native[i]) / (native[i + 1] - native[i]), 0.0, 1.0)
    return native, i, f


def interpolation_noise_factor(native: np.ndarray, grid: np.ndarray) -> float:
    """The factor by which the white-noise variance of a fit on ``grid`` must be multiplied when the output there
    was linearly interpolated from samples at the (increasing) times ``native`` (a repeated time counts once, as
    resampling keeps one sample per time stamp): exactly 1 when every grid time is
    a logged one, about 1.5 for a grid as dense as the logged samples at random offsets, more where a gap in the
    log spreads one sample's noise over several grid points.

    Examples
    --------
    >>> interpolation_noise_factor(np.arange(5.0), np.arange(5.0))  # the logged times themselves
    1.0
    >>> round(interpolation_noise_factor(np.arange(0.0, 1001.0), np.arange(0.0, 1000.0) + 0.5), 3)  # midpoints
    2.0
    """
    weights = _weights(native, grid)
    if weights is None:  # the logged times
        return 1.0
    native, i, f = weights
    kappa = float(np.mean((1.0 - f) ** 2 + f**2))
    carried = np.bincount(i, 1.0 - f, native.size) + np.bincount(i + 1, f, native.size)
    return float(np.sum(carried**2) / np.sum(carried) / kappa)


def interpolation_noise_correlation(native: np.ndarray, grid: np.ndarray, lags: int = 20) -> tuple[float, ...]:
    """The autocorrelation at lags ``1..lags`` grid samples that linear interpolation from the times ``native``
    onto ``grid`` gives white logged noise: ``mean_g (W W^T)_(g, g+k) / mean_g (W W^T)_(g, g)``, ``W`` the
    interpolation weights. Two grid samples between the same two logged samples, or either side of one, share
    that sample's noise: a grid as dense as jittered stamps has about 0.25 at lag 1, none beyond. ``()`` when the
    grid is the logged times (white noise stays white).

    Examples
    --------
    >>> interpolation_noise_correlation(np.arange(5.0), np.arange(5.0))
    ()
    >>> [round(r, 3) for r in interpolation_noise_correlation(np.arange(0.0, 1001.0), np.arange(1000.0) + 0.5, 2)]
    [0.5, 0.0]
    """
    weights = _weights(native, grid)
    if weights is None:
        return ()
    _, i, f = weights
    a, b = 1.0 - f, f  # weights on samples i and i + 1
    energy = float(np.mean(a**2 + b**2))
    rho = []
    for k in range(1, min(int(lags), i.size - 1) + 1):
        same = i[:-k] == i[k:]  # both between the same two logged samples
        next_ = i[:-k] + 1 == i[k:]  # the later one starts at the earlier one's right sample
        shared = np.where(same, a[:-k] * a[k:] + b[:-k] * b[k:], 0.0) + np.where(next_, b[:-k] * a[k:], 0.0)
        rho.append(float(np.mean(shared)) / energy)
    return tuple(rho)
