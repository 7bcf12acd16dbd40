"""Found by a black-box test (session 53): a PI loop whose integrator winds up drives the command past both limits
of an actuator's range, unevenly. The saturation fit moved one limit at a time and ended at a one-sided clip plus
a bias (lower -inf, upper 2.31 against the truth's +-0.9, training error 250 times the noise), and the verdict
named a static nonlinearity instead. Both limits are now also searched together. Random plants, PI gains and
limits; the loop simulated by scipy (exact zero-order hold) with a digital PI, not by synth."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.gap.attribution.refit import fit_augmented
from synth.gap.diagnose import diagnose
from synth.gap.effects import make_effect
from synth.plant import Plant
from tests.pi_loop import digital_pi_loop

DT, N = 0.005, 6000


def _loop(seed):
    """A random second-order plant under a digital PI with a wound-up integrator behind limits [lower, upper]."""
    rng = np.random.default_rng(seed)
    p1, p2, gain = rng.uniform(0.5, 3.0), rng.uniform(4.0, 12.0), rng.uniform(1.0, 5.0)
    num, den = [gain * p1 * p2], np.polymul([1, p1], [1, p2])
    lower, upper = -rng.uniform(0.5, 1.0), rng.uniform(0.5, 1.0)
    r, k = np.zeros(N), 200
    while k < N:
        hold = int(rng.uniform(1.0, 2.5) / DT)
        r[k:k + hold] = rng.uniform(-1.2, 1.2) * gain
        k += hold
    kp, ki = rng.uniform(0.5, 1.5) / gain, rng.uniform(2.0, 5.0) / gain
    noise = rng.normal(0, 0.005 * gain, N)
    u, y = digital_pi_loop(num, den, kp, ki, r, noise, DT, lower, upper)
    return Plant(np.array(num, float), den), np.arange(N) * DT, u, y, lower, upper


@pytest.mark.slow
def test_both_limits_of_a_wound_up_loop_are_found_within_3_percent():
    for seed in (0, 2, 3):  # of seeds 0-9 (all pass), three whose grid fits are cheap: 1 and 4 take 11-17 s
        plant, t, u, y, lower, upper = _loop(seed)
        m = N // 2
        assert np.mean(u[:m] > upper) > 0.05 and np.mean(u[:m] < lower) > 0.05, seed  # both clip in training
        fit = fit_augmented(plant, t[:m], u[:m], y[:m], make_effect("saturation"))
        assert abs(fit.params["lower"] - lower) < 0.03 * abs(lower), (seed, fit.params, lower)
        assert abs(fit.params["upper"] - upper) < 0.03 * upper, (seed, fit.params, upper)
        lo_ci, hi_ci = fit.parameter_ci["upper"]
        assert lo_ci <= fit.params["upper"] <= hi_ci


def test_the_verdict_is_the_saturation_not_a_static_nonlinearity():
    plant, t, u, y, lower, upper = _loop(4)  # the upper limit clipped 60 % of training, the lower 10 %
    d = diagnose(plant, record_from_arrays(t, u, y), candidates=["saturation", "static_nonlinearity"], n_boot=200)
    assert d.verdict["effects"] == ["saturation"], d.summary
    found = next(e for e in d.attribution.effects if e.effect == "saturation").parameters
    assert abs(found["lower"] - lower) < 0.03 * abs(lower) and abs(found["upper"] - upper) < 0.03 * upper
