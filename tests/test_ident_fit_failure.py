"""A failed fit is a failure (issue 16, item 2): FitError in the library, one line and exit 1 on the command line."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.errors import FitError, SynthError
from synth.ident.fit_failure import LIMIT_STATUSES, fit_failure
from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.ident.timefit import fit_structure
from synth.plant import Plant

T = np.arange(0, 6, 0.01)
U = np.where((T % 2) >= 1, 1.0, 0.0)  # a square wave: 3 periods of 2 s


def _noise_only(seed=1):
    return np.random.default_rng(seed).normal(size=T.size)


def test_noise_only_record_is_no_model():
    """The output does not respond to the input: the first-order fit explains no more than noise."""
    with pytest.raises(FitError, match=r"fit of 'K/\(T\*s\+1\)' failed: .*try another structure") as info:
        identify((T, U, _noise_only()), "K/(T*s+1)")
    # the failure is the F-test's, not the solver's: it converged, or stopped at its iteration limit within the
    # fit's uncertainty of the optimum (which one depends on the CPU's floating-point kernels)
    assert isinstance(info.value, SynthError) and info.value.status in ("Solve_Succeeded", *LIMIT_STATUSES)
    assert "F-test p = " in str(info.value) and "IPOPT stopped" not in str(info.value)
    assert "noise" in str(info.value) and "\n" not in str(info.value)


def test_a_delay_fitted_on_noise_names_the_fit_not_the_option():
    """The issue's second run: a diverged delay was reported as '--delay: delay must be ... >= 0 s, got -452.67'.
    On noise the fitted delay ran below 0 here too, until the walk between sample intervals kept the whole delay
    at or above 0 (synth.ident.delay_samples.walk_intervals): the fit fails for what it is, no better than noise."""
    with pytest.raises(FitError, match=r"fit of 'k/\(s\+p\)' failed: .*than noise would") as info:
        identify((T, U, _noise_only()), "k/(s+p)", delay="fit")
    assert "--delay" not in str(info.value) and "must be a finite number" not in str(info.value)
    assert 0.0 <= info.value.parameters["delay"] < T[-1]
    assert "outside [0, 2) s" in fit_failure({"k": 1.0, "p": 1.0}, np.ones(2), "Solve_Succeeded", True, 50.0,
                                             -452.67, 2.0)  # had it run below 0: named as the fit's failure


@pytest.mark.slow
def test_iteration_limit_on_noise_fails_with_the_solver_status():
    """IPOPT crawls on the flat cost of noise: not above noise, and the error carries the status of the fit it
    judged. The same square wave sampled at 20 ms (300 samples, noise seed 2): each iteration costs half as
    much. (Until the delay's moves between sample intervals had to lower the cost, the fit kept was one that
    stopped at the iteration limit; now it is the converged fit before a move that did not pay.)"""
    t = T[::2]
    noise = np.random.default_rng(2).normal(size=t.size)
    with pytest.raises(FitError, match="no more of the output than noise") as info:
        identify((t, U[::2], noise), "K/(T*s+1)", delay="fit")
    assert info.value.status in ("Solve_Succeeded", *LIMIT_STATUSES)
    assert "F-test p = " in str(info.value) and "IPOPT stopped" not in str(info.value)


def test_failure_rules():
    start = np.array([1.0, 1.0])
    ok = {"k": 2.0, "p": 3.0}
    assert fit_failure(ok, start, "Solve_Succeeded", True, 95.0, 0.1, 10.0, 1000, 4) == ""
    assert "Diverging_Iterates" in fit_failure({"k": 2e24, "p": 3.0}, start, "Diverging_Iterates", False, -2.19, 0.1, 10.0)
    assert "absurd" in fit_failure({"k": 2e24, "p": 3.0}, start, "Solve_Succeeded", True, 50.0, 0.1, 10.0)
    assert "absurd" in fit_failure({"k": np.nan, "p": 3.0}, start, "Solve_Succeeded", True, 50.0, 0.1, 10.0)
    assert "outside [0, 10) s" in fit_failure(ok, start, "Solve_Succeeded", True, 95.0, 10.0, 10.0)
    assert "no better than its mean" in fit_failure(ok, start, "Solve_Succeeded", True, -0.5, None, 10.0)
    assert fit_failure(ok, start, "Solve_Succeeded", True, 95.0, -1e-8, 10.0) == ""  # IPOPT's bound relaxation
    limit = "Maximum_Iterations_Exceeded"
    assert limit in fit_failure(ok, start, limit, False, 95.0, 0.1, 10.0, remaining_step=3.0)  # far from converged
    assert fit_failure(ok, start, limit, False, 95.0, 0.1, 10.0, remaining_step=0.01) == ""  # converged as data tell
    assert "Diverging" in fit_failure(ok, start, "Diverging_Iterates", False, 95.0, 0.1, 10.0, remaining_step=0.0)


def test_fit_structure_raises_with_check_and_reports_without():
    """identify and the CLI check; a caller that tries several fits (the gap's re-fits) reads solver["failure"]."""
    rec = record_from_arrays(T, U, _noise_only())
    with pytest.raises(FitError, match="than noise would"):
        fit_structure(rec, "k/(s+p)", delay="fit", check=True)
    res = fit_structure(rec, "k/(s+p)", delay="fit")
    assert "than noise would" in res.solver["failure"]


def test_a_good_fit_is_unchanged():
    y = 3.0 + simulate_plant(Plant.from_string("2/(s+3)", delay=0.043), T, U)
    y = y + 0.01 * np.random.default_rng(0).normal(size=T.size)
    res = fit_structure(record_from_arrays(T, U, y), "k/(s+p)", delay="fit", check=True)
    assert res.parameters["k"] == pytest.approx(2.0, rel=0.02) and res.fit_percent > 95 and res.solver["failure"] == ""


def test_cli_exit_1_one_line_nothing_written(run_cli, tmp_path):
    path = tmp_path / "noise.csv"
    path.write_text("t,u,y\n" + "\n".join(f"{a:.3f},{b:g},{c:.6g}" for a, b, c in zip(T, U, _noise_only())) + "\n")
    out = tmp_path / "out"
    res = run_cli("identify", "--data", str(path), "--structure", "k/(s+p)", "--delay", "fit", "--out", str(out))
    assert res.code == 1 and res.out == ""
    lines = res.err.strip().splitlines()
    assert len(lines) == 1 and "fit of 'k/(s+p)' failed: " in lines[0] and "than noise would" in lines[0], res.err
    assert "--delay:" not in lines[0] and "try another structure, a fixed delay" in lines[0]
    assert not (out / "identify.json").exists()


def test_real_thrust_stand_staircase_second_order_fit_fails_exit_1(run_cli, tmp_path):
    """The issue's real BLDC thrust-stand log: `K/((T1*s+1)*(T2*s+1)) --delay fit` diverged (K = 2e24) and was
    written as a result. README: an up-only ESC staircase logged at 20-50 Hz, "not high-rate transient step
    responses", so the two time constants are not in the record."""
    from tests.conftest import shared_path

    path = shared_path("data", "esc_thrust_stand_1s", "StepsTest20230624_2023-06-24_190243.csv")
    out = tmp_path / "out"
    res = run_cli("identify", "--data", str(path), "--time", "Time (s)", "--input", "ESC signal", "--output", "Thrust",
                  "--structure", "K/((T1*s+1)*(T2*s+1))", "--delay", "fit", "--out", str(out))
    assert res.code == 1 and res.out == ""
    lines = res.err.strip().splitlines()
    assert len(lines) == 1 and "fit of 'K/((T1*s+1)*(T2*s+1))' failed: parameters at absurd magnitudes" in lines[0]
    assert not out.exists() or not (out / "identify.json").exists()


def test_a_fit_worse_than_its_start_is_a_failure():
    start = np.array([2.1, 2.9])
    moved = fit_failure({"k": 2e-12, "p": -3.2}, start, "Solved_To_Acceptable_Level", True, 1.74, 9.36, 60.0,
                        start_fit_percent=96.1)
    assert moved.startswith("the fit ended worse than its start (fit 1.74 % against 96.10 %")
    # no worse than the start (to a relative 1e-6 of the residual norm), or the start unknown: not this failure
    assert fit_failure({"k": 2.0, "p": 3.0}, start, "Solve_Succeeded", True, 96.1 - 3.8e-6 * 0.5, 0.02, 60.0,
                       start_fit_percent=96.1) == ""
    assert fit_failure({"k": 2.0, "p": 3.0}, start, "Solve_Succeeded", True, 50.0, 0.02, 60.0) == ""
    # a diverged fit's astronomically bad fit is printed in three digits, not as 90 of them
    assert "fit -8.47e+91 %" in fit_failure({"k": 68.0, "p": 0.8}, start, "Error_In_Step_Computation", False,
                                            -8.47e91, 0.02, 60.0)


@pytest.mark.slow
def test_ipopt_from_a_far_start_does_not_return_a_fit_worse_than_the_start(monkeypatch):
    """Session 33 found IPOPT, started from a pair cancelled in the right half-plane (the pair relocation
    benchmark's problem 14, 4,000 samples), end at k = 2e-9, a pole at +1.33 and a delay of 2.3 s with fit 1.12 %,
    returned without a failure. The start's own fit is computed here apart from the fitter (simulate_plant).
    The singular Gauss-Newton Hessian there let IPOPT take steps 1e12 long and cut each back some 88 times: 31,951
    cost evaluations in all; with the perturbation's floor (sim_error_problem.MIN_HESSIAN_PERTURBATION) 6,261."""
    from benchmarks.pair_relocation import problem, wrong_start
    from synth.ident.sim_error_problem import SimulationErrorProblem
    from synth.ident.structure import parse_structure

    evaluations = []
    solve = SimulationErrorProblem.solve

    def counted(self, *args, **kwargs):
        out = solve(self, *args, **kwargs)
        evaluations.append(int(self.solver.stats().get("n_call_nlp_f", 0)))
        return out

    monkeypatch.setattr(SimulationErrorProblem, "solve", counted)

    p = problem(14)
    rec, st = record_from_arrays(p["t"], p["u"], p["y"]), parse_structure(p["structure"])
    start = {**wrong_start(p["truth"], 2), "delay": p["delay"]}
    model = st.plant(np.array([start[k] for k in st.parameters]), delay=p["delay"])
    before = float(np.mean(p["y"][p["t"] < 1.0]))  # the output before the first step (the fit's offset start)
    y0 = before + simulate_plant(model, p["t"], p["u"] - p["u"][0])
    start_fit = 100.0 * (1.0 - np.linalg.norm(p["y"] - y0) / np.linalg.norm(p["y"] - p["y"].mean()))
    try:
        res = fit_structure(rec, st, "fit", None, initial=start, solver="ipopt", check=True)
    except FitError as error:  # a failure, not a result (this machine: IPOPT stops on an invalid number)
        assert error.status is not None and "failed: " in str(error)
        if "worse than its start" in str(error):
            assert f"against {start_fit:.2f} % at the start" in str(error)
    else:  # where IPOPT's path differs, the fit returned must at least hold the start's
        assert res.fit_percent >= start_fit - 1e-3, (res.fit_percent, start_fit)
    assert 0 < sum(evaluations) <= 12_000, evaluations


def test_a_first_order_plant_on_jittered_stamps_is_not_biased(run_cli, tmp_path):
    """Found by a black-box test: ``3/(0.3 s + 1)`` simulated exactly on stamps jittered 4-6 ms, the input changing
    only at stamps, noise std 0.01. With the resampled edges half an interval late on average, K came out 0.46 % and
    T 1.1 % low (31 and 46 of their reported std); now within 0.2 % and 0.4 %."""
    import json

    import numpy as np

    rng, levels = np.random.default_rng(1), np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.004, 0.006, 6000))
    t -= t[0]
    u = np.zeros(t.size)
    k, value = 0, 0.0
    while k < t.size:  # a random binary command held at least 0.1 s, switching only at stamps
        end = int(np.searchsorted(t, t[k] + 0.1 * (1 + levels.integers(0, 4))))
        value = 1.0 if value <= 0 else -1.0
        u[k:end] = value
        k = max(end, k + 1)
    y = np.zeros(t.size)  # exact: the command held from each stamp to the next through 3/(0.3 s + 1)
    for i in range(1, t.size):
        a = np.exp(-(t[i] - t[i - 1]) / 0.3)
        y[i] = a * y[i - 1] + (1 - a) * 3.0 * u[i - 1]
    y += 0.01 * rng.standard_normal(t.size)
    path = tmp_path / "jittered.csv"
    path.write_text("Time (s),cmd,out\n" + "".join(f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in zip(t, u, y)))
    r = run_cli("identify", "--data", str(path), "--time", "Time (s)", "--input", "cmd", "--output", "out",
                "--structure", "K/(T*s+1)", "--out", str(tmp_path / "id"), "--json", str(tmp_path / "id.json"))
    assert r.code == 0, r.err
    p = json.loads((tmp_path / "id.json").read_text())["parameters"]
    assert abs(p["K"] / 3.0 - 1) < 0.002 and abs(p["T"] / 0.3 - 1) < 0.004


