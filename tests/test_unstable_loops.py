"""Unstable and marginal loops (issue 15, item 2), each verdict against an independent computation:
closed-loop poles by numpy roots, margins by python-control, feasible sets on a dense gain grid."""

from __future__ import annotations

import json

import control
import numpy as np
import pytest
import yaml

from synth.check import check
from synth.controllers import Controller
from synth.design import design
from synth.loop import Loop
from synth.loop_batch import LoopBatch
from synth.plant import Plant
from synth.requirements import Bandwidth, MarginsRequirement, PeakComplementary, PeakSensitivity, Sensitivity
from synth.spec import parse_spec
from synth.stability import STABILITY_FLOOR

PLANT = "10/((s-1)*(s+5))"  # one open-loop pole at +1; P control stabilizes for K > 0.5 (char. s^2 + 4s + 10K - 5)


def _spec(bounds=(0.0, 20.0), bw=5.0, pm=45.0) -> dict:
    return {"name": "unstable_p", "plant": {"tf": PLANT},
            "controller": {"type": "P", "bounds": {"kp": list(bounds)}},
            "requirements": [{"type": "bandwidth", "min": bw}, {"type": "margins", "phase_margin_deg": pm}],
            "objective": {"maximize": "bandwidth"}}


def _poles(k: float) -> np.ndarray:
    return np.roots([1.0, 4.0, 10.0 * k - 5.0])


def _pm_and_bw(k: float) -> tuple[float, float, bool]:
    """Independent: python-control's stability margins and closed-loop bandwidth, numpy's roots."""
    L = control.tf([10.0 * k], np.polymul([1.0, -1.0], [1.0, 5.0]))
    stable = bool(np.all(_poles(k).real < 0))
    _, pm, _, _ = control.margin(L)
    bw = control.bandwidth(control.feedback(L, 1)) if stable else np.nan
    return float(pm), float(bw), stable


@pytest.mark.parametrize("k", [0.4, 0.5])
def test_margins_and_bandwidth_are_never_met_on_an_unstable_or_marginal_loop(k):
    assert np.max(_poles(k).real) >= 0  # independent: a root in the closed right half-plane
    loop = Loop(Plant.from_string(PLANT), Controller("P", {"kp": k}))
    for req in (MarginsRequirement(phase_margin_deg=45), Bandwidth(min=5)):
        r = req.evaluate(loop)
        assert not r.met and r.slack < 0 and np.isnan(r.value)
        assert ("UNSTABLE" if k < 0.5 else "marginally stable") in r.message and "undefined" in r.message
        assert r.details["closed_loop_stable"] is False


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_closed_loop_magnitudes_are_met_only_on_stable_loops(seed):
    """|S| over a band, peak |S| and peak |T| of random plants (some open-loop unstable) under P gains on both
    sides of their stability limits: met only where numpy's closed-loop roots are all in the left half-plane
    (an unstable loop's |S(jw)| can be small: P(0.05) on this file's plant has peak |S| 0.92 dB), the scalar
    and the batch slack agree in sign, and on stable loops the peak is a dense grid's."""
    rng = np.random.default_rng(seed)
    poles = [rng.uniform(0.2, 2.0), rng.uniform(-6.0, 2.0), -rng.uniform(5.0, 20.0)]  # high gain stabilizes (2 zeros)
    num = rng.uniform(1.0, 20.0) * np.poly(-rng.uniform(0.5, 5.0, size=2))
    den = np.poly(poles)
    plant = Plant(num, den)
    gains = np.geomspace(0.01, 50.0, 25)
    reqs = [Sensitivity(max_db=20.0, band=(0.0, 1.0)), PeakSensitivity(max_db=20.0), PeakComplementary(max_db=20.0)]
    batch = LoopBatch(plant, [Controller("P", {"kp": float(k)}) for k in gains])
    w = np.geomspace(1e-3, 1e7, 150000)  # relative degree 1: |S| -> 1 as w -> inf
    seen = set()
    for req in reqs:
        batch_slacks = req.batch_slack(batch)
        for k, batch_slack in zip(gains, batch_slacks):
            stable = bool(np.all(np.roots(np.polyadd(den, k * num)).real < 0))
            r = req.evaluate(Loop(plant, Controller("P", {"kp": float(k)})))
            assert (batch_slack >= 0) == r.met
            if not stable:
                assert not r.met and np.isnan(r.value) and "UNSTABLE" in r.message
                seen.add("unstable")
            else:
                L = k * np.polyval(num, 1j * w) / np.polyval(den, 1j * w)
                curve = np.abs(L / (1 + L)) if isinstance(req, PeakComplementary) else np.abs(1 / (1 + L))
                if isinstance(req, Sensitivity):
                    curve = curve[w <= 1.0]
                assert r.value == pytest.approx(20 * np.log10(curve.max()), abs=0.01)
                seen.add("stable")
    assert seen == {"stable", "unstable"}


def test_check_on_unstable_and_marginal_loops_gives_a_verdict(run_cli):
    spec = parse_spec(_spec())
    for k in (0.4, 0.5):
        result = check(spec, f"P({k})")
        assert not result.feasible and not any(r.met for r in result.requirements)
        json.dumps(result.to_dict())  # JSON-ready, no exception


