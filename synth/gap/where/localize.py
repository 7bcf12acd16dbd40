"""Localize the sim-to-real gap: residual, time, frequency and regime in one call, and a headline.

:func:`localize_gap` returns a :class:`GapLocalization` whose ``to_dict()`` is
the ``gap`` and ``where`` part of the diagnosis JSON::

    {"gap": {"nrmse": 0.12, "fit_percent": 88.0, ...},
     "where": {"time_windows": [[t0, t1, share]], "frequency_bands": [[w0, w1, share]],
               "regimes": {...}, "time": {...}, "frequency": {...}},
     "headline": "gap 12 % NRMSE, mostly during rise of up-steps, 20-80 rad/s, grows with input rate"}
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from synth.data.record import Record
from synth.gap.where.frequency import FrequencyLocalization, localize_frequency
from synth.gap.where.regime import RegimeVariable, localize_regime
from synth.gap.where.residual import ModelResidual, model_residual
from synth.gap.where.time import TimeLocalization, localize_time
from synth.plant import Plant

__all__ = ["REGIME_WORDS", "GapLocalization", "WhereResult", "headline", "localize_gap"]

REGIME_WORDS = {"amplitude": "input amplitude", "rate": "input rate", "operating_point": "output level",
                "direction": "direction of motion"}


@dataclass(frozen=True)
class WhereResult:
    """Where the residual lies: in time, in frequency and by regime.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 20, 0.01)
    >>> u = np.where((t % 4) >= 2, 1.0, 0.0)
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> from synth.ident.simulate import simulate_plant
    >>> y = simulate_plant(G, t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> sorted(localize_gap(G, record_from_arrays(t, u, y)).where.to_dict())[:3]
    ['frequency', 'frequency_bands', 'regimes']
    """

    time: TimeLocalization
    frequency: FrequencyLocalization
    regimes: dict[str, RegimeVariable]

    def to_dict(self) -> dict[str, Any]:
        """The ``"where"`` part of the diagnosis JSON."""
        return {"time_windows": [w.to_list() for w in self.time.windows],
                "frequency_bands": [b.to_list() for b in self.frequency.bands],
                "regimes": {k: v.to_dict() for k, v in self.regimes.items()},
                "time": self.time.to_dict(), "frequency": self.frequency.to_dict()}


def _time_phrase(time: TimeLocalization) -> str | None:
    parts = []
    dom = time.dominant_phase()
    if dom is not None:
        d, p, share = dom
        both = sum(time.phases[k][p] for k in time.phases)
        where = f"{p} of {d}-steps"
        if share < 2.0 / 3.0 * both:  # the other direction holds a comparable part: name the phase only
            where, share = f"{p} of steps (up and down)", both
    if dom is not None and share >= 0.2:
        parts.append(f"mostly during {where}" if share >= 0.5 else f"largest share during {where} ({100 * share:.0f} %)")
    elif time.windows and time.windows[0].share >= 0.2:
        w = time.windows[0]
        parts.append(f"{'mostly' if w.share >= 0.5 else 'largest share'} in t = {w.t0:.3g}-{w.t1:.3g} s")
    if time.drift.detected:
        parts.append(f"drifts {time.drift.direction} from t = {time.drift.t_start:.3g} s")
    return ", ".join(parts) or None


def _frequency_phrase(freq: FrequencyLocalization) -> str:
    if freq.bands:
        b = freq.bands[0]
        return f"{b.w0:.3g}-{b.w1:.3g} rad/s"
    if freq.xcorr.to_dict()["causal_significant"] or freq.coherence.fraction_significant > 2 * freq.coherence.alpha:
        return "input-correlated but no significant error-model band"
    return "no significant input-correlated error"


def _regime_phrase(regimes: dict[str, RegimeVariable]) -> str | None:
    growing = [v for v in regimes.values() if v.trend == "grows"]
    if growing:
        v = max(growing, key=lambda v: v.contrast)
        return f"grows with {REGIME_WORDS.get(v.name, v.name.replace('aux:', ''))}"
    high = [v for v in regimes.values() if v.flagged_high is not None]
    if high:
        v = max(high, key=lambda v: v.contrast)
        b = v.flagged_high
        word = REGIME_WORDS.get(v.name, v.name.replace("aux:", ""))
        return f"larger at {word} {b.label} (x{b.ratio:.2g})"
    return None


def headline(residual: ModelResidual, where: WhereResult) -> str:
    """One plain-language line: size of the gap, when, which frequencies, which regime.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 20, 0.01)
    >>> u = np.where((t % 4) >= 2, 1.0, 0.0)
    >>> from synth.ident.simulate import simulate_plant
    >>> y = simulate_plant(Plant.from_string("1/(0.3*s+1)"), t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> localize_gap(Plant.from_string("1/(0.1*s+1)"), record_from_arrays(t, u, y)).headline.split(",")[0]
    'gap 35 % NRMSE (fit 65 %)'
    """
    parts = [f"gap {100 * residual.nrmse:.0f} % NRMSE (fit {residual.fit_percent:.0f} %)"]
    for phrase in (_time_phrase(where.time), _frequency_phrase(where.frequency), _regime_phrase(where.regimes)):
        if phrase:
            parts.append(phrase)
    return ", ".join(parts)


@dataclass(frozen=True)
class GapLocalization:
    """The residual of a model on a record and where it lies.

    Attributes
    ----------
    residual : ModelResidual
    where : WhereResult
    headline : str

    Examples
    --------
    >>> import json, numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 10, 0.01)
    >>> u = np.where((t % 4) >= 2, 1.0, 0.0)
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> from synth.ident.simulate import simulate_plant
    >>> y = simulate_plant(G, t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> d = json.loads(json.dumps(localize_gap(G, record_from_arrays(t, u, y)).to_dict()))
    >>> sorted(d), sorted(d["gap"])[:2]
    (['gap', 'headline', 'where'], ['fit_percent', 'initial'])
    """

    residual: ModelResidual
    where: WhereResult
    headline: str

    def to_dict(self) -> dict[str, Any]:
        """``{"gap": ..., "where": ..., "headline": ...}`` (JSON-serializable)."""
        return {"gap": self.residual.to_dict(), "where": self.where.to_dict(), "headline": self.headline}


def localize_gap(plant: Plant, record: Record, initial: str = "steady", offset: str | float = "fit",
                 n_bins: int = 5, level: float = 0.95, max_lag: int = 50, n_segments: int = 16,
                 na: int = 4, nb: int = 10, burn_in: float = 0.0) -> GapLocalization:
    """Simulate ``plant`` on the record's input and localize its residual in time, frequency and regime.

    Parameters
    ----------
    plant : Plant
        The model.
    record : Record
        The measured record (its ``aux`` channels become regime variables).
    initial, offset
        See :func:`synth.gap.where.residual.model_residual`.
    n_bins : int
        Bins per regime variable.
    level : float
        Confidence level of the frequency and regime tests.
    max_lag, n_segments, na, nb : int
        Cross-correlation lags, Welch segments, error-model orders (see :mod:`synth.gap.where.frequency`).
    burn_in : float
        Seconds at the start left out of the residual (see :func:`synth.gap.where.residual.model_residual`).

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 10, 0.01)
    >>> u = np.where((t % 4) >= 2, 1.0, 0.0)
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> from synth.ident.simulate import simulate_plant
    >>> y = simulate_plant(G, t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> loc = localize_gap(G, record_from_arrays(t, u, y))
    >>> loc.residual.nrmse < 0.05, loc.where.frequency.bands
    (True, [])
    """
    residual = model_residual(plant, record, initial=initial, offset=offset, burn_in=burn_in)
    time = localize_time(residual, false_alarm=1.0 - level)
    frequency = localize_frequency(residual, max_lag=max_lag, n_segments=n_segments, na=na, nb=nb, level=level,
                                   plant=plant)
    regimes = localize_regime(residual, plant, record.aux, n_bins=n_bins, level=level,
                              units=(record.input.unit, record.output.unit))
    where = WhereResult(time, frequency, regimes)
    return GapLocalization(residual, where, headline(residual, where))
