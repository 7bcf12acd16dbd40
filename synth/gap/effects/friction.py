"""Coulomb friction of a drive, with sticking, on the model's own velocity.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``friction``           input     Coulomb force ``-fc sign(velocity)``, stick-slip; ``G`` to     ``fc``
                                 a position (pole at the origin) or a velocity
=====================  ========  ===========================================================  ==============

Not a default candidate (:attr:`FrictionEffect.excluded_because` says why).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import Effect, Params, log_grid
from synth.plant import Plant

__all__ = ["FrictionEffect", "coulomb_force", "velocity_model"]


@dataclass(frozen=True)
class FrictionEffect(Effect):
    """Coulomb friction of a drive: the force ``fc`` [input units] against the motion, with sticking.

    The linear model ``G`` (output a position if ``G`` has a pole at the
    origin, else a velocity) is driven by ``u + f``, ``f = -fc sign(v)`` while
    the model's own velocity ``v`` (``s G`` or ``G``, simulated sample by sample) is
    nonzero; at rest the drive sticks while ``|u| <= fc`` (``f = -u``) and
    breaks away with ``f = -fc sign(u)`` otherwise; a velocity that changes
    sign within a sample stops there. The viscous part stays in ``G``. Exact
    for a first-order velocity model (mass and viscous friction,
    ``G = b/(s (s + a))``); for higher orders, stopping resets the velocity
    model's state. A delay of ``G`` acts on the command before the friction
    (whole samples). ``fc`` times the drive gain is the Coulomb force.

    A dead zone on the command is the same only while the force and the
    velocity have the same sign (steady motion); when a drive brakes they do
    not, and the dead zone then pushes where friction holds back.

    Examples
    --------
    >>> import numpy as np
    >>> G = Plant.from_string("1/(s*(s+1))")  # unit mass, unit viscous friction
    >>> t = np.arange(0, 6, 0.01); u = np.where((t >= 0.5) & (t < 3), 1.5, 0.0)
    >>> v = np.gradient(FrictionEffect().apply(G, t, u, {"fc": 1.0}), t)
    >>> round(float(v[290]), 3), round(abs(float(v[-1])), 3)  # 1.5 - 1 drives it; friction stops it after the push
    (0.455, 0.0)
    """

    name: ClassVar[str] = "friction"
    parameter_names: ClassVar[tuple[str, ...]] = ("fc",)
    grid_names: ClassVar[tuple[str, ...]] = ("fc",)
    needs_plant: ClassVar[bool] = True
    excluded_because: ClassVar[str] = (
        "a model of a drive: the plant must have its output a position (one pole at the origin) or a velocity, "
        "and the force depends on the model's own velocity, so the screen cannot fit it and every diagnosis "
        "would pay one more joint re-fit; name it with candidates for a drive")

    def off(self) -> Params:
        return {"fc": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"fc": (0.0, float(np.max(np.abs(u))))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        top = float(np.max(np.abs(u)))
        if top <= 0:
            raise ModelError("the input is zero; no friction can be fitted", where="record.u")
        return log_grid(0.01 * top, 0.5 * top, 8, "fc")

    def base_input(self, plant: Plant, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        fc = float(params.get("fc", 0.0))
        if fc <= 0:
            return u
        return u + coulomb_force(plant, u, dt, fc)


def velocity_model(plant: Plant) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of the velocity model: ``s G`` for a position output, else ``G``.

    Raises
    ------
    ModelError
        More than one pole at the origin, or ``s G`` not strictly proper.

    Examples
    --------
    >>> [a.tolist() for a in velocity_model(Plant.from_string("2/(s*(s+1))"))]
    [[2.0], [1.0, 1.0]]
    """
    den = np.asarray(plant.den, float)
    if den[-1] == 0.0:
        den = den[:-1]
        if den.size < 2 or den[-1] == 0.0:
            raise ModelError("friction needs a drive with at most one pole at the origin", where="plant")
    num = np.asarray(plant.num, float)
    if num.size >= den.size:
        raise ModelError("friction needs a strictly proper velocity model s*G", where="plant")
    return num, den


def coulomb_force(plant: Plant, u: np.ndarray, dt: float, fc: float) -> np.ndarray:
    """Friction term ``f`` (input units) that makes ``G (u + f)`` a drive with Coulomb friction ``fc``.

    Parameters
    ----------
    plant : Plant
        Position model (one pole at the origin) or velocity model of the drive.
    u : numpy.ndarray
        Command samples (held), the drive at rest before the first one.
    dt : float
        Sample time [s].
    fc : float
        Coulomb friction in input units.

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> import numpy as np
    >>> coulomb_force(Plant.from_string("1/(s*(s+1))"), np.array([0.5, 2.0, 2.0, -0.5]), 0.1, 1.0).round(3).tolist()
    [-0.5, -1.0, -1.0, -1.0]
    """
    from scipy.linalg import expm

    from synth.sim.discretize import tf_to_ss

    num, den = velocity_model(plant)
    A, B, C, _D = tf_to_ss(num, den)
    n = A.shape[0]
    M = expm(np.block([[A, B[:, None]], [np.zeros((1, n + 1))]]) * dt)
    Ad, Bd = M[:n, :n], M[:n, n]
    u = np.asarray(u, float)
    k = round(plant.delay / dt)
    ud = np.r_[np.full(k, 0.0), u[:u.size - k]] if k > 0 else u
    w = np.empty_like(ud)
    x = np.zeros(n)
    stuck = True
    for i in range(ud.size):
        ui = ud[i]
        if stuck:
            if abs(ui) <= fc:
                w[i] = 0.0
                continue
            w[i] = ui - fc * np.sign(ui)
            stuck = False
            direction = np.sign(ui)
        else:
            w[i] = ui - fc * direction
        x = Ad @ x + Bd * w[i]
        v = float(C @ x)
        if v * direction <= 0.0:  # the velocity reached zero within the sample: stop there
            x = np.zeros(n)
            stuck = True
    f = w - ud
    return np.r_[f[k:], np.full(k, f[-1])] if k > 0 else f
