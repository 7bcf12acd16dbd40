"""Found by a black-box test (session 53): a closed-loop record whose reference stepped at its first sample (the
loop at rest at zero command, the command 1.22 at once) was diagnosed with an exact model as "68 % gap, drifts up
from 2.48 s, unexplained", without a warning: the model starts at rest at the first command. The residual's
decaying start is now named. Random stable plants; the records simulated by scipy (exact zero-order hold)."""

from __future__ import annotations

import numpy as np
from scipy.signal import cont2discrete, dlsim

from synth.data import record_from_arrays
from synth.gap.where.residual import model_residual
from synth.gap.where.start import start_transient_warning
from synth.plant import Plant


def _case(seed):
    rng = np.random.default_rng(seed)
    poles = -rng.uniform(0.5, 20.0, rng.integers(1, 4))
    den = np.real(np.poly(poles))
    num = np.array([den[-1] * rng.uniform(0.5, 3.0)])
    dt = 1.0 / (20.0 * max(-poles.min(), 1.0))
    slow = 5.0 / -poles.max()
    n = int(np.ceil(12 * slow / dt))
    u, k = np.zeros(n), 0
    while k < n:  # levels held for one to two slowest settling times, never zero at the start
        hold = int(rng.uniform(1.0, 2.0) * slow / dt)
        u[k:k + hold] = rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 1.0)
        k += hold
    numd, dend, _ = cont2discrete((num, den), dt, method="zoh")
    t = np.arange(n) * dt
    noise = 0.01 * np.max(np.abs(u)) * abs(num[0] / den[-1]) * rng.normal(size=n)
    in_motion = dlsim((np.ravel(numd), dend, dt), u)[1].ravel() + noise  # from rest at zero input
    at_rest = dlsim((np.ravel(numd), dend, dt), u - u[0])[1].ravel() + num[0] / den[-1] * u[0] + noise
    return Plant(num, den), t, u, in_motion, at_rest


def test_a_record_in_motion_at_its_start_is_named_and_one_at_rest_is_not():
    for seed in range(30):
        plant, t, u, in_motion, at_rest = _case(seed)
        named = start_transient_warning(plant, model_residual(plant, record_from_arrays(t, u, in_motion)))
        assert named.startswith("the residual in the first") and "--burn-in" in named, seed
        assert start_transient_warning(plant, model_residual(plant, record_from_arrays(t, u, at_rest))) == "", seed


def test_a_record_of_8_to_19_time_constants_is_judged_on_its_first_quarter():
    """A black-box test's record (``2/(2s+1)``, a sum of sines cut 15 s into the run, 40 s long: its five time
    constants, 10 s, were a hair over its quarter) got no warning; it is judged on its first quarter now, as long
    as that holds two time constants. Random plants, records of 8-19 slowest time constants, a sum of sines."""
    for seed in range(20):
        rng = np.random.default_rng(100 + seed)
        poles = -rng.uniform(0.5, 5.0, rng.integers(1, 3))
        den = np.real(np.poly(poles))
        num = np.array([den[-1] * rng.uniform(0.5, 3.0)])
        tau = 1.0 / -poles.max()
        dt = 1.0 / (20.0 * max(-poles.min(), 1.0))
        cut, n = int(rng.uniform(3, 8) * tau / dt), int(rng.uniform(8, 19) * tau / dt)
        w = rng.uniform(0.3, 3.0, 2) / tau
        tt = np.arange(cut + n) * dt
        u_all = np.sin(w[0] * tt) + 0.5 * np.sin(w[1] * tt + 1.0)
        numd, dend, _ = cont2discrete((num, den), dt, method="zoh")
        y_all = dlsim((np.ravel(numd), dend, dt), u_all)[1].ravel()  # from rest at the run's start
        u, y, t = u_all[cut:], y_all[cut:] + 0.002 * rng.normal(size=n), np.arange(n) * dt  # cut out of the run
        plant = Plant(num, den)
        named = start_transient_warning(plant, model_residual(plant, record_from_arrays(t, u, y)))
        assert named.startswith("the residual in the first") and "--burn-in" in named, (seed, n * dt / tau)
        steady = dlsim((np.ravel(numd), dend, dt), u - u[0])[1].ravel() + num[0] / den[-1] * u[0]
        at_rest = steady + 0.002 * rng.normal(size=n)  # the same input, from rest at its first value
        assert start_transient_warning(plant, model_residual(plant, record_from_arrays(t, u, at_rest))) == "", seed
