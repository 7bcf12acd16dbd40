"""A record that begins just after a step is not fitted as if the plant had settled at its first input (session 44).

Found by a black-box test on the real HSM150 drive records: the torque is already at its first level at t = 0 while
the speed starts from rest; the whole-record fit assumed the plant settled at that level, and returned K 6084 and
T 0.68 s (fit 39.7 %, exit 0) where a fit after the start gives about 3710 and 1.42 s. Session 44 made that a failed
fit; since session 46 the start state is tested (synth.ident.start_state) and left out where it matters
(synth.ident.unknown_start): the record is fitted from where the start-up transient has died out.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy import signal

from synth.errors import FitError
from synth.ident.identification import identify

HSM = Path(__file__).resolve().parents[2] / "shared" / "data" / "hsm150_two_motor_steps"


def _record(start_at_rest: bool, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """2/(0.5 s + 1): the input steps to 1 at t = 0 (already 1 at the first sample) and to 1.5 at t = 10 s."""
    t = np.arange(0.0, 20.0, 0.005)
    u = np.where(t < 10.0, 1.0, 1.5)
    x0 = [2.0] if start_at_rest else [0.0]  # settled at u = 1 (y = 2), or at rest from u = 0 (y = 0)
    sys = signal.StateSpace([[-2.0]], [[4.0]], [[1.0]], [[0.0]])  # y = x, x' = -2 x + 4 u
    _, y, _ = signal.lsim(sys, u, t, X0=x0)
    y = y + np.random.default_rng(seed).normal(0.0, 0.01, t.size)
    return t, u, y


@pytest.mark.parametrize("seed", [0, 1])
def test_a_record_starting_mid_transient_is_fitted_after_its_start(seed: int) -> None:
    t, u, y = _record(False, seed)
    res = identify((t, u, y), "K/(T*s+1)")
    fit, test = res.fit, res.fit.solver["start_state"]
    assert "does not start at rest" in res.whole_record_note and "weighted 0" in res.whole_record_note
    # the free response 2 exp(-2 t) falls below the noise (0.01) after ln(200)/2 = 2.6 s: not before it, nor past
    # the step at 10 s
    assert 2.6 <= test["first"] < 10.0 and not test["matters"]
    assert fit.weights is not None and fit.weights[t < test["first"] - 0.01].sum() == 0
    assert fit.parameters["K"] == pytest.approx(2.0, abs=4 * fit.std["K"])
    assert fit.parameters["T"] == pytest.approx(0.5, abs=4 * fit.std["T"])


@pytest.mark.parametrize("seed", [0, 1])
def test_a_record_starting_settled_is_fitted(seed: int) -> None:
    t, u, y = _record(True, seed)
    fit = identify((t, u, y), "K/(T*s+1)").fit
    assert fit.parameters["K"] == pytest.approx(2.0, abs=4 * fit.std["K"] + 1e-3)
    assert fit.parameters["T"] == pytest.approx(0.5, abs=4 * fit.std["T"] + 1e-3)


def test_the_real_hsm150_record(run_cli, tmp_path) -> None:
    """The README: a step from rest at t = 0 and one of -0.010 N m at 10 s, 63 % of it within 1.1-1.9 s; the
    incremental gain from the 2-s means before each step's end is 3937 rad/s per N m on this run (computed here)."""
    path = HSM / "idf_neg_0.04_1.mat"
    if not path.exists():
        pytest.skip(f"needs the shared data folder {HSM} (present in CI and the dev workspace)")
    import json

    from scipy.io import loadmat

    data = loadmat(path, squeeze_me=True)["data"]
    t, torque, speed = data[:, 0], data[:, 4], data[:, 3]
    gain = (speed[t >= 18.0].mean() - speed[(t >= 8.0) & (t < 10.0)].mean()) / (torque[-1] - torque[9000])
    r = run_cli("identify", "--data", str(path), "--columns", "data[0]=t,data[4]=torque,data[3]=speed", "--time", "t",
                "--input", "torque", "--output", "speed", "--structure", "K/(T*s+1)", "--no-figures", "--json", "-",
                "--out", str(tmp_path / "out"))
    assert r.code == 0, r.err
    out = json.loads(r.out)
    assert "does not start at rest" in out["whole_record"]
    assert out["solver"]["start_state"]["first"] < 11.5  # the second step's transient stays in the fit
    assert out["parameters"]["K"] == pytest.approx(gain, rel=0.05)
    assert 1.1 <= out["parameters"]["T"] <= 1.9


