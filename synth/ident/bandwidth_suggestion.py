"""A closed-loop bandwidth requirement suggested by a disturbance spectrum's power share."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from synth.errors import DataError

if TYPE_CHECKING:
    from synth.ident.psd import PsdAnalysis

__all__ = ["BandwidthSuggestion", "suggest_bandwidth"]


@dataclass(frozen=True)
class BandwidthSuggestion:
    """A closed-loop bandwidth requirement derived from a disturbance spectrum.

    Rule: feedback attenuates a disturbance only below the loop's bandwidth, so the closed-loop
    bandwidth must reach ``factor`` times the frequency below which ``share`` of the disturbance
    power lies (narrow-band spikes left out: they call for a notch or a filter, not bandwidth).

    Examples
    --------
    >>> BandwidthSuggestion(0.9, 62.0, 1.0, 62.0).spec_entry()
    {'type': 'bandwidth', 'min': 62.0}
    """

    share: float
    share_frequency: float
    factor: float
    min_bandwidth: float

    def spec_entry(self) -> dict[str, Any]:
        """The requirement as a spec-file entry (``docs/spec-format.md``)."""
        return {"type": "bandwidth", "min": float(f"{self.min_bandwidth:.3g}")}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"status": "suggested", "share": self.share, "share_frequency": self.share_frequency,
                "factor": self.factor,
                "min_bandwidth": self.min_bandwidth, "spec_entry": self.spec_entry(),
                "rule": f"closed-loop bandwidth >= {self.factor:g} x the frequency below which "
                        f"{100 * self.share:g} % of the disturbance power (above the noise floor, spikes left out) lies"}


def suggest_bandwidth(analysis: PsdAnalysis, factor: float = 1.0) -> BandwidthSuggestion:
    """Turn the share frequency of a spectrum into a minimum closed-loop bandwidth (rule above).

    Raises
    ------
    DataError
        ``factor`` not a finite number > 0 or the bandwidth not finite; no share frequency; or the
        analysis withholds a suggestion (``analysis.suggestion_withheld``: too few segments, or the
        power above the floor within the estimate's scatter), with its reason.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> from scipy.signal import lfilter
    >>> x = lfilter([0.05], [1, -0.95], rng.normal(size=60000))   # first-order low-pass, ~51 rad/s corner
    >>> from synth.ident.psd import analyze_psd
    >>> s = suggest_bandwidth(analyze_psd([x], 0.001))
    >>> s.spec_entry()["type"], 100 < s.min_bandwidth < 2000
    ('bandwidth', True)
    """
    if not (np.isfinite(factor) and factor > 0):
        raise DataError(f"factor must be > 0, got {factor!r}", where="psd: bandwidth factor")
    if analysis.suggestion_withheld:
        raise DataError(analysis.suggestion_withheld, where="psd")
    if analysis.share_frequency is None:
        raise DataError("the spectrum has no disturbance power above its noise floor; no bandwidth follows from it",
                        where="psd")
    bandwidth = factor * analysis.share_frequency
    if not np.isfinite(bandwidth):
        raise DataError(f"{factor:g} x the share frequency {analysis.share_frequency:.4g} rad/s is not finite",
                        where="psd: bandwidth factor")
    return BandwidthSuggestion(analysis.share, analysis.share_frequency, factor, bandwidth)