def test_a_failed_fit_with_a_negative_delay_is_reported_not_raised_without_check(monkeypatch):
    """Found by a helper's randomized test: fit_structure(check=False) on a cut record whose weighted fit ended with
    the delay at -2.3 ms raised ModelError ('delay must be ... >= 0') from building the model; without ``check`` a
    failed fit is reported in ``solver["failure"]`` (here forced: the delay walk's result is moved below 0)."""
    import synth.ident.timefit as timefit

    real = timefit.walk_intervals

    def below_zero(*args, **kwargs):
        xs, ssr, m, status, moves = real(*args, **kwargs)
        xs = xs.copy()
        xs[-2] = -0.003 - m * 0.01  # the fraction: the whole delay 3 ms below 0
        return xs, ssr, m, status, moves

    monkeypatch.setattr(timefit, "walk_intervals", below_zero)
    t = np.arange(0, 4, 0.01)
    u = np.where(t >= 0.5, 1.0, 0.0)
    y = simulate_plant(Plant.from_string("2/(s+3)"), t, u)
    res = fit_structure(record_from_arrays(t, u, y), "k/(s+p)", delay="fit")
    assert "delay" in res.solver["failure"] and "outside" in res.solver["failure"]
    assert res.delay == 0.0 and res.plant.delay == 0.0


