"""Direction-dependent dynamics (issue 16, item 3): up and down steps fitted apart, compared, reported."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.data import load_record, record_from_arrays
from synth.errors import DataError
from synth.ident.directions import compare_fits, fit_by_direction
from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.ident.timefit import fit_structure
from synth.plant import Plant
from tests.conftest import shared_path
from tests.first_order_reference import first_order_held, square_wave

T = np.arange(0, 4, 0.001)
U = np.where((T % 0.5) >= 0.25, 1.0, 0.0)  # 8 periods of 0.5 s: 8 up and 7 down steps, settled in 0.25 s


def _train(t_up, t_down, noise=0.05, seed=0, gain=2.0):
    """Each up step answers with gain/(t_up s + 1), each down step with gain/(t_down s + 1)."""
    w_up = np.cumsum(np.maximum(np.diff(U, prepend=0.0), 0.0))
    y = (simulate_plant(Plant.from_string(f"{gain}/({t_up}*s+1)"), T, w_up)
         + simulate_plant(Plant.from_string(f"{gain}/({t_down}*s+1)"), T, U - w_up))
    return record_from_arrays(T, 10 + U, 5 + y + noise * np.random.default_rng(seed).normal(size=T.size))


def test_load_cell_like_difference_is_detected_and_both_reported_near_truth():
    """The issue's load cell: up-steps about 40 ms, down-steps about 25 ms."""
    res = identify(_train(0.040, 0.025), "K/(T*s+1)", delay="fit")
    c = res.directions
    assert res.direction_dependent and c.significant and c.largest == "T"
    assert c.up.parameters["T"] == pytest.approx(0.040, rel=0.05)
    assert c.down.parameters["T"] == pytest.approx(0.025, rel=0.05)
    assert c.up.parameters["K"] == pytest.approx(2.0, rel=0.02) and c.down.parameters["K"] == pytest.approx(2.0, rel=0.02)
    assert abs(c.difference["T"] - 0.015) < 3 * c.std["T"]  # the difference with its standard error
    # 8 up and 7 down steps; the first (up) step is left out of the comparison: its window holds the record's start
    assert (c.up_average.up, c.up_average.down, c.down_average.up, c.down_average.down) == (7, 0, 0, 7)
    assert c.summary().startswith("up and down steps differ: T 0.039") and "p < 1e-12 over 3 parameters" in c.summary()
    # the average of both directions lies between them: the compromise the report warns about
    assert 0.025 < res.fit.parameters["T"] < 0.040


def test_equal_directions_are_not_flagged_over_20_noise_seeds():
    flagged = [fit_by_direction(_train(0.030, 0.030, noise=0.2, seed=seed), "K/(T*s+1)", delay="fit").significant
               for seed in range(20)]
    assert sum(flagged) <= 1, flagged


def test_by_direction_needs_both_directions():
    t = np.arange(0, 2, 0.001)
    u = np.where(t >= 0.5, 1.0, 0.0)
    y = simulate_plant(Plant.from_string("2/(0.03*s+1)"), t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    with pytest.raises(DataError, match="up and down steps"):
        identify((t, u, y), "K/(T*s+1)", by_direction=True)
    assert identify((t, u, y), "K/(T*s+1)").directions is None


def test_cli_reports_the_difference_and_fits_by_direction(run_cli, tmp_path):
    r = _train(0.040, 0.025)
    path = tmp_path / "cell.csv"
    path.write_text("t,u,y\n" + "\n".join(f"{a:.4f},{b:g},{c:.6g}" for a, b, c in zip(r.t, r.u, r.y)) + "\n")
    base = ["identify", "--data", str(path), "--structure", "K/(T*s+1)", "--delay", "fit", "--no-figures"]
    res = run_cli(*base, "--out", str(tmp_path / "a"))
    assert res.code == 0, res.err
    assert "up and down steps differ: T 0.039" in res.out and "--by-direction" in res.out
    res = run_cli(*base, "--out", str(tmp_path / "b"), "--by-direction", "--json", "-")
    assert res.code == 0, res.err
    d = json.loads(res.out)
    assert d["by_direction"] and d["directions"]["significant"]
    assert d["directions"]["up"]["parameters"]["T"] == pytest.approx(0.040, rel=0.05)
    assert d["directions"]["down"]["parameters"]["T"] == pytest.approx(0.025, rel=0.05)


HSM = "hsm150_two_motor_steps"


@pytest.mark.parametrize("run", [1, 2, 3])
def test_hsm150_torque_steps_differ_by_direction_as_the_readme_says(run):
    """README: "negative runs ~ -40..-46 rad/s per -0.010 N m, positive runs ~ +71..+97 rad/s per +0.010 N m;
    63 % rise time after the t=10 s step ~1.1-1.9 s". The t = 10 s steps: -0.030 -> -0.040 N m (down)
    and +0.050 -> +0.060 N m (up), fitted from t = 5 s (settled on the first plateau) with K/(T s + 1)."""
    def fit(kind):
        r = load_record(shared_path("data", HSM, f"idf_{kind}_{run}.mat"), "data[0]", "data[4]", "data[3]")
        k = r.t >= 5
        return fit_structure(record_from_arrays(r.t[k], r.u[k], r.y[k], r.input, r.output), "K/(T*s+1)")

    c = compare_fits(fit("pos_0.06"), fit("neg_0.04"))
    assert c.significant and c.largest == "K"
    assert 71 - 2 <= c.up.parameters["K"] * 0.010 <= 97 + 2  # rad/s per 0.010 N m, up
    assert 40 - 2 <= c.down.parameters["K"] * 0.010 <= 46 + 2  # down
    for side in (c.up, c.down):
        assert 1.1 - 0.1 <= side.parameters["T"] <= 1.9 + 0.1


def _linear_train_starting_off_rest(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``2/(0.03 s + 1)``, a square wave between 1 and 2 (half period 0.3 s, 20 edges, the first at 0.1 s), the
    output starting at 1.0 where rest at the first level is 2.0; exact zero-order hold at 1 ms, noise std 0.02."""
    t, u = square_wave(0.3, 20, 0.1, 0.001)
    y = first_order_held(t, u, 2.0, 0.03, y0=1.0)
    return t, u, y + 0.02 * np.random.default_rng(seed).normal(size=t.size)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_record_starting_mid_transient_is_not_called_direction_dependent(seed):
    """Found by a black-box test: the first up step's window held the start-up from an unknown state (1.8 % of a
    step left), and a linear plant's up and down steps were called different at 3.9-4.9 sigma on 3 of 3 seeds.
    That step is now left out of the comparison when its direction has others."""
    res = identify(_linear_train_starting_off_rest(seed), "K/(T*s+1)")
    c = res.directions
    assert c is not None and not c.significant, c.z if c is not None else res.direction_note
    for fit in (c.up, c.down):
        assert abs(fit.parameters["K"] - 2.0) < 4 * fit.std["K"] and abs(fit.parameters["T"] - 0.03) < 4 * fit.std["T"]
