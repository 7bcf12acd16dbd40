"""Every effect class, by name; the default candidate list derived from them; names to effects.

Adding an effect: write its class in a module of :mod:`synth.gap.effects` (one family per module,
the class attributes of :class:`synth.gap.effects.base.Effect` filled in) and add the class to
:data:`EFFECT_CLASSES` here. Its ``default_candidates`` put it in :data:`DEFAULT_CANDIDATES`, its
``spellings`` make :func:`make_effect` build its placements from their names.
"""

from __future__ import annotations

from synth.errors import ModelError
from synth.gap.effects.actuator import BacklashEffect, DeadzoneEffect, RateLimitEffect, SaturationEffect
from synth.gap.effects.amplitude import DuffingEffect
from synth.gap.effects.auxiliary import AuxInputEffect, MeasuredSagEffect
from synth.gap.effects.base import Effect
from synth.gap.effects.damping import AmplitudeDampingEffect
from synth.gap.effects.direction import DirectionEffect
from synth.gap.effects.drift import DriftEffect
from synth.gap.effects.dynamics import ResonanceEffect
from synth.gap.effects.friction import FrictionEffect
from synth.gap.effects.quantization import QuantizationEffect
from synth.gap.effects.static_map import StaticNonlinearityEffect
from synth.gap.effects.supply import SupplySagEffect
from synth.gap.effects.timing import DelayEffect, LagEffect

__all__ = ["DEFAULT_CANDIDATES", "EFFECTS", "EFFECT_CLASSES", "aux_candidates", "make_effect"]

EFFECT_CLASSES: tuple[type[Effect], ...] = (
    DelayEffect, LagEffect, ResonanceEffect, RateLimitEffect, SaturationEffect, FrictionEffect, DeadzoneEffect,
    BacklashEffect, QuantizationEffect, SupplySagEffect, StaticNonlinearityEffect, DriftEffect, DirectionEffect,
    DuffingEffect, AmplitudeDampingEffect, MeasuredSagEffect, AuxInputEffect)
"""The registered effect classes, in the order of the default candidate list."""

EFFECTS: dict[str, type[Effect]] = {cls.name: cls for cls in EFFECT_CLASSES}
"""Every effect class by name."""

DEFAULT_CANDIDATES: tuple[str, ...] = tuple(label for cls in EFFECT_CLASSES for label in cls.default_candidates)
"""The effects tried when none are named: each registered class's ``default_candidates``, in registry order
(both placements of the lag; not friction, see :attr:`synth.gap.effects.friction.FrictionEffect.excluded_because`,
nor output clipping)."""


def make_effect(spec: str | Effect) -> Effect:
    """An effect from its name (``"lag(sensor)"``: the lag at the sensor; ``"saturation(output)"``: clipping).

    Parameters
    ----------
    spec : str or Effect
        A name of :data:`EFFECTS`, or one of a class's ``spellings``; an effect is returned as it is.

    Returns
    -------
    Effect

    Raises
    ------
    ModelError
        An unknown name.

    Examples
    --------
    >>> make_effect("rate_limit").name, make_effect("lag(sensor)").label
    ('rate_limit', 'lag(sensor)')
    >>> DEFAULT_CANDIDATES[:3]
    ('delay', 'lag', 'lag(sensor)')
    >>> make_effect("measured_sag(Voltage)").label
    'measured_sag(Voltage)'
    >>> make_effect("stiction")
    Traceback (most recent call last):
    synth.errors.ModelError: candidates: unknown effect 'stiction'; known: delay, lag, resonance, ...
    """
    if isinstance(spec, Effect):
        return spec
    text = str(spec).strip()
    for cls in EFFECT_CLASSES:
        if text in cls.spellings:
            return cls(**cls.spellings[text])
        if cls.aux_driven and text.startswith(cls.name + "(") and text.endswith(")") and len(text) > len(cls.name) + 2:
            return cls(channel=text[len(cls.name) + 1:-1].strip())  # type: ignore[call-arg]
    if text not in EFFECTS:
        raise ModelError(f"unknown effect {text!r}; known: {', '.join(EFFECTS)}", where="candidates")
    return EFFECTS[text]()


def aux_candidates(channels: list[str] | tuple[str, ...]) -> tuple[str, ...]:
    """The aux-driven candidates for measured channels: each aux-driven class once per channel.

    They join the default candidates when the record has aux channels (their trigger).

    Examples
    --------
    >>> aux_candidates(["Voltage"])
    ('measured_sag(Voltage)', 'aux_input(Voltage)')
    """
    return tuple(f"{cls.name}({c})" for c in channels for cls in EFFECT_CLASSES if cls.aux_driven)
