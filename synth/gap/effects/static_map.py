"""A smooth static map on the command: quadratic and cubic terms around the command's center.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``static_nonlinearity``input     ``u + a2 x^2 + a3 x^3``, ``x = (u - c)/h``                   ``a2, a3``
=====================  ========  ===========================================================  ==============
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from synth.gap.effects.base import Effect, Params, command_span
from synth.plant import Plant

__all__ = ["StaticNonlinearityEffect"]


@dataclass(frozen=True)
class StaticNonlinearityEffect(Effect):
    """Smooth static input map ``u + h (a2 x^2 + a3 x^3)``, ``x = (u - c)/h`` (c the center, h half the span).

    Examples
    --------
    >>> import numpy as np
    >>> e = StaticNonlinearityEffect()
    >>> e.plant_input(np.array([0.0, 1.0, 2.0]), 1.0, {"a2": 0.1, "a3": 0.0, "center": 1.0, "scale": 1.0}).tolist()
    [0.1, 1.0, 2.1]
    """

    name: ClassVar[str] = "static_nonlinearity"
    parameter_names: ClassVar[tuple[str, ...]] = ("a2", "a3", "center", "scale")
    basis_names: ClassVar[tuple[str, ...]] = ("a2", "a3")
    default_candidates: ClassVar[tuple[str, ...]] = ("static_nonlinearity",)

    def off(self) -> Params:
        return {"a2": 0.0, "a3": 0.0, "center": 0.0, "scale": 1.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"a2": (-1.0, 1.0), "a3": (-1.0, 1.0)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        return [{"center": float(0.5 * (np.max(u) + np.min(u))), "scale": 0.5 * command_span(u)}]

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        h = params.get("scale", 1.0)
        x = (np.asarray(u, float) - params.get("center", 0.0)) / h
        return [h * x**2, h * x**3]
