"""Design objectives: named scalar measures of a loop, each with a unit and a natural sense."""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from synth.freqgrid import log_grid, peak

if TYPE_CHECKING:
    from synth.loop import Loop

__all__ = ["Measure", "in_plant_units", "measure", "score"]


@dataclass(frozen=True)
class Measure:
    """A scalar measure of a loop usable as an objective.

    Attributes
    ----------
    name : str
        Name used in spec files (``objective: {maximize: bandwidth}``).
    unit : str
        Unit of the value (``u``/``y`` stand for the plant input/output units).
    sense : str
        ``"maximize"`` or ``"minimize"``: the direction that is usually better.
    description : str
        Plain words for reports.
    """

    name: str
    unit: str
    sense: str
    description: str
    evaluate: Callable[[Loop], float]


def _bandwidth(loop: Loop) -> float:
    return loop.bandwidth()


def _crossover(loop: Loop) -> float:
    wc = loop.crossover()
    return float(wc) if wc is not None else 0.0


def _low_frequency_gain(loop: Loop) -> float:
    return abs(loop.controller.dc_gain())


def _integral_gain(loop: Loop) -> float:
    num, den = loop.controller.tf()
    if den[-1] != 0.0:
        return 0.0
    return float(abs(num[-1] / den[-2]))  # lim s->0 of s*C(s)


def _peak(curve_name: str) -> Callable[[Loop], float]:
    def measure(loop: Loop) -> float:
        lo, hi = loop.frequency_range
        curve = getattr(loop, curve_name)
        value, _ = peak(lambda w: np.abs(curve(w)), log_grid(lo, hi * 10))
        return float(20 * np.log10(value))

    return measure


MEASURES: dict[str, Measure] = {
    m.name: m
    for m in (
        Measure("bandwidth", "rad/s", "maximize", "closed-loop -3 dB bandwidth of T", _bandwidth),
        Measure("crossover", "rad/s", "maximize", "gain-crossover frequency of L", _crossover),
        Measure("low_frequency_gain", "u/y", "maximize", "controller gain at s = 0, |C(0)|", _low_frequency_gain),
        Measure("integral_gain", "u/(y*s)", "maximize", "integral gain, lim s C(s) as s -> 0", _integral_gain),
        Measure("peak_sensitivity", "dB", "minimize", "peak |S| over all frequencies", _peak("S")),
        Measure("peak_complementary", "dB", "minimize", "peak |T| over all frequencies", _peak("T")),
        Measure("control_effort", "dB", "minimize", "peak |KS|, controller output per unit disturbance",
                _peak("KS")),
    )
}


def measure(name: str) -> Measure:
    """Look a measure up by name.

    Examples
    --------
    >>> measure("bandwidth").unit
    'rad/s'
    """
    try:
        return MEASURES[name]
    except KeyError:
        raise KeyError(f"unknown objective {name!r}; expected one of: {', '.join(MEASURES)}") from None


def score(loop: Loop, terms: list[tuple[str, str, float]]) -> float:
    """Weighted objective to maximize: ``sum(+w f)`` for maximized terms, ``sum(-w f)`` for minimized.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 9.0}))
    >>> round(score(loop, [("crossover", "maximize", 1.0)]), 4)
    8.9443
    """
    total = 0.0
    for name, sense, weight in terms:
        value = measure(name).evaluate(loop)
        total += weight * (value if sense == "maximize" else -value)
    return float(total)


def in_plant_units(unit: str, input_unit: str | None, output_unit: str | None) -> str:
    """A unit written in ``u`` (plant input) and ``y`` (plant output) with the plant's own units put in, when the spec
    gives both (a unit with ``/``, ``*`` or a space in parentheses); else ``unit`` as it is.

    Examples
    --------
    >>> in_plant_units("u/(y*s)", "%", "l/min"), in_plant_units("u/y", "V", "rpm"), in_plant_units("u/y", "", "rpm")
    ('%/((l/min)*s)', 'V/rpm', 'u/y')
    """
    if not (input_unit and output_unit):
        return unit

    def wrap(text: str) -> str:
        return f"({text})" if re.search(r"[/* ]", text) else text

    return re.sub(r"\b[uy]\b", lambda m: wrap(input_unit if m.group(0) == "u" else output_unit), unit)
