"""Timing effects: an extra pure delay and an extra first-order lag (actuator or sensor), both in the plant.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``delay``              linear    ``G exp(-d s)``                                             ``delay``
``lag``                linear    ``G / (tau s + 1)``, actuator or sensor placement            ``tau``
=====================  ========  ===========================================================  ==============
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import Effect, Params, fastest_pole
from synth.plant import Plant

__all__ = ["DelayEffect", "LagEffect"]


@dataclass(frozen=True)
class DelayEffect(Effect):
    """Extra pure delay ``d`` [s] (fitted jointly with the nominal coefficients, exact fractional delay).

    Examples
    --------
    >>> DelayEffect().augment_plant(Plant.from_string("1/(s+1)", delay=0.01), {"delay": 0.02}).delay
    0.03
    """

    name: ClassVar[str] = "delay"
    side: ClassVar[str] = "linear"
    parameter_names: ClassVar[tuple[str, ...]] = ("delay",)
    factor_names: ClassVar[tuple[str, ...]] = ("delay",)
    default_candidates: ClassVar[tuple[str, ...]] = ("delay",)
    folds_into_plant: ClassVar[bool] = True  # a further effect is fitted alone on the plant with the delay added

    def off(self) -> Params:
        return {"delay": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"delay": (-plant.delay, 0.25 * float(t[-1] - t[0]))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        dt = float(t[1] - t[0])
        return [{"delay": 2.0 * dt}]

    def screen_points(self, grid: list[Params], t: np.ndarray, plant: Plant) -> list[Params]:
        """16 delays from a quarter sample to the slowest time constant (at most a quarter of the record).

        Examples
        --------
        >>> t = np.arange(0, 10, 0.01)
        >>> g = DelayEffect().screen_points([], t, Plant.from_string("1/(s+1)"))
        >>> len(g), g[0]["delay"], round(g[-1]["delay"], 6)
        (16, 0.0025, 1.0)
        """
        dt = float(t[1] - t[0])
        p = np.abs(plant.poles())
        slow = float(np.min(p[p > 0])) if np.any(p > 0) else 1.0
        top = min(0.25 * float(t[-1] - t[0]), 1.0 / slow)
        return [{"delay": float(d)} for d in np.geomspace(0.25 * dt, max(top, dt), 16)]

    @property
    def changes_rational(self) -> bool:
        """A delay leaves the rational part alone."""
        return False

    def augment_plant(self, plant: Plant, params: Params) -> Plant:
        return plant.with_delay(max(0.0, plant.delay + params.get("delay", 0.0)))


@dataclass(frozen=True)
class LagEffect(Effect):
    """Extra first-order lag ``1/(tau s + 1)`` at the actuator or at the sensor (exact, in series with ``G``).

    On a linear model both placements give the same output; only a record with
    the actuator output logged (or a known excitation entering at the output)
    tells them apart. ``tau`` is searched on a grid (then golden section) with
    the nominal coefficients fitted by casadi at each point, which keeps the
    fit away from the stiff ``tau -> 0`` end.

    Examples
    --------
    >>> LagEffect().augment_plant(Plant.from_string("1/(s+1)"), {"tau": 0.5}).den.tolist()
    [1.0, 3.0, 2.0]
    """

    placement: str = "actuator"
    name: ClassVar[str] = "lag"
    side: ClassVar[str] = "linear"
    parameter_names: ClassVar[tuple[str, ...]] = ("tau",)
    grid_names: ClassVar[tuple[str, ...]] = ("tau",)
    spellings: ClassVar[dict[str, dict[str, str]]] = {
        "lag(sensor)": {"placement": "sensor"}, "sensor_lag": {"placement": "sensor"},
        "lag(actuator)": {"placement": "actuator"}, "actuator_lag": {"placement": "actuator"}}
    default_candidates: ClassVar[tuple[str, ...]] = ("lag", "lag(sensor)")

    def __post_init__(self) -> None:
        if self.placement not in ("actuator", "sensor"):
            raise ModelError(f"must be 'actuator' or 'sensor', got {self.placement!r}", where="lag.placement")

    @property
    def label(self) -> str:
        return "lag" if self.placement == "actuator" else "lag(sensor)"

    def to_dict(self) -> dict[str, Any]:
        return {"effect": self.label, "side": "input" if self.placement == "actuator" else "output",
                "parameters": list(self.parameter_names)}

    def off(self) -> Params:
        return {"tau": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"tau": (0.0, 1.0 / fastest_pole(plant))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        dt = float(t[1] - t[0])
        top = 1.0 / fastest_pole(plant)  # an actuator or sensor lag is faster than the plant it is added to
        # from a quarter sample, as the extra delay's search: the exact discretization sees a sub-sample lag
        return [{"tau": float(x)} for x in np.geomspace(0.25 * dt, max(2 * dt, top), 8)]

    def factor(self, params: Params | None = None) -> str | None:
        tau = float((params or {}).get("tau", 0.0))
        return f"{1.0 / tau!r}/(s+{1.0 / tau!r})" if tau > 0 else None  # monic: better scaled for the fit

    def augment_plant(self, plant: Plant, params: Params) -> Plant:
        tau = params.get("tau", 0.0)
        return Plant(plant.num, np.polymul(plant.den, [tau, 1.0]), plant.delay, plant.input, plant.output,
                     plant.label)
