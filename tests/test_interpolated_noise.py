"""The noise factor of an output interpolated from uneven time stamps, against a Monte Carlo of least squares.

Independent of the fit code: white noise drawn at the logged stamps, interpolated by numpy onto the grid that
resampling makes, smooth regressors fitted by ``numpy.linalg.lstsq``; the estimates' variance over 600 draws is
compared with what a white-noise fit on the grid reports (its residual variance times ``(J^T J)^-1``) times the
factor.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.data.interpolated_noise import interpolation_noise_factor


def _stamps(kind: str, rng: np.random.Generator) -> np.ndarray:
    if kind == "jitter":  # 5 ms +- 30 %
        steps = 0.005 * (1 + rng.uniform(-0.3, 0.3, 3000))
    elif kind == "dropouts":  # 2 % of the stamps missing in runs of 2-4
        steps = np.full(3000, 0.005) * (1 + rng.uniform(-0.05, 0.05, 3000))
        for k in rng.choice(3000, 60, replace=False):
            steps[k] *= rng.integers(2, 5)
    else:  # bursts: a short and a long interval
        steps = np.where(rng.random(3000) < 0.5, 0.002, 0.008)
    t = np.concatenate([[0.0], np.cumsum(steps)])
    return t


@pytest.mark.parametrize("kind", ["jitter", "dropouts", "bursts"])
def test_factor_matches_the_variance_of_least_squares_on_interpolated_noise(kind):
    rng = np.random.default_rng({"jitter": 1, "dropouts": 2, "bursts": 3}[kind])
    native = _stamps(kind, rng)
    u = np.where(np.sin(native) > 0, 1.0, 0.0)  # a command, so that the record is one
    record = record_from_arrays(native, u, np.cos(native))
    grid = record.t
    assert record.noise_factor == pytest.approx(interpolation_noise_factor(native, grid))
    span = grid[-1]
    J = np.column_stack([np.ones(grid.size), grid / span, np.sin(2 * np.pi * grid / span), np.exp(-3 * grid / span)])
    inverse = np.linalg.inv(J.T @ J)
    estimates, reported = [], []
    for _ in range(600):
        e = np.interp(grid, native, rng.standard_normal(native.size))
        theta, ssr, *_ = np.linalg.lstsq(J, e, rcond=None)
        estimates.append(theta)
        reported.append(float(ssr[0]) / (grid.size - J.shape[1]) * np.diag(inverse))
    empirical = np.var(np.array(estimates), axis=0)
    white = np.mean(reported, axis=0)
    ratio = empirical / (white * record.noise_factor)
    # 600 draws: each variance to about 6 %; the white-noise report alone is 1.5-2.6 times too small here
    assert np.all(np.abs(ratio - 1) < 0.2), (kind, ratio, record.noise_factor)
    assert np.all(empirical / white > 1.3)
