"""Real records diagnosed from a linear model fitted to them (issue 6, item 7).

Measured here (nothing tuned to the documented values):

- EMPS (vir -> velocity, 100 Hz): a first-order drive model ``b/(s+a)`` fitted by ``identify`` (fit 83.8 %)
  leaves Coulomb friction: ``friction`` is the verdict, fc = 0.579 V = 20.35 N (README 20.4 N), held-out
  shrinkage 0.79 [0.75, 0.85]; the re-fitted drive with friction gives M = 89.0 kg, Fv = 210.6 N s/m
  (README 95.1 kg, 203.5 N s/m). A dead zone on the voltage (the quasi-static picture) shrinks 0.10, not significant.
- DC motor 06_*_05 (eddy-current brake at alpha 0.5) against the authors' no-load model: the verdict is
  ``parameter_mismatch`` with the re-fitted gain 151.9 rpm/V, 0.619 of the nominal (README: 150.5 rpm/V, -40 %).
- DC motor 09_*_05: the logged voltage is already clipped at 24.0 V (11 samples), so from the logged command the
  saturation cannot be seen in the gap; the diagnosis names it from the record itself (``verdict.observed``: the
  voltage rests on its maximum 24 V for 11 samples, no other value occurs more than twice). The PID's unclipped
  output is rebuilt from setpoint and speed to 0.004 V RMS.
- DC motor, the three no-load runs (06_*_00 open-loop step, 09_*_00 and 12_*_00 closed-loop steps), from a
  delay-free ``k/((T1 s+1)(T2 s+1))`` fitted to 06_*_00 (fit 98.6 %): each run holds one transient, so no single
  run confirms the documented delay on held-out data (trained on 06, 09 or 12 alone, the verdict is a parameter
  mismatch, ``delay``, or unexplained). The round robin (each run trains once, the other two are held out, the
  evidence pooled) names ``delay``: shrinkage 0.35 [0.13, 0.50], the delay fitted on each run 41.7, 39.2 and 36.5 ms
  (README: Td = 35 ms in the authors' model). An extra lag does almost as well (0.34 [0.12, 0.49], tau 46-73 ms).
- Cascaded tanks (README: output clipped at 10.0, 47 samples in yEst, 37 in yVal; Torricelli outflow): from a
  2nd-order linear model fitted on yEst (fit 74.7 %), the diagnosis names the clip from both records
  (``verdict.observed == ["saturation(output)"]``, level 10.0, 47 and 37 samples). On held-out data (yVal) the clip
  fitted into the model shrinks the error by 0.13 [-0.01, 0.25], not significant: the Torricelli outflow (level-dependent
  dynamics, not in the effect library) dominates the linear model's gap, so no effect is accepted.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.attribution.roundrobin import diagnose_runs
from synth.gap.diagnose import diagnose
from synth.gap.effects.registry import DEFAULT_CANDIDATES
from synth.ident.identification import identify
from synth.ident.timefit import fit_structure
from synth.plant import Plant
from tests.conftest import shared_path
from tests.gap_realdata_helpers import EMPS_DRIVE_GAIN, dcmotor_controller_output, dcmotor_record, emps_record, tanks_record

DC = ("data", "dcmotor_speed_lab")
AUTHORS_NO_LOAD = Plant.from_string("245.5/(0.1468*s+1)^2", delay=0.035)  # rpm/V, 09/pid_kuhn.tex


def test_emps_linear_model_leaves_coulomb_friction():
    rec = emps_record(shared_path("data", "emps_friction_drive", "DATA_EMPS.mat"))
    fit = identify(rec, "b/(s+a)", delay=0.0).fit
    nominal = Plant.from_string(f"{fit.parameters['b']!r}/(s+{fit.parameters['a']!r})")
    dg = diagnose_effects(nominal, rec, options=DiagnoseOptions(candidates=["friction", "deadzone", "saturation", "drift"]))
    assert dg.verdict["effects"] == ["friction"] and dg.verdict["status"] == "effect"
    best = dg.effects[0]
    assert best.effect == "friction" and best.shrinkage_ci[0] > 0.5
    fc_newton = EMPS_DRIVE_GAIN * best.parameters["fc"]
    assert 20.4 / 2 < fc_newton < 20.4 * 2  # README (reference inverse model): Fc 20.4 N
    mass = EMPS_DRIVE_GAIN / best.nominal["n0"]
    viscous = mass * best.nominal["d0"]
    assert mass == pytest.approx(95.1, rel=0.25) and viscous == pytest.approx(203.5, rel=0.25)
    deadzone = next(e for e in dg.effects if e.effect == "deadzone")
    assert deadzone.shrinkage < best.shrinkage_ci[0] and not deadzone.accepted


def test_dcmotor_brake_is_a_gain_change_against_the_no_load_model():
    rec = dcmotor_record(shared_path(*DC, "06_dc_step_5_15_05.mat"))
    dg = diagnose_effects(AUTHORS_NO_LOAD, rec,
                          options=DiagnoseOptions(n_null=19, candidates=["delay", "lag", "saturation", "deadzone",
                                                                         "static_nonlinearity", "drift"]))
    assert dg.verdict["effects"] == ["parameter_mismatch"]
    assert not any(e.accepted for e in dg.effects)
    assert dg.refit_shrinkage_ci[0] > 0.9
    gain = dg.refit.plant.dc_gain()
    assert gain / AUTHORS_NO_LOAD.dc_gain() == pytest.approx(0.6, abs=0.05)  # README: the brake cuts ~40 %
    assert gain == pytest.approx(150.5, rel=0.05)  # README 07/parameter.m: loaded gain


def test_dcmotor_saturation_is_clipped_in_the_log_and_the_controller_output_is_rebuilt():
    path = shared_path(*DC, "09_dc_step_20_25_05.mat")
    logged = dcmotor_record(path)
    assert float(np.max(logged.u)) == 24.0 and int(np.sum(logged.u == 24.0)) == 11
    ctrl = dcmotor_controller_output(path)
    assert ctrl.clipped == 11 and ctrl.limit == 24.0
    assert ctrl.rms_unclipped < 0.01  # PID without anti-windup reproduces the log, also after the limit
    over = ctrl.record.u[logged.u == 24.0]
    assert np.all(over > 24.0) and float(np.max(over)) > 40.0  # derivative kick of the 500 rpm setpoint step


def test_dcmotor_saturation_is_named_from_the_clipped_voltage_in_the_record():
    rec = dcmotor_record(shared_path(*DC, "09_dc_step_20_25_05.mat"))
    loaded = Plant.from_string("150.5/(0.1468*s+1)^2", delay=0.035)  # README 07/parameter.m: loaded gain
    dg = diagnose(loaded, rec, candidates=["saturation", "delay"], n_null=5)
    assert dg.verdict["observed"] == ["saturation"]
    (clip,) = dg.clipping
    assert (clip.column, clip.side, clip.level, clip.samples, clip.runs) == ("input", "upper", 24.0, 11, 1)
    assert "already sees it" in dg.summary
    unloaded = diagnose(loaded, dcmotor_record(shared_path(*DC, "09_dc_step_20_25_00.mat")),
                        candidates=["delay"], n_null=3)
    assert unloaded.clipping == ()  # one sample on 24 V in the unloaded run: too few to call it a clip


NO_LOAD = ("06_dc_step_5_15_00.mat", "09_dc_step_20_25_00.mat", "12_dc_step_20_25_00.mat")


@pytest.mark.slow
def test_dcmotor_delay_is_confirmed_by_the_round_robin_over_the_no_load_runs():
    runs = [dcmotor_record(shared_path(*DC, name)) for name in NO_LOAD]
    fit = fit_structure(runs[0], "k/((T1*s+1)*(T2*s+1))", delay=0.0, initial={"k": 245.0, "T1": 0.2, "T2": 0.1},
                        lower={"T1": 0.0, "T2": 0.0})
    p = fit.parameters
    linear = Plant.from_string(f"{p['k']!r}/(({p['T1']!r}*s+1)*({p['T2']!r}*s+1))")
    # every default candidate, as docs/gap.md's command runs it: the resonance's fits without a peak are refused
    d = diagnose_runs(linear, runs, list(DEFAULT_CANDIDATES), names=list(NO_LOAD), n_null=19)
    assert d.verdict["effects"] == ["delay"] and d.verdict["status"] == "effect", d.summary
    assert all("resonance" not in g for g in d.verdict["indistinguishable"])
    best = next(e for e in d.effects if e.effect == "delay")
    assert best.accepted and best.shrinkage_ci[0] > 0.1
    delays = [q["delay"] for q in best.parameters]
    assert all(0.03 < x < 0.045 for x in delays)  # README: Td = 0.035 s in the authors' model
    # one transient per run: trained on a single run, the delay is confirmed in at most one of the three folds
    assert sum(f.verdict["effects"] == ["delay"] for f in d.folds) <= 1


def test_tanks_overflow_is_named_from_the_clipped_level_in_both_records():
    path = shared_path("data", "cascaded_tanks_overflow", "dataBenchmark.csv")
    est, val = tanks_record(path, "est"), tanks_record(path, "val")
    settled = (est.t >= est.t[0] + 200.0).astype(float)  # unknown initial levels: 200 s burn-in
    fit = fit_structure(est, "k/((T1*s+1)*(T2*s+1))", delay=0.0, initial={"k": 4.6, "T1": 250.0, "T2": 30.0},
                        lower={"T1": 0.0, "T2": 0.0}, weights=settled)
    p = fit.parameters
    linear = Plant.from_string(f"{p['k']!r}/(({p['T1']!r}*s+1)*({p['T2']!r}*s+1))")
    dg = diagnose(linear, est, val, candidates=["saturation(output)", "saturation", "static_nonlinearity", "lag"],
                  n_null=19, burn_in=200.0)
    assert dg.verdict["observed"] == ["saturation(output)"]
    assert [(c.record, c.column, c.level, c.samples) for c in dg.clipping] == [
        ("record", "output", 10.0, 47), ("validate", "output", 10.0, 37)]  # README: 47 in yEst, 37 in yVal
    clip_fit = next(e for e in dg.attribution.effects if e.effect == "saturation(output)")
    assert 9.0 < clip_fit.parameters["upper"] <= 10.0 and clip_fit.shrinkage > 0.05
    assert "Adding the output clip to the model shrinks the held-out error" in dg.summary
