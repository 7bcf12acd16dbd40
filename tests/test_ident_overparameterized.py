"""A structure with more poles and zeros than the plant has, fitted with a free delay (issue 16, items 1 and 2).

A first-order plant fitted as ``k (s + z)/((s + p1)(s + p2))``: the record pins down the plant's pole and its gain,
while a zero and a pole that cancel can sit anywhere, trading with the delay. IPOPT's Gauss-Newton steps leave
that valley from a start that already fits to the noise (sums of squares up to 25 times the start's), and the
fit was reported as failed ("ended worse than its start", "IPOPT stopped with Maximum_Iterations_Exceeded") on 9
of 32 such records of 2,000 samples (session 47; seeds 8-39 of this generator), after 3-16 s. Levenberg-
Marquardt from the same start now takes over where IPOPT fails: the fit is returned, its cancelling pair and
the delay marked weak. The reference is independent of synth's fit: the truth, and the noise it was drawn with.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.ident import identify

STRUCTURE = "k*(s+z)/((s+p1)*(s+p2))"
SAMPLE_TIME = 0.01
NOISE = 0.02


def first_order_record(seed: int, n: int = 2000) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float]:
    """A random step train (levels in [-1, 1], 1-4 s each, at rest for the first second) through ``K/(T s + 1)``
    held by a zero-order hold (scipy), white noise of std :data:`NOISE`: ``(t, u, y, K, T)``."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * SAMPLE_TIME
    u = np.zeros(n)
    k = 100
    while k < n:
        length = int(rng.integers(100, 400))
        u[k:k + length] = rng.uniform(-1.0, 1.0)
        k += length
    T, K = rng.uniform(0.2, 1.0), rng.uniform(0.5, 3.0)
    num, den, _ = signal.cont2discrete(([K], [T, 1.0]), SAMPLE_TIME, method="zoh")
    y = signal.dlsim((np.ravel(num), den, SAMPLE_TIME), u)[1][:, 0] + NOISE * rng.normal(size=n)
    return t, u, y, K, T


@pytest.mark.parametrize(("seed", "solver"), [(10, "Levenberg-Marquardt"), (11, "Levenberg-Marquardt"),
                                              (15, "Levenberg-Marquardt"), (16, "Levenberg-Marquardt")])
def test_an_overparameterized_fit_with_a_free_delay_is_returned_with_its_cancelling_pair_weak(seed, solver):
    """Seeds 15 and 16 failed before (IPOPT: maximum iterations at 98.06 %; ended worse than its start); seed 10
    with a delay of -0.84 ms (IPOPT's bounded solve at the first sample interval stopped at its iteration limit, the
    unbounded one in the next interval went below 0); Levenberg-Marquardt from the same start took over. Seed 11
    was returned as a result at 29 % fit with a delay of 1.07 s: SRIVC's iteration on the delay grid left a fit
    at the noise for one far off at the true delay 0, so the grid chose 1.5 s; its best iterate is now kept (seed
    10's start is then good enough for IPOPT). IPOPT's fit of seed 10 leaves the pair at -269/-902 with a delay of
    2.4 ms; the pair relocation's refit from the pair at the plant's pole (Levenberg-Marquardt, which crawled to its
    iteration limit against the delay's bound at 0 until its steps kept a variable the bound holds fixed) is kept
    at 31.9 noise variances of SSR lower, with the delay 0."""
    t, u, y, K, T = first_order_record(seed)
    fit = identify((t, u, y), STRUCTURE, delay="fit", average="none").fit
    assert fit.solver["method"].startswith(solver)
    relocated = any(step.get("refit") == "kept: a lower residual" for step in fit.solver.get("pair_profile", []))
    assert solver == "ipopt" or "IPOPT from the same start" in fit.solver["method"] or relocated
    assert relocated or seed != 10
    assert fit.residual_std == pytest.approx(NOISE, rel=0.05)  # fitted to the noise, no further
    assert fit.delay >= 0.0
    # the plant's own pole: one of the two, within 4 of its standard errors of the truth
    own = min(("p1", "p2"), key=lambda p: abs(fit.parameters[p] - 1.0 / T))
    assert abs(fit.parameters[own] - 1.0 / T) <= 4.0 * fit.std[own]
    # the gain the record shows: the step response five of the plant's time constants on (a pair that cancels near
    # the origin, as seed 10's does at 0.0063/0.0067 rad/s, moves the gain at s = 0, which 20 s of record cannot see)
    _, step = signal.step((fit.plant.num, fit.plant.den), T=[0.0, 5.0 * T])
    assert step[-1] == pytest.approx(K * (1.0 - np.exp(-5.0)), rel=0.01)
    # the zero and the other pole cancel: marked weak, never given as confident numbers
    other = "p2" if own == "p1" else "p1"
    assert {w.name for w in fit.weak} >= {"z", other}