def test_a_fit_at_its_iteration_limit_says_how_close_it_is_to_the_optimum(run_cli, tmp_path, monkeypatch):
    """Found by a black-box test: the 2020 ESC staircase, ``K/(T*s+1)`` with a fitted delay, ended with
    Levenberg-Marquardt at its iteration limit (100) and was written (exit 0) while the help said such a fit never
    is. It is a result because the Gauss-Newton step from there gains less than 0.1 standard errors: the status
    line and the help now say so. The crawl itself was the delay held at its bound 0 by clipping a step that moved
    every parameter; the steps now leave a parameter the bound holds where it is, and the fit converges in a few
    iterations to the same parameters. The limit is lowered to 4 here to stop it there."""
    import json

    import synth.ident.convolution_problem as convolution
    from tests.conftest import shared_path

    path = shared_path("data", "esc_thrust_stand_1s", "StepsTest_2020-06-16_220513.csv")

    def identify_esc(name: str):
        res = run_cli("identify", "--data", str(path), "--time", "Time (s)", "--input", "ESC signal", "--output",
                      "Thrust", "--structure", "K/(T*s+1)", "--delay", "fit", "--no-figures", "--out",
                      str(tmp_path / name), "--json", str(tmp_path / f"{name}.json"))
        assert res.code == 0, res.err
        return res, json.loads((tmp_path / f"{name}.json").read_text())

    _, free = identify_esc("free")
    assert free["solver"]["status"] == "Solve_Succeeded" and free["solver"]["iterations"] <= 20
    assert free["parameters"]["delay"] == 0.0
    monkeypatch.setattr(convolution, "_MAX_ITER", 4)
    monkeypatch.setattr(convolution, "_MAX_ITER_PROGRESSING", 4)
    res, capped = identify_esc("capped")
    solver = capped["solver"]
    assert solver["status"] == "Maximum_Iterations_Exceeded" and solver["remaining_improvement_std"] < 0.1
    assert capped["parameters"]["K"] == pytest.approx(free["parameters"]["K"], abs=0.01 * capped["std"]["K"])
    assert "stopped at its limit within 0.01 standard errors of the optimum, converged as far as the record can" \
           " tell" in res.out
    help_text = run_cli("identify", "--help").out
    assert "more than 0.1 standard errors from\nthe optimum" in help_text


