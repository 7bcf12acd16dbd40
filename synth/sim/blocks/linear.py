"""Linear blocks: any proper transfer function (:class:`Dynamics`) and the first-order :class:`Lag`.

Next to the plant they are folded into its exact discretization (:mod:`synth.sim.folding`);
elsewhere in a chain they run as a zero-order-hold state space of order up to
:data:`~synth.sim.layout.MAX_DYNAMICS_ORDER`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.sim.blocks.chain import Block, checked_positive, padded
from synth.sim.layout import DYNAMICS, MAX_DYNAMICS_ORDER, P_MAX, S_MAX

__all__ = ["Dynamics", "Lag"]


@dataclass(frozen=True)
class Dynamics(Block):
    """Linear dynamics ``num(s)/den(s)`` (proper), e.g. a sensor filter or a resonance.

    Next to the plant (the end of the actuator chain, the start of the sensor chain) the block
    is folded into the plant's exact zero-order-hold discretization; elsewhere it is discretized
    on its own with a zero-order hold (exact when its input is piecewise constant, as after a
    sample-and-hold), up to order 4.

    Parameters
    ----------
    num, den : sequence of float
        Coefficients in descending powers of ``s``.
    text : str
        The transfer function as written (for reports).

    Examples
    --------
    >>> d = Dynamics.from_string("442/((s+45)*(s+9.7))")
    >>> round(d.dc_gain(), 4)
    1.0126
    """

    num: tuple[float, ...]
    den: tuple[float, ...]
    text: str = ""
    kind: ClassVar[str] = "dynamics"
    code: ClassVar[int] = DYNAMICS
    linear: ClassVar[bool] = True

    def __post_init__(self) -> None:
        from synth.plant import Plant

        plant = Plant(np.asarray(self.num, float), np.asarray(self.den, float))  # validates properness
        object.__setattr__(self, "num", tuple(float(v) for v in plant.num))
        object.__setattr__(self, "den", tuple(float(v) for v in plant.den))
        if plant.den[-1] == 0.0:
            raise ModelError(f"{self.kind}: {self.text or 'transfer function'} has a pole at s = 0; "
                             "a block must have a finite static gain")
        if np.any(np.roots(plant.den).real >= 0):
            raise ModelError(f"{self.kind}: {self.text or 'transfer function'} is unstable")

    @classmethod
    def from_string(cls, text: str) -> Dynamics:
        """Parse a transfer function such as ``"442/((s+45)*(s+9.7))"``.

        Examples
        --------
        >>> Dynamics.from_string("10/(s+10)").den
        (1.0, 10.0)
        """
        from synth.plant import Plant

        p = Plant.from_string(text)
        if p.delay:
            raise ModelError(f"dynamics: {text!r} has a delay; use a delay block")
        return cls(tuple(p.num), tuple(p.den), text)

    def dc_gain(self) -> float:
        return float(self.num[-1] / self.den[-1])

    def state_space(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Continuous ``(A, B, C, D)`` of the block.

        Examples
        --------
        >>> A, B, C, D = Dynamics.from_string("10/(s+10)").state_space()
        >>> A.tolist(), C.tolist()
        ([[-10.0]], [10.0])
        """
        from synth.sim.discretize import tf_to_ss

        return tf_to_ss(np.asarray(self.num), np.asarray(self.den))

    def _discrete(self, dt: float):
        from synth.sim.discretize import zoh

        A, B, C, D = self.state_space()
        Ad, Bd = zoh(A, B[:, None], dt)
        return Ad, Bd[:, 0], C, D

    def parameters(self, dt: float, operating_input: float = 0.0) -> np.ndarray:
        n = len(self.den) - 1
        if n > MAX_DYNAMICS_ORDER:
            raise ModelError(f"{self.kind}: order {n} is above {MAX_DYNAMICS_ORDER}; only blocks next to the "
                             "plant (folded into it) may be of higher order")
        Ad, Bd, C, D = self._discrete(dt)
        a = np.zeros((4, 4))
        a[:n, :n] = Ad
        return padded([n, *a.ravel(), *padded(list(Bd), 4), *padded(list(C), 4), D], P_MAX)

    def initial_state(self, x: float, dt: float) -> np.ndarray:
        n = len(self.den) - 1
        if n == 0 or n > MAX_DYNAMICS_ORDER:
            return padded([], S_MAX)
        Ad, Bd, _, _ = self._discrete(dt)
        xs = np.linalg.solve(np.eye(n) - Ad, Bd * x)
        return padded(list(xs), S_MAX)

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.kind, "tf": self.text or _tf_text(self.num, self.den)}


def _tf_text(num: tuple[float, ...], den: tuple[float, ...]) -> str:
    from synth.polynomials import format_factored

    return format_factored(np.asarray(num), np.asarray(den), 6)


@dataclass(frozen=True, init=False)
class Lag(Dynamics):
    """First-order lag ``gain/(tau s + 1)`` (e.g. motor electrical or ESC filter).

    Examples
    --------
    >>> y = Lag(tau=1.0).apply(np.ones(4), dt=np.log(2.0))
    >>> y.round(4).tolist()
    [1.0, 1.0, 1.0, 1.0]
    """

    tau: float = 0.0
    gain: float = 1.0
    kind: ClassVar[str] = "lag"

    def __init__(self, tau: float, gain: float = 1.0) -> None:
        tau = checked_positive("tau", tau, "lag")
        object.__setattr__(self, "tau", tau)
        object.__setattr__(self, "gain", float(gain))
        Dynamics.__init__(self, (float(gain),), (tau, 1.0), f"{gain:g}/({tau:g}*s+1)")

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.kind, "tau": self.tau, "gain": self.gain}
