"""What a disturbance spectrum holds: noise floor, spikes, trend and power share (seed 1, section 5).

Spectra as :mod:`synth.ident.welch` computes them (``unit^2/(rad/s)`` on ``w`` in rad/s).

- **Noise floor**: the median of the PSD over a floor band (default: the upper half of the
  frequency axis, spikes left out), divided by the median of the estimate's chi-square
  distribution so that it estimates the mean level.
- **Spikes**: local peaks standing more than ``threshold_db`` above a running median of the dB
  spectrum (window +-max(8 bins, 5 % of the frequency)), with frequency (parabolic interpolation),
  height, and the power standing above the median.
- **Trend**: least-squares line of dB against ``log10 w`` with equal weight per decade, spikes left
  out, over a band.
- **Share frequency**: the frequency below which ``share`` of the disturbance power lies.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.distributions import chi2_median
from synth.errors import DataError
from synth.ident.welch import effective_dof

__all__ = ["Spike", "Trend", "find_spikes", "fit_trend", "noise_floor", "running_median_db", "share_frequency"]


@dataclass(frozen=True)
class Spike:
    """A narrow-band peak of the spectrum.

    Attributes
    ----------
    w : float
        Peak frequency [rad/s] (parabolic interpolation on the dB values of three bins).
    level_db : float
        PSD at the peak [dB re 1 unit^2/(rad/s)].
    height_db : float
        How far the peak stands above the running median [dB].
    power : float
        Power above the running median over the peak's bins [unit^2]; a sinusoid of amplitude
        ``A`` gives ``A^2/2``.

    Examples
    --------
    >>> Spike(200.0, -10.0, 25.0, 0.5).amplitude
    1.0
    """

    w: float
    level_db: float
    height_db: float
    power: float

    @property
    def amplitude(self) -> float:
        """Amplitude of the sinusoid with this power [unit]."""
        return float(np.sqrt(2.0 * max(self.power, 0.0)))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"w": self.w, "level_db": self.level_db, "height_db": self.height_db, "power": self.power,
                "amplitude": self.amplitude}


@dataclass(frozen=True)
class Trend:
    """Straight line of the PSD in dB against ``log10 w``.

    Attributes
    ----------
    band : tuple of float
        Frequencies fitted [rad/s].
    slope_db_per_decade : float
    level_db_at_1 : float
        Line at ``w = 1`` rad/s [dB].
    rms_residual_db : float
    points : int

    Examples
    --------
    >>> float(Trend((1.0, 100.0), -20.0, -10.0, 0.5, 50).value_db(10.0))
    -30.0
    """

    band: tuple[float, float]
    slope_db_per_decade: float
    level_db_at_1: float
    rms_residual_db: float
    points: int

    def value_db(self, w: float | np.ndarray) -> float | np.ndarray:
        """Trend line at ``w`` [dB]."""
        return self.level_db_at_1 + self.slope_db_per_decade * np.log10(w)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"band": list(self.band), "slope_db_per_decade": self.slope_db_per_decade,
                "level_db_at_1_rad_s": self.level_db_at_1, "rms_residual_db": self.rms_residual_db,
                "points": self.points}



def running_median_db(S: np.ndarray, min_half: int = 8, fraction: float = 0.05) -> np.ndarray:
    """Running median of ``10 log10 S``: symmetric window of +-max(``min_half``, ``fraction`` k) bins.

    The window shrinks symmetrically at the ends, so a monotonic spectrum is its own median.

    Examples
    --------
    >>> s = np.ones(50); s[25] = 1000.0
    >>> float(running_median_db(s)[25])
    0.0
    """
    db = 10 * np.log10(np.maximum(S, np.finfo(float).tiny))
    n = db.size
    k = np.arange(n)
    half = np.minimum.reduce([np.maximum(min_half, (fraction * (k + 1)).astype(int)), k, n - 1 - k])
    out = np.empty(n)
    for h in np.unique(half):  # one vectorized median per window width
        at = k[half == h]
        out[at] = np.median(np.lib.stride_tricks.sliding_window_view(db, 2 * h + 1)[at - h], axis=1)
    return out


def find_spikes(w: np.ndarray, S: np.ndarray, threshold_db: float = 10.0,
                median_db: np.ndarray | None = None) -> tuple[list[Spike], np.ndarray]:
    """Narrow-band peaks standing more than ``threshold_db`` above the running median.

    Returns the spikes and a boolean mask of the bins they occupy (each spike's bins extend from
    its peak while they stand more than 3 dB above the median).

    Examples
    --------
    >>> w = np.arange(1, 201) * 1.0; S = np.ones(200); S[99] = 100.0
    >>> spikes, mask = find_spikes(w, S)
    >>> [(float(s.w), round(s.height_db)) for s in spikes], int(mask.sum())
    ([(100.0, 20)], 1)
    """
    db = 10 * np.log10(np.maximum(S, np.finfo(float).tiny))
    med = running_median_db(S) if median_db is None else median_db
    excess = db - med
    mask = np.zeros(S.size, bool)
    spikes: list[Spike] = []
    dw = float(np.median(np.diff(w))) if w.size > 1 else 1.0
    above = excess > threshold_db
    k = 1
    while k < S.size - 1:
        if not above[k]:
            k += 1
            continue
        j = k
        while j + 1 < S.size and above[j + 1]:
            j += 1
        peak = k + int(np.argmax(db[k:j + 1]))
        lo, hi = peak, peak
        while lo > 0 and excess[lo - 1] > 3.0:
            lo -= 1
        while hi < S.size - 1 and excess[hi + 1] > 3.0:
            hi += 1
        wp = float(w[peak])
        if 0 < peak < S.size - 1:
            a, b, c = db[peak - 1], db[peak], db[peak + 1]
            denom = a - 2 * b + c
            if denom < 0:
                wp += 0.5 * (a - c) / denom * dw
        power = float(np.sum(S[lo:hi + 1] - 10 ** (med[lo:hi + 1] / 10)) * dw)
        spikes.append(Spike(float(wp), float(db[peak]), float(excess[peak]), power))
        mask[lo:hi + 1] = True
        k = max(j, hi) + 1
    return spikes, mask


def fit_trend(w: np.ndarray, S: np.ndarray, band: tuple[float, float], exclude: np.ndarray | None = None) -> Trend:
    """Least-squares line of ``10 log10 S`` against ``log10 w`` on ``band``, equal weight per decade.

    Bins are uniformly spaced in ``w``, so each gets the weight ``1/w`` (its width in ``log w``);
    an unweighted fit would let the top decade decide.

    Raises
    ------
    DataError
        Fewer than 3 bins in the band.

    Examples
    --------
    >>> w = np.arange(1.0, 1001.0)
    >>> round(fit_trend(w, 1 / w**2, (1.0, 1000.0)).slope_db_per_decade, 6)
    -20.0
    """
    sel = (w >= band[0]) & (w <= band[1])
    if exclude is not None:
        sel &= ~exclude
    n = int(np.count_nonzero(sel))
    if n < 3:
        raise DataError(f"only {n} bin(s) between {band[0]:.4g} and {band[1]:.4g} rad/s; the trend needs 3",
                        where="psd: band")
    x = np.log10(w[sel])
    y = 10 * np.log10(np.maximum(S[sel], np.finfo(float).tiny))
    sw = np.sqrt(1.0 / w[sel])
    A = np.column_stack([np.ones(n), x])
    coef, *_ = np.linalg.lstsq(A * sw[:, None], y * sw, rcond=None)
    resid = y - A @ coef
    return Trend((float(band[0]), float(band[1])), float(coef[1]), float(coef[0]),
                 float(np.sqrt(np.average(resid**2, weights=sw**2))), n)


def noise_floor(w: np.ndarray, S: np.ndarray, segments: int, band: tuple[float, float] | None = None,
                exclude: np.ndarray | None = None) -> tuple[float, tuple[float, float]]:
    """Mean PSD level of a flat noise floor, estimated robustly as a bias-corrected median.

    The median of ``S`` over ``band`` (default: the upper half of the frequency axis; bins in
    ``exclude`` left out) is divided by the median of ``chi2(nu)/nu``, ``nu`` the estimate's
    degrees of freedom for ``segments`` 50 %-overlapped Hann segments.

    Returns the floor [unit^2/(rad/s)] and the band used.

    Examples
    --------
    >>> x = np.random.default_rng(1).normal(size=100000)
    >>> from synth.ident.welch import welch_psd
    >>> w, S, k = welch_psd([x], 0.001)
    >>> floor, band = noise_floor(w, S, k)
    >>> round(floor * np.pi / 0.001, 2)
    1.0
    """
    band = band or (float(w[-1]) / 2, float(w[-1]))
    sel = (w >= band[0]) & (w <= band[1])
    if exclude is not None and np.count_nonzero(sel & ~exclude) >= 3:
        sel &= ~exclude
    if np.count_nonzero(sel) < 3:
        raise DataError(f"fewer than 3 bins between {band[0]:.4g} and {band[1]:.4g} rad/s for the noise floor",
                        where="psd: floor band")
    nu = effective_dof(segments)
    return float(np.median(S[sel]) / (chi2_median(nu) / nu)), (float(band[0]), float(band[1]))


def share_frequency(w: np.ndarray, D: np.ndarray, share: float) -> float:
    """Frequency below which ``share`` of the power of density ``D`` lies (first crossing, interpolated).

    Each bin covers ``w_k +- dw/2``; ``D`` may be negative in places (floor subtracted, not clipped).

    Examples
    --------
    >>> w = np.arange(1.0, 101.0)
    >>> share_frequency(w, np.ones(100), 0.9)
    90.5
    """
    if not 0 < share < 1:
        raise DataError(f"share must lie strictly between 0 and 1, got {share!r}", where="psd: share")
    dw = float(np.median(np.diff(w)))
    cum = np.cumsum(D) * dw
    total = cum[-1]
    if not total > 0:
        raise DataError("no disturbance power above the noise floor", where="psd")
    target = share * total
    k = int(np.argmax(cum >= target))
    prev = cum[k - 1] if k > 0 else 0.0
    upper = w[k] + dw / 2
    return float(upper - dw + dw * (target - prev) / (cum[k] - prev))
