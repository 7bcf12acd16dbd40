"""A record's white-noise level without a model: the robust spread of its second difference.

A slow signal (a step response, a drift, a model error) barely enters a second difference, white noise of standard
deviation ``sigma`` enters it with ``sqrt(6) sigma``; the median absolute deviation keeps the few samples at the
input's edges out of it. Used by the gap diagnosis's held-out test and by identification's check that an edge
average's model explains the whole record.
"""

from __future__ import annotations

import numpy as np

from synth.errors import ModelError

__all__ = ["noise_sigma"]


def noise_sigma(e: np.ndarray, keep: np.ndarray | None = None) -> float:
    """Robust white-noise standard deviation from the second difference (MAD): ``1.4826 MAD / sqrt(6)``.

    Raises
    ------
    ModelError
        Fewer than five samples.

    Examples
    --------
    >>> e = 0.1 * np.random.default_rng(0).normal(size=20000)
    >>> round(float(noise_sigma(e + np.linspace(0, 5, e.size))), 2)  # a slow error barely enters a second difference
    0.1
    """
    d2 = np.diff(np.asarray(e, float), 2)
    if keep is not None:  # the second differences to use (a mask or indices into them)
        d2 = d2[keep]
    if d2.size < 3:
        raise ModelError("too few samples to estimate the noise floor", where="record")
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return 1.4826 * mad / np.sqrt(6.0)
