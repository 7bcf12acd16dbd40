"""A fit whose residuals are correlated says that its std column (which assumes white residuals) may be too small;
a fit with white residuals says nothing. Records: a first-order step train, exact (tests/first_order_reference.py),
with white or AR(1) output noise."""

from __future__ import annotations

import numpy as np
import pytest

from synth.ident.identification import identify
from synth.ident.residual_whiteness import correlated_residuals_note
from tests.first_order_reference import first_order_held, square_wave


def record(seed: int, ar: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """2/(0.5 s + 1), steps between 1 and 2 every 2 s for 100 s at 100 Hz; noise of std 0.05 passed through
    1/(1 - ar z^-1)."""
    rng = np.random.default_rng(seed)
    t, u = square_wave(2.0, 50, 1.0, 0.01)
    white = 0.05 * rng.normal(size=t.size)
    noise = np.empty_like(white)
    state = 0.0
    for k, v in enumerate(white):
        state = ar * state + v
        noise[k] = state
    return t, u, first_order_held(t, u, 2.0, 0.5, y0=2.0) + noise


def test_white_residuals_give_no_note():
    for seed in range(4):
        fit = identify(record(seed, 0.0), "K/(T*s+1)").fit
        assert "correlated" not in fit.solver.get("covariance_note", "")
        assert abs(fit.parameters["T"] - 0.5) < 5 * fit.std["T"]


def test_correlated_noise_is_named_and_the_stds_it_warns_about_are_too_small():
    """AR(1) noise with coefficient 0.95: every fit carries the note, and the estimates scatter across seeds
    several times more than the std each fit reports (what the note warns of)."""
    fits = [identify(record(100 + seed, 0.95), "K/(T*s+1)").fit for seed in range(8)]
    for fit in fits:
        note = fit.solver.get("covariance_note", "")
        assert "the residuals are correlated" in note and "lag 1 sample" in note
    for name in ("K", "T"):
        scatter = np.std([f.parameters[name] for f in fits], ddof=1)
        reported = np.mean([f.std[name] for f in fits])
        assert scatter > 3 * reported


def test_the_cli_prints_the_note_under_the_table(tmp_path, run_cli):
    t, u, y = record(7, 0.95)
    path = tmp_path / "train.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    res = run_cli("identify", "--data", str(path), "--time", "t", "--input", "u", "--output", "y",
                  "--structure", "K/(T*s+1)", "--out", str(tmp_path / "out"), "--no-figures")
    assert res.code == 0, res.err
    assert "note on the std column: the residuals are correlated" in res.out


@pytest.mark.parametrize("n", [10, 49])
def test_too_few_samples_to_test_give_no_note(n):
    assert correlated_residuals_note(np.cumsum(np.ones(n))) == ""


def test_a_significant_but_small_correlation_gives_no_note():
    """200,000 samples with autocorrelation 0.05 at lag 1: significant (p far below 1e-6) but the stds are
    only about 5 % too small, not worth a warning."""
    rng = np.random.default_rng(3)
    w = rng.normal(size=200_001)
    e = w[1:] + 0.05 * w[:-1]
    assert correlated_residuals_note(e) == ""
