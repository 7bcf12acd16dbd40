"""Levenberg-Marquardt on the convolution path with a bound that holds at the optimum (``synth.ident.convolution_problem``).

A plant with a little lead (a zero well above its pole) fitted as ``K/(T*s+1)`` with a fitted delay: the best delay
is below 0, so the fit ends with the delay at its bound 0. The steps clipped at the bound used to move the other
parameters for a delay move the bound then refused; the fit crawled to its iteration limit (125-1,000 iterations,
1-121 s, SSR 0.04-74 % above the optimum on records of 2,000-30,000 samples). The steps now leave a parameter the
bound holds where it is. Judged against an independent reference (the model of
``benchmarks/ident_delay_at_bound.py``, written from the model's definition with scipy only: the record's exact
sampled model, zero-order hold and the delay's fraction of a sample, by ``scipy.signal.lfilter``), fitted by
``scipy.optimize.least_squares`` with the same bound.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize

from benchmarks.ident_delay_at_bound import model
from synth.data import record_from_arrays
from synth.ident.simulate import simulate_plant
from synth.ident.timefit import fit_structure
from synth.plant import Plant


def _record(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float]:
    """A square wave of random half-period through ``2 (lead s + 1)/(T s + 1)``, 1 % noise: ``(t, u, y, dt, T)``."""
    rng = np.random.default_rng(seed)
    T = rng.uniform(0.05, 1.0)
    lead = rng.uniform(0.05, 0.3) * T
    n, dt = int(rng.choice([2000, 4000, 6000])), float(rng.choice([0.001, 0.005]))
    t = np.arange(n) * dt
    hold = max(5, int(rng.uniform(0.5, 2.0) * T / dt))
    u = ((np.arange(n) // hold) % 2).astype(float)
    y = simulate_plant(Plant.from_string(f"2*({lead}*s+1)/({T}*s+1)"), t, u) + 0.01 * rng.normal(size=n)
    return t, u, y, dt, T


@pytest.mark.parametrize("seed", [0, 1, 3, 8])
def test_a_delay_held_at_its_bound_converges_to_the_bounded_optimum(seed: int) -> None:
    t, u, y, dt, T = _record(seed)
    fit = fit_structure(record_from_arrays(t, u, y), "K/(T*s+1)", "fit", solver="convolution")
    assert fit.solver["status"] == "Solve_Succeeded" and fit.solver["iterations"] <= 25, fit.solver
    assert fit.delay == 0.0
    ref = _reference(t, u, y, dt, T)
    ssr_fit, ssr_ref = float(np.sum((y - fit.yhat) ** 2)), 2.0 * float(ref.cost)
    assert ssr_fit <= ssr_ref * (1.0 + 1e-9)  # at the bounded optimum (before: 0.04-0.7 % above it)
    assert ssr_ref <= ssr_fit * (1.0 + 1e-6)
    for name, value in zip(("K", "T"), ref.x[:2]):
        assert abs(fit.parameters[name] - value) <= 0.01 * fit.std[name], name


@pytest.mark.parametrize("seed", [9, 16])
def test_ipopt_at_its_limit_on_the_bound_gives_way_to_the_converged_fit_there(seed: int) -> None:
    """On records of 2,000-6,000 samples IPOPT fits first; with the delay's bound at 0 active it can run its 300
    iterations at the optimum, its SSR taken 1e-8 past the bound (IPOPT's relaxation) and so a hair below what any
    delay of 0 or more gives. Levenberg-Marquardt from the same start converges there; its answer was refused for
    not being lower, and the fit went on to four restarts (or ended at the limit). It is kept now. (Seed 6 ran into
    the limit until session 74 made SRIVC's filters exact; from that start IPOPT converges, at the same optimum.)"""
    t, u, y, dt, T = _record(seed)
    fit = fit_structure(record_from_arrays(t, u, y), "K/(T*s+1)", "fit")
    assert "IPOPT from the same start: Maximum_Iterations_Exceeded" in fit.solver["method"]
    assert fit.solver["status"] == "Solve_Succeeded" and fit.solver["starts"] == 2, fit.solver
    ref = _reference(t, u, y, dt, T)
    assert float(np.sum((y - fit.yhat) ** 2)) <= 2.0 * float(ref.cost) * (1.0 + 1e-9)


def _reference(t: np.ndarray, u: np.ndarray, y: np.ndarray, dt: float, T: float) -> optimize.OptimizeResult:
    """The bounded optimum by scipy, from the truth's gain and time constant."""
    w = u - u[0]
    ref = optimize.least_squares(lambda x: y - model(1, x, w, dt), x0=[2.0, T, 0.5 * dt, 0.0],
                                 bounds=([-np.inf, 1e-6, 0.0, -np.inf], np.inf), x_scale=[1.0, T, dt, 1.0],
                                 xtol=1e-12, ftol=1e-14, gtol=1e-12)
    assert ref.success and ref.x[2] == pytest.approx(0.0, abs=1e-9)  # the reference holds the delay at 0 too
    return ref


def test_the_gain_left_to_a_stopped_fit_is_measured_with_the_bound_held() -> None:
    """``remaining_improvement`` judges a fit stopped at its limit (and a start kept as converged) by the SSR a
    Gauss-Newton step still gains. With the delay at its bound the full step asks the delay to go below 0 and moves
    the others to match; clipped, that step gained nothing, and a fit 1.8 standard errors from its bounded optimum
    passed as converged (the benchmark's "the start kept" 3 % of SSR above it). Here ``y = 33 t - 10 t^2`` fitted as
    ``a t + f t^2`` with ``f`` the bounded delay slot, stopped at ``a = f = 0``: the full step is ``(33, -10)``, the
    bounded optimum ``f = 0, a = sum(t y)/sum(t^2) = -1/3``, a gain of ``sqrt((sum t y)^2/sum t^2)`` standard errors
    at ``s^2 = 1``."""
    from synth.ident.fit_failure import remaining_improvement

    class Toy:
        p, scale = 1, np.array([1.0])

        def yhat_fn(self, xs: np.ndarray, par: np.ndarray) -> np.ndarray:
            return xs[0] * par + xs[1] * par ** 2

    t = np.arange(5.0)
    y = 33.0 * t - 10.0 * t ** 2
    J = np.column_stack([t, t ** 2])
    gain = remaining_improvement(Toy(), np.zeros(2), t, J, y, J.T @ J, np.ones(2), 1.0, None, y, None, True, 10.0)
    assert gain == pytest.approx(np.sqrt(float(t @ y) ** 2 / float(t @ t)), rel=1e-9)  # 1.826; 0 before