def test_a_fixed_delay_as_long_as_the_record_is_refused_in_one_line(run_cli, tmp_path):
    """Found by a black-box test: ``--delay 100`` on a 40 s step train was fitted ("fit 94.02 %", a plant
    ``exp(-100*s)...``, exit 0) though no output sample can answer the input 100 s later."""
    t = np.arange(0.0, 40.0, 0.01)
    u = ((t % 4.0) >= 2.0) * 1.0
    y = 2.5 * (1.0 - np.exp(-np.clip(t % 4.0 - 2.0, 0.0, None) / 0.3)) * u + 0.01 * np.random.default_rng(0).normal(
        size=t.size)
    path = tmp_path / "r.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    res = run_cli("identify", "--data", str(path), "--structure", "K/(T*s+1)", "--delay", "100", "--no-figures",
                  "--out", str(tmp_path / "o"))
    assert res.code == 2 and res.out == ""
    lines = res.err.strip().splitlines()
    assert len(lines) == 1 and "the fixed delay 100 s is outside [0, 39.99) s, the record's length" in lines[0]
    assert not (tmp_path / "o").exists()


def test_an_integrating_structure_on_a_step_train_is_fitted_without_averaging(run_cli, tmp_path):
    """Found by a black-box test: ``K/(s*(T*s+1))`` on a 0/1 step train exited 2 ("a periodic fit needs a model
    without an integrator", no file named, nothing about ``--average none``, which fits it). The default average
    now leaves such a structure's record as it is; an average asked for is refused with the way out."""
    from scipy import signal

    t = np.arange(0.0, 30.0, 0.01)
    u = ((t % 3.0) >= 1.5) * 1.0
    _, y, _ = signal.lsim(signal.lti([3.0], [0.2, 1.0, 0.0]), u, t)  # 3/(s (0.2 s + 1)), scipy's own simulation
    y = y + 0.01 * np.random.default_rng(1).normal(size=t.size)
    path = tmp_path / "r.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    res = run_cli("identify", "--data", str(path), "--structure", "K/(s*(T*s+1))", "--no-figures", "--out",
                  str(tmp_path / "o"), "--json", str(tmp_path / "fit.json"))
    assert res.code == 0, res.err
    assert "not averaged as a step train (the structure integrates" in res.out
    import json

    p = json.loads((tmp_path / "fit.json").read_text())["parameters"]
    assert p["K"] == pytest.approx(3.0, rel=0.01) and p["T"] == pytest.approx(0.2, rel=0.03)
    asked = run_cli("identify", "--data", str(path), "--structure", "K/(s*(T*s+1))", "--average", "cycle",
                    "--no-figures", "--out", str(tmp_path / "o2"))
    assert asked.code == 2 and len(asked.err.strip().splitlines()) == 1
    assert "r.csv" in asked.err and "--average none" in asked.err


