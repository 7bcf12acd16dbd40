"""Dynamics the model lacks: a lightly damped mode in series with the plant.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``resonance``          linear    ``G wn^2 / (s^2 + 2 zeta wn s + wn^2)``                      ``wn, zeta``
=====================  ========  ===========================================================  ==============
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from synth.gap.effects.base import Effect, Params, fastest_pole
from synth.plant import Plant

__all__ = ["ResonanceEffect"]


@dataclass(frozen=True)
class ResonanceEffect(Effect):
    """A lightly damped mode ``wn^2/(s^2 + 2 zeta wn s + wn^2)`` in series (unit DC gain).

    ``wn`` is searched on a grid (then golden section); ``zeta`` joins the nominal
    coefficients in the casadi fit as ``z`` with ``zeta = z^2 / (1 + z^2)``, so the
    fitted damping stays in ``[0, 1)``: a lightly damped mode, never an overdamped
    pair of real poles (which the lag effect, or the re-fit's own poles, describe).

    Examples
    --------
    >>> G = ResonanceEffect().augment_plant(Plant.from_string("1/(s+1)"), {"wn": 10.0, "zeta": 0.1})
    >>> round(float(abs(G.freqresp([10.0])[0]) * abs(1 + 10j)), 3)  # peak 1/(2 zeta) at wn
    5.0
    """

    name: ClassVar[str] = "resonance"
    side: ClassVar[str] = "linear"
    parameter_names: ClassVar[tuple[str, ...]] = ("wn", "zeta")
    grid_names: ClassVar[tuple[str, ...]] = ("wn",)
    factor_names: ClassVar[tuple[str, ...]] = ("zeta",)
    default_candidates: ClassVar[tuple[str, ...]] = ("resonance",)
    #: dampings the screen tries at every frequency of the grid (the joint fit treats ``zeta`` as smooth)
    screen_dampings: ClassVar[tuple[float, ...]] = (0.05, 0.1, 0.2, 0.4, 0.7)

    def off(self) -> Params:
        return {"wn": np.inf, "zeta": 1.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"wn": (0.0, np.pi / float(t[1] - t[0])), "zeta": (0.0, 1.0)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        nyquist = np.pi / float(t[1] - t[0])
        lo = min(2.0 * fastest_pole(plant), nyquist / 20)
        hi = 0.9 * nyquist  # a mode can sit anywhere below the Nyquist frequency the record resolves
        count = max(6, int(np.ceil(np.log(hi / lo) / np.log(1.32))) + 1)  # neighbours at most 32 % apart
        return [{"wn": float(w), "zeta": 0.2} for w in np.geomspace(lo, hi, count)]

    def screen_points(self, grid: list[Params], t: np.ndarray, plant: Plant) -> list[Params]:
        """Every grid frequency with each of :attr:`screen_dampings`.

        Examples
        --------
        >>> ResonanceEffect().screen_points([{"wn": 10.0, "zeta": 0.2}], np.arange(3.0), Plant.from_string("1"))[:2]
        [{'wn': 10.0, 'zeta': 0.05}, {'wn': 10.0, 'zeta': 0.1}]
        """
        return [{**g, "zeta": z} for g in grid for z in self.screen_dampings]

    #: largest damping handed to the fit (``z`` finite)
    zeta_max: ClassVar[float] = 1.0 - 1e-6
    #: above this damping ``|wn^2/(s^2 + 2 zeta wn s + wn^2)|`` has no peak: not a resonance
    no_peak_damping: ClassVar[float] = float(np.sqrt(0.5))

    def unlike_its_name(self, params: Params) -> str:
        """Why a fitted mode is no resonance ('' when it is one): its damping leaves ``|G|`` without a peak.

        On a DC motor's step runs the fit ran to ``zeta = 1``, a double real pole, and was named "resonance".

        Examples
        --------
        >>> ResonanceEffect().unlike_its_name({"wn": 30.0, "zeta": 0.2})
        ''
        >>> ResonanceEffect().unlike_its_name({"wn": 30.0, "zeta": 0.999999})[:40]
        'zeta = 1: a mode this damped has no reso'
        """
        zeta = float(params.get("zeta", 0.0))
        if zeta <= self.no_peak_damping:
            return ""
        return (f"zeta = {zeta:.3g}: a mode this damped has no resonance peak (none above {self.no_peak_damping:.3f}); "
                "real poles are a lag's, or the re-fit's own")

    def factor(self, params: Params | None = None) -> str:
        wn = float((params or {}).get("wn", 1.0))
        return f"{wn**2!r}/(s^2+2*(zeta^2/(1+zeta^2))*{wn!r}*s+{wn**2!r})"

    def to_factor(self, params: Params) -> dict[str, float]:
        """``z = sqrt(zeta / (1 - zeta))`` (``zeta`` clamped to ``[0, 1)``).

        Examples
        --------
        >>> e = ResonanceEffect()
        >>> round(e.to_factor({"zeta": 0.5})["zeta"], 6), round(e.from_factor({"zeta": 1.0})["zeta"], 6)
        (1.0, 0.5)
        >>> e.from_factor({"zeta": 1e3})["zeta"] <= 1.0  # never overdamped, whatever the solver returns
        True
        """
        zeta = float(np.clip(params.get("zeta", 0.2), 0.0, self.zeta_max))
        return {"zeta": float(np.sqrt(zeta / (1.0 - zeta)))}

    def from_factor(self, values: dict[str, float]) -> Params:
        """``zeta = z^2 / (1 + z^2)`` (inverse of :meth:`to_factor`)."""
        if "zeta" not in values:
            return {}
        z2 = float(values["zeta"]) ** 2
        return {"zeta": z2 / (1.0 + z2) if np.isfinite(z2) else 1.0}

    def augment_plant(self, plant: Plant, params: Params) -> Plant:
        wn, zeta = params.get("wn", np.inf), float(np.clip(params.get("zeta", 1.0), 0.0, 1.0))
        if not np.isfinite(wn):
            return plant
        return Plant(plant.num * wn**2, np.polymul(plant.den, [1.0, 2 * zeta * wn, wn**2]), plant.delay,
                     plant.input, plant.output, plant.label)
