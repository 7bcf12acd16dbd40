"""Supply effects: the battery sags on fast command increases.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``supply_sag``         input     ``u - a u max(0, u - u_f)``, ``tau u_f' + u_f = u``          ``sag, tau``
=====================  ========  ===========================================================  ==============

Supply sag is :class:`synth.sim.blocks.SupplySag` with a 1 V battery, a 1 ohm internal resistance and
no static current, so ``sag`` is the relative voltage drop per input unit of the command's fast part.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from synth.gap.effects.base import Effect, Params, command_span, slowest_pole
from synth.plant import Plant
from synth.sim.blocks import SupplySag

__all__ = ["SupplySagEffect"]


@dataclass(frozen=True)
class SupplySagEffect(Effect):
    """Battery sag on fast command increases (:class:`synth.sim.blocks.SupplySag`, normalized).

    With a 1 V battery, 1 ohm, no static current and no brown-out the block is
    ``v = u (1 - sag max(0, u - u_f))``, ``tau u_f' + u_f = u``: linear in
    ``sag`` (a basis parameter), ``tau`` on a grid.

    Examples
    --------
    >>> import numpy as np
    >>> phi = SupplySagEffect().input_basis(np.array([1.0, 1.0, 2.0, 2.0]), 0.01, {"tau": 1.0})[0]
    >>> phi.round(4).tolist()  # -u (u - u_f) once the command steps up
    [0.0, 0.0, -2.0, -1.9801]
    """

    name: ClassVar[str] = "supply_sag"
    parameter_names: ClassVar[tuple[str, ...]] = ("sag", "tau")
    grid_names: ClassVar[tuple[str, ...]] = ("tau",)
    basis_names: ClassVar[tuple[str, ...]] = ("sag",)
    default_candidates: ClassVar[tuple[str, ...]] = ("supply_sag",)

    def off(self) -> Params:
        return {"sag": 0.0, "tau": 0.1}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"sag": (0.0, 1.0 / max(command_span(u), 1e-12)), "tau": (float(t[1] - t[0]), float(t[-1] - t[0]))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        slow = 1.0 / slowest_pole(plant)
        return [{"tau": float(x)} for x in np.geomspace(0.05 * slow, 2.0 * slow, 5)]

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        eps = 1e-9 / max(float(np.max(np.abs(u))), 1.0) ** 2  # keeps the normalized voltage near 1: exact linearity
        block = SupplySag(v_open=1.0, r_internal=1.0, i_dynamic=eps, tau=params.get("tau", 0.1), v_reset=0.0)
        return [(block.apply(u, dt) - u) / eps]
