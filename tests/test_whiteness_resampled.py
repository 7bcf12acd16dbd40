"""A record logged at jittered time stamps is interpolated onto a uniform grid, which alone correlates white
noise between neighbouring grid samples (session 62's black-box test: every such fit carried the note "the
residuals are correlated ... the stds may be several times too small" although its stds matched the scatter).
The whiteness test now looks for correlation beyond what the interpolation gives; coloured noise is still named.

References written here, apart from the code under test: the interpolation's correlation by Monte Carlo
(``np.interp`` of white noise), the records by scipy's ``lsim`` on a fine grid read at the logged stamps.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.data.interpolated_noise import interpolation_noise_correlation
from synth.ident import identify


def _stamps(rng: np.random.Generator, dt: float, jitter: float, duration: float, dropout: bool) -> np.ndarray:
    nominal = np.arange(dt, duration, dt)
    t = np.sort(nominal + rng.uniform(-jitter, jitter, nominal.size) * dt)
    if dropout:  # a logger that stopped for 40 samples
        t = np.r_[t[: t.size // 2], t[t.size // 2 + 40:]]
    return t


@pytest.mark.parametrize(("jitter", "dropout"), [(0.4, False), (0.2, False), (0.45, True)])
def test_the_interpolations_correlation_matches_monte_carlo(jitter: float, dropout: bool) -> None:
    rng = np.random.default_rng(7)
    t = _stamps(rng, 0.002, jitter, 20.0, dropout)
    grid = np.arange(t[0], t[-1], 0.002)
    expected = np.array(interpolation_noise_correlation(t, grid, lags=3))
    sample = np.zeros(3)
    for _ in range(40):
        e = np.interp(grid, t, rng.normal(size=t.size))
        e -= e.mean()
        sample += [float(e[k:] @ e[:-k] / (e @ e)) for k in (1, 2, 3)]
    sample /= 40
    # 40 x 10,000 samples: the Monte Carlo mean is good to about 0.002
    assert np.abs(expected - sample).max() < 0.006, (expected, sample)
    assert expected[0] > 0.05  # the interpolation does correlate lag 1 (the test would pass on zeros otherwise)


def _record(seed: int, ar: float) -> tuple:
    """A damped second-order plant 43.2/(s^2 + 3.6 s + 36) behind steps at random times, simulated on a 0.1 ms
    grid and read at jittered 2 ms stamps (the steps at stamps), with white (``ar`` 0) or AR(1) output noise."""
    rng = np.random.default_rng(seed)
    fine = np.arange(0.0, 60.0, 1e-4)
    idx = np.unique(np.round(_stamps(rng, 0.002, 0.4, 59.9, False) / 1e-4).astype(int))
    edges = np.cumsum(rng.uniform(1.0, 4.0, 30)) + 0.5
    edges = fine[idx[np.searchsorted(fine[idx], edges[edges < 59.0])]]  # the logger logs a command as it is issued
    levels = rng.choice([0.0, 0.5, 1.0, 1.5], edges.size)
    u_fine = np.zeros_like(fine)
    for at, level in zip(edges, levels):
        u_fine[fine >= at] = level
    _, y_fine, _ = signal.lsim(([43.2], [1.0, 3.6, 36.0]), u_fine, fine)
    noise = rng.normal(0.0, 0.01, idx.size)
    if ar:
        noise = signal.lfilter([np.sqrt(1 - ar**2)], [1.0, -ar], noise)
    return fine[idx], u_fine[idx], y_fine[idx] + noise


@pytest.mark.parametrize("seed", [0, 1])
def test_white_noise_at_jittered_stamps_gives_no_correlation_note(seed: int) -> None:
    t, u, y = _record(seed, 0.0)
    record = record_from_arrays(t, u, y)
    assert record.noise_correlation[0] > 0.1  # resampled: the record knows its interpolation's correlation
    fit = identify(record, "k/(s^2+a*s+b)", average="none").fit
    assert "correlated" not in fit.solver.get("covariance_note", "")
    assert fit.parameters["k"] == pytest.approx(43.2, abs=4 * fit.std["k"])


def test_coloured_noise_at_jittered_stamps_is_still_named() -> None:
    t, u, y = _record(0, 0.9)
    fit = identify(record_from_arrays(t, u, y), "k/(s^2+a*s+b)", average="none").fit
    note = fit.solver.get("covariance_note", "")
    assert "the residuals are correlated" in note and "of it from the resampling of uneven stamps" in note, note
