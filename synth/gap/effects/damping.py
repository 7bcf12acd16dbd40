"""Amplitude-dependent damping: a quadratic (drag-type) damping force in feedback around the linear model.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``amplitude_damping``  input     ``G`` driven by ``u - drag y' |y'| / G(0)``, ``y'`` the      ``drag``
                                 output rate of the nominal model with the force
=====================  ========  ===========================================================  ==============

A force against the output's rate that grows with it (air or fluid drag, a structural joint whose
losses grow with the stroke): the damping, and with it the gain at a resonance and the speed of a
large step, depend on the amplitude. For a mode ``G(0) wn^2 / (s^2 + 2 zeta wn s + wn^2)`` moving
sinusoidally at ``wn`` with amplitude ``Y`` the equivalent damping ratio is
``zeta + 4 drag wn^2 Y / (3 pi)`` (the describing function of ``v |v|`` is ``8 V / (3 pi)``), so the
resonance peak falls as ``1 / (2 zeta_eq)`` with the amplitude; a first-order model slows on large
steps (its time constant grows with the rate). ``drag`` [s^2 / output] is positive for damping that
grows with the amplitude; a small negative value (damping that falls with it) is searched too.
Not a default candidate (:attr:`AmplitudeDampingEffect.excluded_because`).

As for the cubic spring (:mod:`synth.gap.effects.amplitude`), the force is computed with the nominal
model the effect is bound to (:meth:`AmplitudeDampingEffect.bind`): a fixed block on the command for
every re-fitted linear model.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import Effect, Params
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["AmplitudeDampingEffect", "drag_feedback"]


def drag_feedback(plant: Plant, u: np.ndarray, dt: float, drag: float) -> np.ndarray:
    """The input ``w = u - drag v |v| / G(0)`` that makes ``G w`` a system with quadratic damping.

    ``v`` is the output's rate over each sample, ``(y[k+1] - y[k]) / dt``, which depends on ``w[k]``
    itself: the implicit equation is solved exactly per sample (a quadratic in ``|v|``).

    Parameters
    ----------
    plant : Plant
        The linear model (a static gain ``G(0)`` that is finite and nonzero).
    u : numpy.ndarray
        Command samples (held), the model at rest at the first one's linear steady state.
    dt : float
        Sample time [s].
    drag : float
        Quadratic damping coefficient [s^2 / output].

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ModelError
        No finite, nonzero static gain.

    Examples
    --------
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> u = np.r_[np.zeros(10), np.ones(90)]
    >>> w = drag_feedback(G, u, 0.01, 0.01)
    >>> y, y0 = simulate_plant(G, np.arange(100) * 0.01, w), simulate_plant(G, np.arange(100) * 0.01, u)
    >>> bool(y[15] < y0[15]), round(float(y[-1]), 3)  # slower while it moves, the same at rest
    (True, 1.0)
    """
    from scipy.linalg import expm

    from synth.sim.discretize import tf_to_ss

    num, den = np.asarray(plant.num, float), np.asarray(plant.den, float)
    if den[-1] == 0.0 or num[-1] == 0.0:
        raise ModelError("a damping force needs a model with a finite, nonzero static gain", where="plant")
    u = np.asarray(u, float)
    if drag == 0.0:
        return u
    k0 = float(num[-1] / den[-1])
    A, B, C, _ = tf_to_ss(num, den)
    n = A.shape[0]
    M = expm(np.block([[A, B[:, None]], [np.zeros((1, n + 1))]]) * dt)
    Ad, Bd = M[:n, :n], M[:n, n]
    k = round(plant.delay / dt)
    ud = np.r_[np.full(k, u[0]), u[:u.size - k]] if k > 0 else u
    try:
        x = np.linalg.solve(np.eye(n) - Ad, Bd * ud[0])
    except np.linalg.LinAlgError:
        x = np.zeros(n)
    c = drag / k0
    rate_a = ((C @ Ad - C) / dt).tolist()  # v = rate_a . x + rate_b w
    rate_b = float(C @ Bd) / dt
    q = c * rate_b
    limit = 1e3 * (1.0 + abs(k0) * float(np.max(np.abs(ud)))) / dt
    Adl, Bdl = Ad.tolist(), Bd.tolist()
    xs = x.tolist()
    w = np.empty_like(ud)
    for i in range(ud.size):
        ui = float(ud[i])
        r = sum(a * xi for a, xi in zip(rate_a, xs)) + rate_b * ui  # the rate without the force
        r = max(-limit, min(limit, r))
        if q > 0.0:  # v + q v |v| = r: sign(v) = sign(r), |v| the positive root
            v = np.sign(r) * 2.0 * abs(r) / (1.0 + np.sqrt(1.0 + 4.0 * q * abs(r)))
        else:  # a force that would feed the rate back positively: explicit in the force-free rate
            v = r
        wi = ui - c * v * abs(v)
        w[i] = wi
        xs = [sum(p * xj for p, xj in zip(row, xs)) + b * wi for row, b in zip(Adl, Bdl)]
    return np.r_[w[k:], np.full(k, w[-1])] if k > 0 else w


@dataclass(frozen=True)
class AmplitudeDampingEffect(Effect):
    """Quadratic damping in feedback around the nominal model (:func:`drag_feedback`): amplitude-dependent damping.

    ``drag`` is searched on a grid of both signs scaled so that the force at the nominal model's
    fastest output rate ``v`` is a fraction of its output amplitude ``a`` (``drag v^2 / a`` from
    -0.03 to 1), refined by a golden-section search when positive.

    Attributes
    ----------
    plant : Plant or None
        The nominal model the force is computed with (:meth:`bind`); ``None``: unbound.

    Examples
    --------
    >>> G = Plant.from_string("400/(s^2+4*s+400)")
    >>> t = np.arange(0, 4, 0.002); u = np.sin(2 * np.pi * 3.18 * t)  # at the resonance
    >>> y0 = simulate_plant(G, t, u)
    >>> y = AmplitudeDampingEffect(G).apply(G, t, u, {"drag": 0.002})
    >>> bool(np.max(np.abs(y[1000:])) < 0.8 * np.max(np.abs(y0[1000:])))  # a lower resonance peak
    True
    """

    plant: Plant | None = field(default=None, compare=False, repr=False)
    name: ClassVar[str] = "amplitude_damping"
    parameter_names: ClassVar[tuple[str, ...]] = ("drag",)
    grid_names: ClassVar[tuple[str, ...]] = ("drag",)
    excluded_because: ClassVar[str] = (
        "a structure's or a drive's effect, simulated sample by sample at every search point: name it with "
        "candidates for a record whose amplitude varies")

    def bind(self, records: Any, plant: Plant | None = None) -> AmplitudeDampingEffect:
        """The effect with its force computed on the nominal model ``plant``."""
        return self if plant is None else replace(self, plant=plant)

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        drag = float(params.get("drag", 0.0))
        if drag == 0.0:
            return np.asarray(u, float)
        if self.plant is None:
            raise ModelError("the damping force needs the nominal model: bind it first",
                             where="effect amplitude_damping")
        return drag_feedback(self.plant, u, dt, drag)

    def off(self) -> Params:
        return {"drag": 0.0}

    @staticmethod
    def scales(t: np.ndarray, u: np.ndarray, plant: Plant) -> tuple[float, float]:
        """Output amplitude ``a`` (largest deviation from the mean) and fastest output rate ``v`` of the
        linear model on this command.

        Examples
        --------
        >>> t = np.arange(0, 2, 0.01); u = (t >= 0.5).astype(float)
        >>> a, v = AmplitudeDampingEffect.scales(t, u, Plant.from_string("1/(0.1*s+1)"))
        >>> round(a, 2), round(v, 1)  # a unit step: rate 1/tau over the first sample
        (0.7, 9.5)
        """
        y = simulate_plant(plant, t, u)
        a = float(np.max(np.abs(y - np.mean(y))))
        v = float(np.max(np.abs(np.diff(y)))) / float(t[1] - t[0])
        if not (np.isfinite(a) and a > 0 and np.isfinite(v) and v > 0):
            raise ModelError("the model's output does not move; no damping force can be fitted", where="plant")
        return a, v

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        a, v = self.scales(t, u, plant)
        return {"drag": (-0.1 * a / v**2, 3.0 * a / v**2)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        a, v = self.scales(t, u, plant)
        return [{"drag": float(f * a / v**2)} for f in (-0.03, 0.01, 0.03, 0.1, 0.3, 1.0)]
