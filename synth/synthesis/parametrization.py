"""Controller parametrizations in which the loop is affine in a parameter vector ``rho``.

Every parametrization writes the controller as ``C = X/D`` with ``X`` and ``D``
affine in ``rho`` at each frequency, so that with the plant ``G`` the loop is
``L = N/D``, ``N = G X``, and

    S = D/(D + N),  T = N/(D + N),  KS = X/(D + N),  C = X/D.

**Linear in the parameters** (``D = 1``): ``C(s) = rho^T phi(s)``.

========  ==========================================  ============================
type      basis phi(s)                                rho
========  ==========================================  ============================
P         [1]                                         [kp]
PI        [1, 1/s]                                    [kp, ki]
PID       [1, 1/s, s/(tf s + 1)] (tf fixed)           [kp, ki, kd]
leadlag   [s/(s + p), 1/(s + p)] (p fixed)            [k, k z]
========  ==========================================  ============================

**Rational of fixed order** ``[m, n]``: ``X = sum b_i s^i``,
``D = s^n + sum a_i s^i``, with ``rho = (b, a)``. Powers of ``s`` are taken of
``s/w0`` internally (``w0`` a characteristic frequency) so that the numbers
stay of order one; :meth:`RationalParametrization.controller` converts back.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from synth.controllers import RATIONAL, Controller
from synth.errors import SynthError
from synth.freqgrid import characteristic_range
from synth.unity_gain import unity_gain_frequency

if TYPE_CHECKING:
    from synth.spec import Spec

__all__ = ["STRUCTURAL", "Affine", "LinearParametrization", "Parametrization", "RationalParametrization", "parametrize",
           "reference_frequency", "structural_values"]

STRUCTURAL = {"PID": "tf", "leadlag": "p"}


def structural_values(lo: float, hi: float) -> list[float]:
    """The values of a structural parameter (:data:`STRUCTURAL`) the convex stage fixes in turn: the bounds' ends and
    their middle (geometric for positive bounds), or the one fixed value.

    Examples
    --------
    >>> structural_values(0.01, 1.0), structural_values(0.05, 0.05)
    ([0.01, 0.1, 1.0], [0.05])
    """
    if lo == hi:
        return [lo]
    if lo > 0:
        return [float(v) for v in np.geomspace(lo, hi, 3)]
    return [float(v) for v in np.linspace(lo, hi, 3)]
"""The structural parameter of each controller type that the convex stage holds at a few fixed values."""


@dataclass
class Affine:
    """A complex quantity affine in ``rho`` at each frequency point: ``q(rho) = q0 + Q rho``.

    Examples
    --------
    >>> q = Affine(np.array([1.0 + 0j]), np.array([[2.0j]]))
    >>> q(np.array([3.0]))
    array([1.+6.j])
    """

    q0: np.ndarray  # (n,) complex
    Q: np.ndarray  # (n, size) complex

    def __call__(self, rho: np.ndarray) -> np.ndarray:
        # one column at a time, not ``Q @ rho``: a complex matrix-vector product goes to a multithreaded
        # BLAS, whose threads cost milliseconds per call on a busy machine (measured: 4 ms against 10 us)
        rho = np.asarray(rho, dtype=float)
        out = np.array(self.q0, dtype=complex)
        for k in range(rho.size):
            out += self.Q[:, k] * rho[k]
        return out

    def __add__(self, other: Affine) -> Affine:
        return Affine(self.q0 + other.q0, self.Q + other.Q)

    def scaled(self, factor: np.ndarray) -> Affine:
        """Each row multiplied by ``factor`` (shape (n,))."""
        factor = np.asarray(factor)
        return Affine(self.q0 * factor, self.Q * factor[:, None])

    def rows(self, mask: np.ndarray) -> Affine:
        """The rows where ``mask`` is true."""
        return Affine(self.q0[mask], self.Q[mask])

    def is_constant(self) -> bool:
        """True when no row depends on ``rho``."""
        return not np.any(self.Q)


@dataclass
class LinearParametrization:
    """``C(s) = rho^T phi(s)`` for one controller type, with the other parameters fixed.

    Attributes
    ----------
    ctype : str
        Controller type.
    names : list of str
        Names of the entries of ``rho``.
    fixed : dict
        Parameters held fixed (e.g. ``tf`` of a PID, ``p`` of a lead-lag).
    bounds : dict
        ``{name: (lo, hi)}`` of the controller's own parameters.
    integrator_index : int or None
        Entry of ``rho`` multiplying ``1/s``.
    """

    ctype: str
    names: list[str]
    fixed: dict[str, float]
    bounds: dict[str, tuple[float, float]]
    integrator_index: int | None = None

    @property
    def size(self) -> int:
        """Number of entries of ``rho``."""
        return len(self.names)

    def basis(self, w: np.ndarray) -> np.ndarray:
        """``phi(j w)``, shape ``(len(w), size)``.

        Examples
        --------
        >>> par = parametrize("PI", {"kp": (0, 10), "ki": (0, 10)})
        >>> par.basis(np.array([2.0])).round(3)
        array([[1.+0.j , 0.-0.5j]])
        """
        s = 1j * np.asarray(w, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            if self.ctype == "P":
                cols = [np.ones_like(s)]
            elif self.ctype == "PI":
                cols = [np.ones_like(s), 1.0 / s]
            elif self.ctype == "PID":
                tf = self.fixed["tf"]
                cols = [np.ones_like(s), 1.0 / s, s / (tf * s + 1.0)]
            else:  # leadlag
                p = self.fixed["p"]
                cols = [s / (s + p), 1.0 / (s + p)]
        return np.stack(cols, axis=-1)

    def numerator(self, w: np.ndarray) -> Affine:
        """``X = phi^T rho``."""
        return Affine(np.zeros(len(w), complex), self.basis(w))

    def denominator(self, w: np.ndarray) -> Affine:
        """``D = 1``."""
        return Affine(np.ones(len(w), complex), np.zeros((len(w), self.size), complex))

    def dc_ratio(self, rho: np.ndarray) -> float:
        """``C(0)`` (``inf`` with integral action)."""
        if self.integrator_index is not None and rho[self.integrator_index] != 0:
            return np.inf
        phi0 = self.basis(np.array([0.0]))[0]
        finite = np.isfinite(phi0)
        return float(np.real(phi0[finite] @ np.asarray(rho, float)[finite]))

    def has_integrator(self, rho: np.ndarray | None = None) -> bool:
        """Whether the controller has integral action (at ``rho``, or structurally)."""
        if self.integrator_index is None:
            return False
        return rho is None or rho[self.integrator_index] != 0

    def controller(self, rho: np.ndarray) -> Controller:
        """The controller for ``rho``.

        Examples
        --------
        >>> parametrize("leadlag", {"k": (0, 10), "z": (0.1, 10), "p": (20, 20)}).controller([2.0, 4.0])
        Controller(type='leadlag', parameters={'k': 2.0, 'z': 2.0, 'p': 20.0})
        """
        rho = np.asarray(rho, dtype=float)
        if self.ctype == "leadlag":
            k = float(rho[0])
            z = float(rho[1] / k) if k != 0 else float(self.bounds["z"][0])
            return Controller("leadlag", {"k": k, "z": z, "p": self.fixed["p"]})
        values = {n: float(v) for n, v in zip(self.names, rho)}
        return Controller(self.ctype, {**values, **self.fixed})

    def rho(self, controller: Controller) -> np.ndarray:
        """``rho`` of a controller of this type (fixed parameters must agree).

        Examples
        --------
        >>> par = parametrize("leadlag", {"k": (0, 10), "z": (0.1, 10), "p": (20, 20)})
        >>> par.rho(par.controller([2.0, 4.0]))
        array([2., 4.])
        """
        v = controller.parameters
        if self.ctype == "leadlag":
            return np.array([v["k"], v["k"] * v["z"]])
        return np.array([v[n] for n in self.names], dtype=float)

    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """Elementwise bounds on ``rho`` implied by the parameter bounds."""
        lo = np.array([self.bounds[n][0] if n in self.bounds else -np.inf for n in self.names], float)
        hi = np.array([self.bounds[n][1] if n in self.bounds else np.inf for n in self.names], float)
        if self.ctype == "leadlag":
            (k_lo, k_hi), (z_lo, z_hi) = self.bounds["k"], self.bounds["z"]
            corners = [k_lo * z_lo, k_lo * z_hi, k_hi * z_lo, k_hi * z_hi]
            lo = np.array([k_lo, min(corners)])
            hi = np.array([k_hi, max(corners)])
        return lo, hi

    def scale(self) -> np.ndarray:
        """True value = rho * scale: ones (``rho`` holds the parameters themselves, a lead-lag's ``k z`` for ``z``)."""
        return np.ones(self.size)

    def linear_constraints(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, b)`` with ``A rho <= b`` expressing every bound exactly (linear for lead-lag with k >= 0)."""
        A, b = _box_rows(*self.box())
        if self.ctype == "leadlag":
            (z_lo, z_hi) = self.bounds["z"]
            A = np.vstack([A, [z_lo, -1.0], [-z_hi, 1.0]])  # z_lo k <= kz <= z_hi k
            b = np.concatenate([b, [0.0, 0.0]])
        return A, b

    def start(self) -> np.ndarray:
        """A small, typically stabilizing starting point inside the bounds."""
        lo, hi = self.box()
        x = _small_inside(lo, hi)
        if self.ctype == "leadlag":
            (z_lo, z_hi) = self.bounds["z"]
            x[1] = x[0] * 0.5 * (z_lo + z_hi)
        return x

    def random(self, rng: np.random.Generator) -> np.ndarray:
        """A random point in the bounds: by turns spread towards small values, uniform, and log-uniform over
        six decades above the lower bound (an open-loop unstable plant may need a large gain, a high-gain
        plant a tiny one)."""
        lo, hi = self.box()
        lo = np.where(np.isfinite(lo), lo, -10.0)
        hi = np.where(np.isfinite(hi), hi, 10.0)
        u = rng.random(self.size)
        frac = (u**3, u, 10.0 ** (-6.0 * u))[int(rng.integers(3))]
        x = lo + (hi - lo) * frac
        if self.ctype == "leadlag":
            z_lo, z_hi = self.bounds["z"]
            x[1] = x[0] * (z_lo + (z_hi - z_lo) * rng.random())
        return x


@dataclass
class RationalParametrization:
    """``C = X/D``, ``X = sum b_i s^i`` (degree m), ``D = s^n + sum a_i s^i``; ``rho`` holds the
    coefficients of powers of ``s/w0`` (see the module docstring).

    Examples
    --------
    >>> par = RationalParametrization(1, 2, {"b0": (-10, 10), "b1": (-10, 10), "a0": (0, 0), "a1": (0, 50)}, 10.0)
    >>> c = par.controller(par.rho(Controller.from_string("rational(b0=2, b1=1, a0=0, a1=10)")))
    >>> c.parameters
    {'b0': 2.0, 'b1': 1.0, 'a0': 0.0, 'a1': 10.0}
    """

    m: int
    n: int
    bounds: dict[str, tuple[float, float]]
    w0: float = 1.0

    ctype = RATIONAL

    @property
    def names(self) -> list[str]:
        return [f"b{i}" for i in range(self.m + 1)] + [f"a{i}" for i in range(self.n)]

    @property
    def size(self) -> int:
        return self.m + 1 + self.n

    def scale(self) -> np.ndarray:
        """True coefficient = rho * scale (b_i and a_i both scale with w0^(n - i))."""
        return np.array([self.w0 ** (self.n - i) for i in range(self.m + 1)]
                        + [self.w0 ** (self.n - i) for i in range(self.n)])

    def _powers(self, w: np.ndarray, count: int) -> np.ndarray:
        x = 1j * np.asarray(w, dtype=float) / self.w0
        return np.stack([x**i for i in range(count)], axis=-1)

    def numerator(self, w: np.ndarray) -> Affine:
        Q = np.zeros((len(w), self.size), complex)
        Q[:, : self.m + 1] = self._powers(w, self.m + 1)
        return Affine(np.zeros(len(w), complex), Q)

    def denominator(self, w: np.ndarray) -> Affine:
        Q = np.zeros((len(w), self.size), complex)
        Q[:, self.m + 1:] = self._powers(w, self.n)
        return Affine((1j * np.asarray(w, float) / self.w0) ** self.n, Q)

    def dc_ratio(self, rho: np.ndarray) -> float:
        a0 = rho[self.m + 1]
        return np.inf if a0 == 0 else float(rho[0] / a0)

    def has_integrator(self, rho: np.ndarray | None = None) -> bool:
        lo, hi = self.bounds["a0"]
        if rho is None:
            return lo == hi == 0.0
        return rho[self.m + 1] == 0.0

    def controller(self, rho: np.ndarray) -> Controller:
        true = np.asarray(rho, float) * self.scale()
        return Controller(RATIONAL, {name: float(v) for name, v in zip(self.names, true)})

    def rho(self, controller: Controller) -> np.ndarray:
        return np.array([controller.parameters[n] for n in self.names], float) / self.scale()

    def box(self) -> tuple[np.ndarray, np.ndarray]:
        scale = self.scale()
        lo = np.array([self.bounds[n][0] for n in self.names]) / scale
        hi = np.array([self.bounds[n][1] for n in self.names]) / scale
        return lo, hi

    def linear_constraints(self) -> tuple[np.ndarray, np.ndarray]:
        return _box_rows(*self.box())

    def start(self) -> np.ndarray:
        """A small controller with a stable denominator: ``D = (s/w0 + 1)^n`` (or ``s (s/w0 + 1)^(n-1)``
        with an integrator), ``X`` small."""
        lo, hi = self.box()
        poly = np.poly1d([1.0, 1.0]) ** self.n
        a = poly.coeffs[::-1][: self.n].astype(float)
        if self.has_integrator():
            integ = np.poly1d([1.0, 0.0]) * np.poly1d([1.0, 1.0]) ** (self.n - 1)
            a = integ.coeffs[::-1][: self.n].astype(float)
        b = np.zeros(self.m + 1)
        b[0] = 1e-3
        x = np.concatenate([b, a])
        return np.clip(x, lo, hi)

    def random(self, rng: np.random.Generator) -> np.ndarray:
        """A random controller in the bounds: stable real poles spread over three decades around ``w0``
        (one at the origin with an integrator), numerator coefficients of random sign over six decades."""
        x = self.start()
        poles = 10 ** rng.uniform(-1.0, 2.0, self.n)
        if self.has_integrator():
            poles[0] = 0.0
        x[self.m + 1:] = np.poly(-poles)[::-1][: self.n]
        x[: self.m + 1] = rng.normal(size=self.m + 1) * 10 ** rng.uniform(-3, 3)
        lo, hi = self.box()
        return np.clip(x, lo, hi)


def _box_rows(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    rows, rhs = [], []
    for i in range(lo.size):
        e = np.zeros(lo.size)
        e[i] = 1.0
        if np.isfinite(hi[i]):
            rows.append(e.copy())
            rhs.append(hi[i])
        if np.isfinite(lo[i]):
            rows.append(-e)
            rhs.append(-lo[i])
    return np.array(rows).reshape(-1, lo.size), np.array(rhs)


def _small_inside(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    x = np.zeros(lo.size)
    for i in range(lo.size):
        span = hi[i] - lo[i] if np.isfinite(hi[i] - lo[i]) else 1.0
        x[i] = lo[i] + 1e-3 * span if lo[i] >= 0 else (0.0 if hi[i] >= 0 else hi[i])
    return x


Parametrization = LinearParametrization | RationalParametrization


def parametrize(ctype: str, bounds: dict[str, tuple[float, float]], order: tuple[int, int] | None = None,
                w0: float = 1.0) -> Parametrization:
    """The parametrization of a controller type given its bounds.

    Parameters fixed by their bounds (``lo == hi``) that the linear basis needs
    (``tf`` of a PID, ``p`` of a lead-lag) must be fixed; free ones raise
    :class:`SynthError` (the NLP stage handles them).

    Examples
    --------
    >>> parametrize("PID", {"kp": (0, 5), "ki": (0, 5), "kd": (0, 1), "tf": (0.01, 0.01)}).names
    ['kp', 'ki', 'kd']
    """
    bounds = {k: (float(a), float(b)) for k, (a, b) in bounds.items()}
    if ctype == "P":
        return LinearParametrization("P", ["kp"], {}, bounds)
    if ctype == "PI":
        return LinearParametrization("PI", ["kp", "ki"], {}, bounds, integrator_index=1)
    if ctype == "PID":
        lo, hi = bounds["tf"]
        if lo != hi:
            raise SynthError("PID is linear in kp, ki, kd only with the filter tf fixed (bounds lo == hi)",
                             where="controller.bounds.tf")
        return LinearParametrization("PID", ["kp", "ki", "kd"], {"tf": lo}, bounds, integrator_index=1)
    if ctype == "leadlag":
        lo, hi = bounds["p"]
        if lo != hi:
            raise SynthError("lead-lag is linear in (k, k z) only with the pole p fixed (bounds lo == hi)",
                             where="controller.bounds.p")
        if bounds["k"][0] < 0:
            raise SynthError("lead-lag synthesis needs k >= 0 (bounds on z become linear in (k, k z))",
                             where="controller.bounds.k")
        return LinearParametrization("leadlag", ["k", "kz"], {"p": lo}, bounds)
    if ctype == RATIONAL:
        if order is None:
            raise SynthError("a rational controller needs its order", where="controller.order")
        return RationalParametrization(order[0], order[1], bounds, w0)
    raise SynthError(f"no parametrization for controller type {ctype}", where="controller.type")


def reference_frequency(spec: Spec) -> float:
    """Geometric mean of the nominal plant's corner frequencies (scales rational coefficients). A plant without
    corners, ``k s^r`` (an integrator, a pure gain), has the frequency where its gain is 1 instead, at most
    ``1 / delay``: where a loop around it crosses over. (``1 / delay`` alone put the scale of ``4.59 e^(-0.00023 s)
    / s`` at 4,300 rad/s, three decades above any loop the bounds allow; a rational controller's ``b0`` then
    ranged over +-3e-8 in the convex stage's units, below the solver's tolerance, and the design answered
    "infeasible" where the design benchmark's reference met every requirement: seed 19 #35.)

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = parse_spec({"name": "x", "plant": {"tf": "1/((s+1)*(s+100))"}, "controller": {"type": "P"},
    ...                    "requirements": [{"type": "bandwidth", "min": 1.0}]})
    >>> 1.0 < reference_frequency(spec) < 100.0
    True
    >>> spec = parse_spec({"name": "x", "plant": {"tf": "4/s^2", "delay": 0.01}, "controller": {"type": "P"},
    ...                    "requirements": [{"type": "bandwidth", "min": 1.0}]})
    >>> round(reference_frequency(spec), 6)
    2.0
    """
    p = spec.nominal_plant()
    unity = unity_gain_frequency(p.num, p.den)
    if unity is not None:
        return min(unity, 1.0 / p.delay) if p.delay > 0 else unity
    lo, hi = characteristic_range(p.num, p.den, delay=p.delay)
    return float(np.sqrt(lo * hi))
