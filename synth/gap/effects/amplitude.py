"""Amplitude-dependent dynamics: a cubic spring (Duffing type) in feedback around the linear model.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``duffing``            input     ``G`` driven by ``u - cubic y^3 / G(0)``, ``y`` the output   ``cubic``
                                 of the nominal model with the spring (sample by sample)
=====================  ========  ===========================================================  ==============

At rest the output solves ``y + cubic y^3 = G(0) u``: ``cubic`` [1/output^2] is the relative
stiffness added per squared output, positive for a hardening spring (the resonance rises with the
amplitude: 7.32 -> 6.98 Hz falling with amplitude is a softening one, negative). For a Gaussian
output of standard deviation ``s`` the equivalent linear stiffness is ``1 + 3 cubic s^2`` times the
nominal, so a resonance moving from ``f1`` to ``f2`` as ``s`` grows from ``s1`` to ``s2`` means
``cubic ~ ((f2/f1)^2 - 1) / (3 (s2^2 - s1^2))``. Not a default candidate
(:attr:`DuffingEffect.excluded_because`).

The spring's force is computed with the nominal model ``G_0`` the effect is bound to
(:meth:`DuffingEffect.bind`), not with the re-fitted one: the effect is then a fixed block on the
command for every linear model, which the screen can search in milliseconds per point and the joint
fit re-fits without alternating (a re-fit of a few-% mismatch changes the force by as little).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import Effect, Params
from synth.ident.simulate import simulate_plant
from synth.jit import jit
from synth.plant import Plant

__all__ = ["DuffingEffect", "cubic_feedback"]


def cubic_feedback(plant: Plant, u: np.ndarray, dt: float, cubic: float) -> np.ndarray:
    """The input ``w = u - cubic y^3 / G(0)`` that makes ``G w`` a system with a cubic spring.

    Parameters
    ----------
    plant : Plant
        The linear model (a static gain ``G(0)`` that is finite and nonzero).
    u : numpy.ndarray
        Command samples (held), the model at rest at the first one with the spring (``y + cubic y^3 = G(0) u``).
    dt : float
        Sample time [s].
    cubic : float
        Relative cubic stiffness [1/output^2].

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ModelError
        No finite static gain. A spring that diverges (a softening one driven past its turning point)
        has its output clamped at 1000 times the linear scale: finite, and fitting badly.

    Examples
    --------
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> w = cubic_feedback(G, np.full(200, 2.0), 0.01, 0.25)
    >>> y = simulate_plant(G, np.arange(200) * 0.01, w)
    >>> round(float(y[-1] + 0.25 * y[-1] ** 3), 4)  # y + cubic y^3 = G(0) u
    2.0
    """
    from scipy.linalg import expm

    from synth.sim.discretize import tf_to_ss

    num, den = np.asarray(plant.num, float), np.asarray(plant.den, float)
    if den[-1] == 0.0 or num[-1] == 0.0:
        raise ModelError("a cubic spring needs a model with a finite, nonzero static gain", where="plant")
    u = np.asarray(u, float)
    if cubic == 0.0:
        return u
    k0 = float(num[-1] / den[-1])
    A, B, C, _ = tf_to_ss(num, den)  # strictly proper models (a direct term is left out of the loop)
    n = A.shape[0]
    M = expm(np.block([[A, B[:, None]], [np.zeros((1, n + 1))]]) * dt)
    Ad, Bd = M[:n, :n], M[:n, n]
    k = round(plant.delay / dt)
    ud = np.r_[np.full(k, u[0]), u[:u.size - k]] if k > 0 else u
    # at rest at the first command with the spring: y0 + cubic y0^3 = k0 u0 (the real root nearest the linear
    # one), driven by w0 = u0 - cubic y0^3 / k0
    roots = np.roots([cubic, 0.0, 1.0, -k0 * float(ud[0])])
    real = roots[np.abs(roots.imag) <= 1e-9 * (1.0 + np.abs(roots.real))].real
    y_rest = float(min(real, key=lambda r: abs(r - k0 * float(ud[0])))) if real.size else k0 * float(ud[0])
    w_rest = float(ud[0]) - cubic * y_rest**3 / k0
    try:
        x = np.linalg.solve(np.eye(n) - Ad, Bd * w_rest)
    except np.linalg.LinAlgError:
        x = np.zeros(n)
    limit = 1e3 * (1.0 + abs(k0) * float(np.max(np.abs(ud))))
    C = np.ascontiguousarray(C, float)
    w = _spring_inputs(np.ascontiguousarray(ud, float), np.ascontiguousarray(Ad), np.ascontiguousarray(Bd), C,
                       np.ascontiguousarray(C @ Ad), float(C @ Bd), np.array(x, float), cubic / k0, limit)
    return np.r_[w[k:], np.full(k, w[-1])] if k > 0 else w


@jit
def _spring_inputs(ud, Ad, Bd, C, cad, cbd, x, c, limit):
    """The loop of :func:`cubic_feedback`, sample by sample (each input depends on the state the last one left):
    every sum taken in index order, the clamps as Python's ``max(-limit, min(limit, v))``."""
    n = x.size
    w = np.empty(ud.size)
    xs = x.copy()
    nxt = np.empty(n)
    for i in range(ud.size):
        ui = ud[i]
        y0 = 0.0
        a = 0.0
        for j in range(n):
            y0 += C[j] * xs[j]
        for j in range(n):
            a += cad[j] * xs[j]
        y0 = _clamp(y0, limit)  # a diverging spring stays finite (and fits badly)
        wi = ui - c * y0 * y0 * y0
        for _ in range(3):  # the force at the sample's midpoint output: Newton on w = u - c m^3
            m = _clamp(0.5 * (y0 + a + cbd * wi), limit)
            f = wi - ui + c * m * m * m
            wi -= f / (1.0 + 1.5 * c * m * m * cbd)
        w[i] = wi
        for r in range(n):
            s = 0.0
            for j in range(n):
                s += Ad[r, j] * xs[j]
            nxt[r] = s + Bd[r] * wi
        xs[:] = nxt
    return w