def _train_from_mid_transient(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """2/(0.5 s + 1) under a square wave 1 <-> 1.5 every 5 s, its input at 1 from the first sample while the
    output starts from rest (as the HSM150 records do): a step train, so identify averages it first."""
    t = np.arange(0.0, 40.0, 0.005)
    u = np.where((t // 5.0) % 2 == 0, 1.0, 1.5)
    sys = signal.StateSpace([[-2.0]], [[4.0]], [[1.0]], [[0.0]])
    _, y, _ = signal.lsim(sys, u, t, X0=[0.0])
    return t, u, y + np.random.default_rng(seed).normal(0.0, 0.01, t.size)


def test_the_whole_record_fitted_after_a_failed_average_is_checked_at_its_start_too(monkeypatch) -> None:
    """Where the average's fit fails, identify fits the whole record instead, which also assumes the plant at
    rest at the first input sample; on a record that starts mid-transient that fallback was returned as the result
    (K and T bent to soften the miss) instead of failing as a whole-record fit of its own does."""
    import synth.ident.identification as identification

    t, u, y = _train_from_mid_transient(0)
    real = identification.fit_structure

    def failing_on_the_average(data, *args, **kwargs):
        if data.t.size < t.size:
            raise FitError("IPOPT: Maximum_Iterations_Exceeded (made to fail)", status="Maximum_Iterations_Exceeded")
        return real(data, *args, **kwargs)

    monkeypatch.setattr(identification, "fit_structure", failing_on_the_average)
    res = identify((t, u, y), "K/(T*s+1)", compare_directions=False)  # the fallback leaves the start out
    assert "fitted the whole record instead, the record does not start at rest" in res.whole_record_note
    assert res.fit.solver["start_state"]["first"] >= 2.6 and not res.fit.solver["start_state"]["matters"]
    # (lsim interpolates the input linearly between samples: its eight edges are half a sample late against the
    # zero-order hold the fit assumes, which pulls T by about 0.5 %, 7 std here)
    assert res.fit.parameters["K"] == pytest.approx(2.0, rel=0.01)
    assert res.fit.parameters["T"] == pytest.approx(0.5, rel=0.01)
    # the same record with the plant settled at the first input is fitted by the fallback, near the truth
    y_settled = y + 2.0 * np.exp(-2.0 * t)  # the response from y = 2 (settled at u = 1) instead of from rest
    res = identify((t, u, y_settled), "K/(T*s+1)", compare_directions=False)
    assert "fitted the whole record instead" in res.whole_record_note
    assert res.fit.parameters["K"] == pytest.approx(2.0, rel=0.01)
    assert res.fit.parameters["T"] == pytest.approx(0.5, rel=0.02)


def test_a_refit_after_the_start_that_fails_is_a_failure_naming_the_start(monkeypatch) -> None:
    """The refit from where the start state has died out may fail like any fit (IPOPT at its limit, found on a
    randomized case with a fitted delay): identify raises, saying the start was not at rest and what failed after."""
    import synth.ident.unknown_start as unknown_start

    t, u, y = _record(False, 0)

    def failing(*args, **kwargs):
        raise FitError("fit of 'K/(T*s+1)' failed: IPOPT stopped with Maximum_Iterations_Exceeded (made to fail)",
                       status="Maximum_Iterations_Exceeded")

    monkeypatch.setattr(unknown_start, "fit_structure", failing)
    with pytest.raises(FitError, match=r"does not start at rest \(its start state would move K by [0-9.]+ std\) and "
                                       r"the fit after its first [0-9.]+ s failed: IPOPT stopped") as caught:
        identify((t, u, y), "K/(T*s+1)")
    assert caught.value.status == "Maximum_Iterations_Exceeded"
