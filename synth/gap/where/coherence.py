"""Input-residual coherence (Welch) and its significance threshold.

The magnitude-squared coherence is estimated from ``n_d`` non-overlapping
Hann-windowed segments (no overlap, so the segments are independent and the
classical null distribution applies). When input and residual are
independent, ``P(gamma^2 > x) = (1 - x)^(n_d - 1)``, so the level-``alpha``
threshold is ``1 - alpha^(1/(n_d - 1))``; coherence above it says that part of
the residual at that frequency is a linear function of the input, i.e. a
model error rather than noise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.errors import DataError
from synth.ident.welch import welch_coherence

__all__ = ["Coherence", "coherence_threshold", "input_residual_coherence"]


def coherence_threshold(n_segments: int, alpha: float = 0.05) -> float:
    """Level-``alpha`` threshold of the coherence estimated from ``n_segments`` independent averages.

    Examples
    --------
    >>> round(coherence_threshold(16), 4)
    0.1810
    """
    if n_segments < 2:
        raise DataError(f"need at least 2 segments, got {n_segments}", where="n_segments")
    return float(1.0 - alpha ** (1.0 / (n_segments - 1)))


@dataclass(frozen=True)
class Coherence:
    """Coherence of input and residual.

    Attributes
    ----------
    w : numpy.ndarray
        Frequencies [rad/s] (zero excluded).
    gamma2 : numpy.ndarray
        Magnitude-squared coherence.
    threshold : float
        Significance threshold for ``n_segments`` averages at level ``alpha``.
    n_segments : int
    alpha : float

    Examples
    --------
    >>> import numpy as np
    >>> c = Coherence(np.array([1.0, 2.0, 3.0]), np.array([0.05, 0.6, 0.1]), 0.18, 16, 0.05)
    >>> c.significant.tolist(), c.fraction_significant
    ([False, True, False], 0.3333333333333333)
    """

    w: np.ndarray
    gamma2: np.ndarray
    threshold: float
    n_segments: int
    alpha: float

    @property
    def significant(self) -> np.ndarray:
        """Frequencies where the coherence exceeds the threshold (mask)."""
        return self.gamma2 > self.threshold

    @property
    def fraction_significant(self) -> float:
        """Fraction of frequencies above the threshold (about ``alpha`` when nothing is there)."""
        return float(np.mean(self.significant))

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        return {"threshold": self.threshold, "n_segments": self.n_segments, "alpha": self.alpha,
                "fraction_significant": self.fraction_significant,
                "max": float(self.gamma2.max()), "w_at_max": float(self.w[np.argmax(self.gamma2)]),
                "method": "Welch, Hann window, non-overlapping segments; threshold 1 - alpha^(1/(n_d-1))"}


def input_residual_coherence(u: np.ndarray, e: np.ndarray, dt: float, n_segments: int = 16,
                             alpha: float = 0.05) -> Coherence:
    """Welch coherence of input and residual with its level-``alpha`` threshold.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> u = rng.normal(size=8000)
    >>> c = input_residual_coherence(u, u + rng.normal(size=8000), 0.01)
    >>> c.fraction_significant > 0.95, round(c.threshold, 3)
    (True, 0.181)
    """
    u = np.asarray(u, float)
    e = np.asarray(e, float)
    if u.shape != e.shape:
        raise DataError("input and residual must have the same length", where="residual")
    n_segments = int(n_segments)
    nper = u.size // max(n_segments, 1)
    if n_segments < 2 or nper < 8:
        raise DataError(f"need at least 2 segments of 8 samples ({u.size} samples, {n_segments} segments)",
                        where="n_segments")
    with np.errstate(divide="ignore", invalid="ignore"):  # bins where a segment has no power: coherence 0
        f, g = welch_coherence(u, e, dt, nper, nper)
    keep = f > 0
    return Coherence(2 * np.pi * f[keep], np.nan_to_num(g[keep]), coherence_threshold(n_segments, alpha),
                     n_segments, alpha)