@jit
def _clamp(v, limit):
    low = v if v < limit else limit  # min(limit, v)
    return low if low > -limit else -limit  # max(-limit, low)


@dataclass(frozen=True)
class DuffingEffect(Effect):
    """A cubic spring in feedback around the nominal model (:func:`cubic_feedback`): amplitude-dependent stiffness.

    ``cubic`` is searched on a grid of both signs scaled by the nominal model's output amplitude
    ``a`` (``cubic a^2`` from -0.1 to 0.3), refined by a golden-section search when positive.

    Attributes
    ----------
    plant : Plant or None
        The nominal model the spring's force is computed with (:meth:`bind`); ``None``: unbound.

    Examples
    --------
    >>> G = Plant.from_string("400/(s^2+4*s+400)")
    >>> t = np.arange(0, 2, 0.002); u = np.sin(2 * np.pi * 3 * t)
    >>> y = DuffingEffect(G).apply(G, t, u, {"cubic": 0.5})
    >>> round(float(np.max(y)), 3) < round(float(np.max(simulate_plant(G, t, u))), 3)  # stiffer: smaller
    True
    """

    plant: Plant | None = field(default=None, compare=False, repr=False)
    name: ClassVar[str] = "duffing"
    parameter_names: ClassVar[tuple[str, ...]] = ("cubic",)
    grid_names: ClassVar[tuple[str, ...]] = ("cubic",)
    excluded_because: ClassVar[str] = (
        "a structure's or a spring's effect, simulated sample by sample at every search point: name it with "
        "candidates for a record whose amplitude varies")

    def bind(self, records: Any, plant: Plant | None = None) -> DuffingEffect:
        """The effect with its force computed on the nominal model ``plant``."""
        return self if plant is None else replace(self, plant=plant)

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        if float(params.get("cubic", 0.0)) == 0.0:
            return np.asarray(u, float)
        if self.plant is None:
            raise ModelError("the cubic spring needs the nominal model: bind it first", where="effect duffing")
        return cubic_feedback(self.plant, u, dt, float(params.get("cubic", 0.0)))

    def off(self) -> Params:
        return {"cubic": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        a = self.amplitude(t, u, plant)
        return {"cubic": (-0.3 / a**2, 1.0 / a**2)}

    @staticmethod
    def amplitude(t: np.ndarray, u: np.ndarray, plant: Plant) -> float:
        """Largest deviation of the linear model's output from its mean on this command."""
        y = simulate_plant(plant, t, u)
        a = float(np.max(np.abs(y - np.mean(y))))
        if not (np.isfinite(a) and a > 0):
            raise ModelError("the model's output does not move; no cubic spring can be fitted", where="plant")
        return a

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        a2 = self.amplitude(t, u, plant) ** 2
        return [{"cubic": float(c / a2)} for c in (-0.1, -0.03, 0.01, 0.03, 0.1, 0.3)]
