"""Convex forms of the objectives the convex stage bisects or maximizes directly (peak |S| as the largest
lower bound on ``|1 + L|``; the integral or DC gain of a rational controller at a level)."""

from __future__ import annotations

import numpy as np

from synth.synthesis.convex_bounds import Form, Points
from synth.synthesis.cvxpy_loader import cp
from synth.synthesis.parametrization import Parametrization

__all__ = ["CoefficientRatioFloor", "Level", "ReturnDifferenceFloor"]


class Level:
    """The level an objective form is bisected on (a frequency or a magnitude)."""

    value: float = 1.0


class ReturnDifferenceFloor(Form):
    """``Re{(1 + L) conj(1 + L_c)}/|1 + L_c| >= gamma``: the largest lower bound on ``|1 + L|`` (linear
    parametrizations), maximized to minimize peak |S|."""

    name = "peak sensitivity objective"
    elastic = False

    def __init__(self, points: Points, n_rho: int) -> None:
        self.points = points
        self.R = cp.Parameter((points.n, n_rho))
        self.c = cp.Parameter(points.n)

    def constraints(self, rho, gamma):
        return [self.R @ rho + self.c >= gamma]

    def update(self, rho_c):
        P = self.points.P
        u = P(rho_c)
        mag = np.maximum(np.abs(u), 1e-300)
        self.R.value = np.real(np.conj(u)[:, None] * P.Q) / mag[:, None]
        self.c.value = np.real(np.conj(u) * P.q0) / mag


class CoefficientRatioFloor(Form):
    """``X(0)/D'(0) >= t`` for a rational controller: the integral gain ``b0/a1`` with an integrator
    (``a0 = 0``), else the DC gain ``b0/a0``; linear in ``rho`` for a fixed level ``t``:
    ``b0 - t a_k >= 0``."""

    name = "objective"

    def __init__(self, par: Parametrization, level: Level) -> None:
        self.par, self.level = par, level
        m, n = par.m, par.n
        scale = par.scale()
        self.num = np.zeros(par.size)
        self.num[0] = scale[0]
        k = 1 if par.has_integrator() else 0  # the denominator coefficient the ratio divides by
        self.den = np.zeros(par.size)
        self.den_const = 0.0
        if k < n:
            self.den[m + 1 + k] = scale[m + 1 + k]
        else:
            self.den_const = 1.0  # D = s^n exactly: the ratio is b0 itself
        self.t = cp.Parameter(nonneg=True)

    def constraints(self, rho, slack):
        self._cons = [self.num @ rho - self.t * (self.den @ rho + self.den_const) >= -slack]
        return self._cons

    def update(self, rho_c):
        self.t.value = float(self.level.value)

    def violation(self, rho):
        return float(self.level.value * (self.den @ rho + self.den_const) - self.num @ rho)

    def upper(self) -> float:
        """A level above any value the bounds allow."""
        lo, hi = self.par.box()
        top = float(np.max(np.abs(self.num * np.where(self.num != 0, np.maximum(np.abs(lo), np.abs(hi)), 0))))
        den_lo = float(np.min((self.den * np.where(self.den != 0, np.maximum(lo, 0), 0))[self.den != 0],
                              initial=np.inf)) if np.any(self.den) else self.den_const
        return top / den_lo if den_lo > 0 else top * 1e6