def test_an_edge_average_biased_beyond_its_error_gives_way_to_the_whole_record(run_cli, tmp_path):
    """Found by a black-box test: ``2.5 e^(-0.05 s)/(0.35 s + 1)`` on jittered stamps (8-12 ms), a 4 s step train
    leaving 0.39 % of each step unsettled when the next came: the default (edge) average gave K = 2.48789 +-
    0.00063, 19 of its standard errors low. The bias the leftover allows now exceeds the edge fit's finest
    relative error, so the whole record is fitted; the truth is within 3 standard errors."""
    import json

    from scipy import signal

    rng = np.random.default_rng(1)
    fine_dt = 0.0005
    fine_t = np.arange(0.0, 40.0, fine_dt)
    stamps = np.cumsum(rng.uniform(0.008, 0.012, 5000))
    stamps = np.round(stamps[stamps < 39.9] / fine_dt) * fine_dt
    u = np.where(((stamps - 1.0) % 4.0) < 2.0, 1.0, 0.0) * (stamps >= 1.0)
    at = np.round(stamps / fine_dt).astype(int)
    held = np.zeros(fine_t.size)  # the command changes at the stamps and is held in between
    for k, i in enumerate(at):
        held[i:] = u[k]
    lag = round(0.05 / fine_dt)
    delayed = np.r_[np.zeros(lag), held[:-lag]]
    num, den, _ = signal.cont2discrete(([2.5], [0.35, 1.0]), fine_dt, method="zoh")
    y = signal.dlsim((np.ravel(num), den, fine_dt), delayed)[1][:, 0][at] + 0.01 * rng.normal(size=at.size)
    path = tmp_path / "j.csv"
    np.savetxt(path, np.c_[stamps, u, y], delimiter=",", header="t,u,y", comments="", fmt="%.6f")
    res = run_cli("identify", "--data", str(path), "--structure", "K/(T*s+1)", "--delay", "fit", "--no-figures",
                  "--out", str(tmp_path / "o"), "--json", str(tmp_path / "fit.json"))
    assert res.code == 0, res.err
    assert "of a step unsettled when the next came" in res.out and "fitted the whole record instead" in res.out
    fit = json.loads((tmp_path / "fit.json").read_text())
    assert abs(fit["parameters"]["K"] - 2.5) <= 3.0 * fit["std"]["K"], (fit["parameters"]["K"], fit["std"]["K"])
