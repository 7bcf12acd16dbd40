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


# ----------------------------------------------------------------------------------------- the split check


def drifting(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 200 s train of ``record`` with white noise plus a random walk: the cycle average hides the drift from
    the residuals, not from the estimates."""
    rng = np.random.default_rng(seed)
    t, u = square_wave(2.0, 100, 1.0, 0.01)
    y = first_order_held(t, u, 2.0, 0.5, y0=2.0)
    return t, u, y + 0.05 * rng.normal(size=t.size) + 0.002 * np.cumsum(rng.normal(size=t.size))


def test_a_drift_the_residuals_do_not_show_is_caught_by_the_split_check():
    """Over 6 seeds: the estimates scatter at least twice their reported std (the reference, from the fits
    alone), the residual test says nothing, and the split check says "stds too small" on every seed with a
    largest ratio above 1.5."""
    from synth.data import record_from_arrays
    from synth.ident.split_check import split_check

    fits, checks = [], []
    for seed in range(6):
        t, u, y = drifting(seed)
        fits.append(identify((t, u, y), "K/(T*s+1)").fit)
        checks.append(split_check(record_from_arrays(t, u, y), "K/(T*s+1)", parts=5))
    worst = max(np.std([f.parameters[k] for f in fits], ddof=1) / np.mean([f.std[k] for f in fits])
                for k in ("K", "T"))
    assert worst > 2
    assert all("correlated" not in f.solver.get("covariance_note", "") for f in fits)
    assert all(c.verdict == "stds too small" and c.fitted == 5 for c in checks)
    assert all(max(c.ratio.values()) > 1.5 for c in checks)
    assert set(checks[0].ratio) == {"K", "T"}  # the fixed delay and the offset are not tested


def test_white_noise_passes_the_split_check():
    from synth.data import record_from_arrays
    from synth.ident.split_check import split_check

    for seed in range(3):
        check = split_check(record_from_arrays(*record(seed, 0.0)), "K/(T*s+1)", parts=5)
        assert check.verdict == "consistent", check.text()
        assert all(p > 1e-3 for p in check.p_value.values())


def test_the_split_check_is_undetermined_when_parts_do_not_fit():
    """Parts of 25 samples of a slow plant hold no step: their fits fail and the verdict says so, with why."""
    from synth.data import record_from_arrays
    from synth.ident.split_check import split_check

    t = np.arange(0, 1.5, 0.01)
    u = np.where(t > 0.2, 1.0, 0.0)
    y = first_order_held(t, u, 1.0, 5.0) + 1e-4 * np.random.default_rng(0).normal(size=t.size)
    check = split_check(record_from_arrays(t, u, y), "K/(T*s+1)", parts=6)
    assert check.verdict == "undetermined" and check.fitted < 3 and check.failures
    assert "undetermined" in check.text()


def test_the_cli_split_check_prints_its_verdict_and_refuses_two_parts(tmp_path, run_cli):
    t, u, y = drifting(0)
    path = tmp_path / "drift.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    common = ["identify", "--data", str(path), "--structure", "K/(T*s+1)", "--no-figures"]
    res = run_cli(*common, "--out", str(tmp_path / "a"), "--split-check", "5")
    assert res.code == 0, res.err
    assert "split check over 5 parts of 40.2 s: the part estimates scatter more than their stds say" in res.out
    import json

    data = json.loads((tmp_path / "a" / "identify.json").read_text())
    assert data["split_check"]["verdict"] == "stds too small" and data["split_check"]["fitted"] == 5
    bad = run_cli(*common, "--out", str(tmp_path / "b"), "--split-check", "2")
    assert bad.code == 2 and bad.err.strip().endswith("--split-check: needs 3 parts or more, got 2")
    assert not (tmp_path / "b").exists()


def test_parts_that_return_the_poles_in_another_order_are_compared_pole_by_pole():
    """k/((s+p1)*(s+p2)): a part may return the slow pole as p2. Aligned to the reference fit's labels, white
    noise is "consistent"; compared label by label, the swap looked like a std 20 times too small."""
    from scipy.signal import lsim

    from synth.data import record_from_arrays
    from synth.ident.exchangeable import align_labels, exchangeable_groups
    from synth.ident.split_check import split_check
    from synth.ident.structure import parse_structure

    assert exchangeable_groups(parse_structure("k/((s+p1)*(s+p2))")) == [["p1", "p2"]]
    values, stds = align_labels({"k": 12.7, "p1": 10.5, "p2": 1.157}, {"k": 0.3, "p1": 0.26, "p2": 0.002},
                                {"k": 12.9, "p1": 1.15, "p2": 10.6}, [["p1", "p2"]])
    assert values == {"k": 12.7, "p1": 1.157, "p2": 10.5} and stds["p1"] == 0.002
    t = np.arange(0, 120, 0.005)
    u = np.where((t // 1.0) % 2 == 1, 1.0, 0.0)
    y = lsim(([12.0], [1.0, 11.0, 10.0]), u, t)[1] + 0.01 * np.random.default_rng(4).normal(size=t.size)
    record = record_from_arrays(t, u, y)
    swapped = split_check(record, "k/((s+p1)*(s+p2))", parts=4, reference={"k": 12.0, "p1": 10.0, "p2": 1.0})
    assert swapped.verdict == "consistent", swapped.text()
    assert np.all(np.array(swapped.estimates["p1"]) > 5)  # the fast pole in every part, as the reference has it
