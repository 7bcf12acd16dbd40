"""Controllers that are linear in their parameters: ``C(s) = rho^T phi(s)``.

A :class:`LinearParametrization` maps a vector ``rho`` to a controller and
evaluates the basis ``phi(j w)``; the bounds of the spec become linear
constraints on ``rho``.

========  ==========================================  ============================
type      basis phi(s)                                rho
========  ==========================================  ============================
P         [1]                                         [kp]
PI        [1, 1/s]                                    [kp, ki]
PID       [1, 1/s, s/(tf s + 1)] (tf fixed)           [kp, ki, kd]
leadlag   [s/(s + p), 1/(s + p)] (p fixed)            [k, k z]
========  ==========================================  ============================
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from synth.controllers import Controller
from synth.errors import SynthError


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
    """

    ctype: str
    names: list[str]
    fixed: dict[str, float]
    bounds: dict[str, tuple[float, float]]
    integrator_index: int | None = None
    _extra: dict = field(default_factory=dict, repr=False)

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
            elif self.ctype == "leadlag":
                p = self.fixed["p"]
                cols = [s / (s + p), 1.0 / (s + p)]
            else:  # pragma: no cover - guarded by parametrize()
                raise SynthError(f"no linear parametrization for {self.ctype}")
        return np.stack(cols, axis=-1)

    def dc_basis(self) -> np.ndarray | None:
        """``phi(0)`` when finite (None with an integrator)."""
        if self.integrator_index is not None:
            return None
        return self.basis(np.array([0.0]))[0].real

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
        """Elementwise bounds on ``rho`` implied by the parameter bounds (leadlag: on k only, and kz via k)."""
        lo = np.array([self.bounds[n][0] if n in self.bounds else -np.inf for n in self.names], float)
        hi = np.array([self.bounds[n][1] if n in self.bounds else np.inf for n in self.names], float)
        if self.ctype == "leadlag":
            (k_lo, k_hi), (z_lo, z_hi) = self.bounds["k"], self.bounds["z"]
            corners = [k_lo * z_lo, k_lo * z_hi, k_hi * z_lo, k_hi * z_hi]
            lo = np.array([k_lo, min(corners)])
            hi = np.array([k_hi, max(corners)])
        return lo, hi

    def linear_constraints(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, b)`` with ``A rho <= b`` expressing every bound exactly (linear for lead-lag with k >= 0)."""
        lo, hi = self.box()
        rows, rhs = [], []
        for i in range(self.size):
            e = np.zeros(self.size)
            e[i] = 1.0
            if np.isfinite(hi[i]):
                rows.append(e.copy())
                rhs.append(hi[i])
            if np.isfinite(lo[i]):
                rows.append(-e)
                rhs.append(-lo[i])
        if self.ctype == "leadlag":
            (z_lo, z_hi) = self.bounds["z"]
            rows += [np.array([z_lo, -1.0]), np.array([-z_hi, 1.0])]  # z_lo k <= kz <= z_hi k
            rhs += [0.0, 0.0]
        return np.array(rows), np.array(rhs)

    def start(self) -> np.ndarray:
        """A small, typically stabilizing starting point inside the bounds."""
        lo, hi = self.box()
        x = np.zeros(self.size)
        for i in range(self.size):
            span = hi[i] - lo[i] if np.isfinite(hi[i] - lo[i]) else 1.0
            x[i] = lo[i] + 1e-3 * span if lo[i] >= 0 else (0.0 if hi[i] >= 0 else hi[i])
        if self.ctype == "leadlag":
            (z_lo, z_hi) = self.bounds["z"]
            x[1] = x[0] * 0.5 * (z_lo + z_hi)
        return x


def parametrize(ctype: str, bounds: dict[str, tuple[float, float]]) -> LinearParametrization:
    """The linear parametrization of a controller type given its bounds.

    Parameters fixed by their bounds (``lo == hi``) that the basis needs
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
    raise SynthError(f"no linear parametrization for controller type {ctype}", where="controller.type")
