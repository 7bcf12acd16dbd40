"""Linear blocks next to the plant, folded into it: one continuous core discretized exactly.

The trailing linear blocks of the actuator chain (a motor lag) and the leading linear blocks of
the sensor chain (a sensor filter) commute with nothing nonlinear between them and the plant, so
they join the plant's state space (:func:`plant_core`) and share its exact zero-order-hold
discretization with the delay (:mod:`synth.sim.discretize`). :func:`fold_counts` says how many.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from synth.sim.discretize import tf_to_ss

if TYPE_CHECKING:
    from synth.plant import Plant
    from synth.sim.blocks import Block
    from synth.sim.loops import OperatingPoint

__all__ = ["PlantCore", "fold_counts", "plant_core"]


def fold_counts(act: list[Block], sen: list[Block]) -> tuple[int, int]:
    """How many blocks fold into the plant: the trailing linear run of the actuator chain ``act``
    and the leading linear run of the sensor chain ``sen`` (delay blocks already removed).

    Examples
    --------
    >>> from synth.sim.blocks import Lag, Saturation
    >>> fold_counts([Saturation(0, 1), Lag(0.01)], [Lag(0.002), Saturation(0, 1), Lag(0.1)])
    (1, 1)
    """
    a = 0
    while a < len(act) and act[len(act) - 1 - a].linear:
        a += 1
    s = 0
    while s < len(sen) and sen[s].linear:
        s += 1
    return a, s


def _series_tf(blocks: list[Block]) -> tuple[np.ndarray, np.ndarray]:
    num, den = np.array([1.0]), np.array([1.0])
    for b in blocks:
        num = np.polymul(num, b.num)  # type: ignore[attr-defined]
        den = np.polymul(den, b.den)  # type: ignore[attr-defined]
    return num, den


@dataclass
class PlantCore:
    """Continuous plant core with inputs ``[w, d_in, d_out]`` and outputs ``[y_true, y_sensed]`` (deviations).

    ``w`` is the actuator chain's output less the operating-point input, ``d_in`` and ``d_out``
    the disturbances at the plant input and output; ``y_sensed`` is the output after the folded
    sensor blocks.

    Attributes
    ----------
    A, B, C, D : ndarray
        State space; ``B`` is ``n x 3``, ``C`` is ``2 x n``, ``D`` is ``2 x 3``.
    input_offset : float
        Constant added to ``d_in``: ``(H(0) - 1) u0`` for folded actuator blocks of static gain ``H(0)``.
    sensed_offset : float
        ``F(0) y0`` for folded sensor blocks of static gain ``F(0)``.

    Examples
    --------
    >>> from synth.plant import Plant
    >>> from synth.sim.loops import OperatingPoint
    >>> core = plant_core(Plant.from_string("2/(s+1)"), [], [], OperatingPoint(0, 5))
    >>> core.A.shape, core.B.shape, core.sensed_offset
    ((1, 1), (1, 3), 5.0)
    """

    A: np.ndarray
    B: np.ndarray  # n x 3
    C: np.ndarray  # 2 x n
    D: np.ndarray  # 2 x 3
    input_offset: float  # constant added to d_in: (H(0) - 1) u0
    sensed_offset: float  # F(0) y0


def plant_core(plant: Plant, folded_act: list[Block], folded_sen: list[Block], op: OperatingPoint) -> PlantCore:
    """The plant in series with the folded actuator blocks before it and sensor blocks after it.

    Parameters
    ----------
    plant : Plant
        Rational part (its delay is handled by the discretization).
    folded_act, folded_sen : list of Block
        Linear blocks (``Lag``, ``Dynamics``) at the end of the actuator chain and at the start of
        the sensor chain (:func:`fold_counts`).
    op : OperatingPoint

    Returns
    -------
    PlantCore

    Examples
    --------
    >>> from synth.plant import Plant
    >>> from synth.sim.blocks import Lag
    >>> from synth.sim.loops import OperatingPoint
    >>> core = plant_core(Plant.from_string("1/(s+1)"), [Lag(0.1, gain=2.0)], [], OperatingPoint(10, 0))
    >>> core.A.shape[0], core.input_offset  # one state each; (H(0) - 1) u0
    (2, 10.0)
    """
    Aa, Ba, Ca, Da = tf_to_ss(*_series_tf(folded_act))
    Ag, Bg, Cg, Dg = tf_to_ss(plant.num, plant.den)
    Af, Bf, Cf, Df = tf_to_ss(*_series_tf(folded_sen))
    na, ng, nf = Aa.shape[0], Ag.shape[0], Af.shape[0]
    n = na + ng + nf
    A = np.zeros((n, n))
    B = np.zeros((n, 3))
    C = np.zeros((2, n))
    D = np.zeros((2, 3))
    ia, ig, i_f = slice(0, na), slice(na, na + ng), slice(na + ng, n)
    A[ia, ia] = Aa
    A[ig, ia] = np.outer(Bg, Ca)
    A[ig, ig] = Ag
    A[i_f, ia] = np.outer(Bf, Dg * Ca)
    A[i_f, ig] = np.outer(Bf, Cg)
    A[i_f, i_f] = Af
    B[ia, 0] = Ba
    B[ig, 0] = Bg * Da
    B[ig, 1] = Bg
    B[i_f, 0] = Bf * Dg * Da
    B[i_f, 1] = Bf * Dg
    B[i_f, 2] = Bf
    C[0, ia] = Dg * Ca
    C[0, ig] = Cg
    C[1, ia] = Df * Dg * Ca
    C[1, ig] = Df * Cg
    C[1, i_f] = Cf
    D[0] = [Dg * Da, Dg, 1.0]
    D[1] = [Df * Dg * Da, Df * Dg, Df]
    h0 = float(np.prod([b.dc_gain() for b in folded_act])) if folded_act else 1.0
    f0 = float(np.prod([b.dc_gain() for b in folded_sen])) if folded_sen else 1.0
    return PlantCore(A, B, C, D, (h0 - 1.0) * op.input, f0 * op.output)