def test_check_cli_at_the_origin_pole_exits_1_without_traceback(run_cli, tmp_path):
    path = tmp_path / "u.yaml"
    path.write_text(yaml.safe_dump(_spec()))
    res = run_cli("check", str(path), "--controller", "P(0.5)")
    assert res.code == 1 and "Traceback" not in res.err
    assert "marginally stable" in res.out and "NOT met: closed-loop stability, bandwidth, margins" in res.out


def test_margins_of_an_open_loop_unstable_plant_report_the_lower_gain_limit():
    for k in (0.8, 2.0, 6.0):
        m = Loop(Plant.from_string(PLANT), Controller("P", {"kp": k})).margins()
        L = control.tf([10.0 * k], np.polymul([1.0, -1.0], [1.0, 5.0]))
        gm, pm, _, _ = control.margin(L)  # python-control: gain margin 0.5/k (< 1: a lower limit)
        assert m.closed_loop_stable
        assert m.lower_gain_margin_db == pytest.approx(20 * np.log10(gm), abs=1e-6)
        assert m.lower_gain_margin_db == pytest.approx(20 * np.log10(0.5 / k), abs=1e-6)
        assert m.gain_margin_db == np.inf
        assert m.phase_margin_deg == pytest.approx(pm, abs=1e-4)
        assert m.lower_phase_crossover == pytest.approx(0.0, abs=1e-9)
        # two-sided gain-margin requirement: the lower limit counts
        r = MarginsRequirement(gain_margin_db=6).evaluate(Loop(Plant.from_string(PLANT), Controller("P", {"kp": k})))
        assert r.met == (20 * np.log10(k / 0.5) >= 6)
        assert r.value == pytest.approx(20 * np.log10(k / 0.5), abs=1e-6)
        # the line says which way the gain may move (it read "gain margin 11.1 dB" as if it could rise by that)
        assert f"gain margin {20 * np.log10(k / 0.5):.4g} dB downward" in r.message and "rise by inf dB" in r.message


def test_design_over_an_unstable_plant_states_the_stabilizing_set():
    result = design(parse_spec(_spec((0.3, 17.0))))
    assert not result.feasible
    assert "margins needs" not in result.verdict
    assert "stable only for kp in (0.5, 17]" in result.verdict
    stab = result.gain_set.per_requirement["stability"]
    # independent: s^2 + 4s + 10K - 5 has its slow root -2 + sqrt(9 - 10K) left of -f (the stability floor,
    # STABILITY_FLOOR x the plant's smallest corner, 1 rad/s) iff 10K - 5 > 4 - (2 - f)^2
    f = STABILITY_FLOOR * 1.0
    assert stab[0][0] == pytest.approx((9 - (2 - f) ** 2) / 10, rel=1e-9)
    assert result.compromise is not None and result.compromise.controller.parameters["kp"] > 0.5
    # the compromise is stable (independent roots)
    assert np.all(_poles(result.compromise.controller.parameters["kp"]).real < 0)


def test_design_over_an_unstable_plant_matches_a_dense_gain_grid():
    spec = parse_spec(_spec((0.0, 20.0), bw=4.0, pm=35.0))
    result = design(spec)
    assert result.feasible
    [(lo, hi)] = result.gain_set.as_list()
    grid = np.linspace(0.01, 20.0, 2000)
    ok = []
    for k in grid:
        pm, bw, stable = _pm_and_bw(k)
        ok.append(stable and pm >= 35.0 and bw >= 4.0)
    ok = np.array(ok)
    step = grid[1] - grid[0]
    assert grid[ok].min() == pytest.approx(lo, abs=step) and grid[ok].max() == pytest.approx(hi, abs=step)
    assert lo <= result.controller.parameters["kp"] <= hi


def test_design_at_unstable_bounds_never_raises():
    # the whole range unstable: infeasible, with the (empty) stabilizing set said
    result = design(parse_spec(_spec((0.0, 0.5))))
    assert not result.feasible
    assert "stabilizes the closed loop" in result.verdict or "stable only" in result.verdict


@pytest.mark.parametrize("tf", ["1/(s^2+1)", "1/s^2"])
def test_poles_on_the_axis_give_a_verdict(tf):
    spec = parse_spec({**_spec(), "plant": {"tf": tf}})
    result = check(spec, "P(1)")
    assert not result.feasible
    assert "marginally stable" in result.requirements[0].message


def test_a_zero_plant_is_bad_input(run_cli, tmp_path):
    path = tmp_path / "z.yaml"
    path.write_text(yaml.safe_dump({**_spec(), "plant": {"tf": "0"}}))
    res = run_cli("design", str(path), "--no-report")
    assert res.code == 2 and "identically zero" in res.err and len(res.err.strip().splitlines()) == 1


def test_a_rational_order_beyond_proper_is_bad_input(run_cli, tmp_path):
    path = tmp_path / "r.yaml"
    path.write_text(yaml.safe_dump({**_spec(), "controller": {"type": "rational", "order": [3, 2]}}))
    res = run_cli("design", str(path), "--no-report")
    assert res.code == 2 and "controller.order" in res.err and len(res.err.strip().splitlines()) == 1
