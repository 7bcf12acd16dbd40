"""The design report's nonlinear step check says what the step ends in on the evidence of a run long enough to
decide (synth.sim.verdict.step_verdict), not on the horizon it plots.

specs/x4_rotor_pi.yaml's design, PI(kp=7.13323, ki=1868.25), saturates the 0-255 PWM actuator on its 820 -> 920
rad/s step and winds up; its report said "settles without a limit cycle" from the 1 s it shows, where the output
was still rising past 1000 rad/s. Run on, the step ends in a cycle of about 308 rad/s every 8 s, which the
independent reference of benchmarks/sim_reference.py (written without synth; no sample-and-hold or quantized
sensor there, the loop in deviations from the 820 rad/s rest) finds too.
"""

import pytest

from benchmarks.sim_reference import reference_run
from synth.controllers import Controller
from synth.report.simulation_report import simulation_report
from synth.spec import load_spec

DESIGN = Controller("PI", {"kp": 7.13323, "ki": 1868.25})


@pytest.fixture(scope="module")
def report():
    return simulation_report(load_spec("specs/x4_rotor_pi.yaml"), DESIGN, Controller("P", {"kp": 3.0}))


def test_a_wound_up_pi_is_reported_as_the_limit_cycle_it_ends_in(report):
    design = report.data["runs"]["design"]
    verdict = design["step_verdict"]
    assert verdict["verdict"] == "limit_cycle" and verdict["evidence"]["horizon"] > report.data["horizon"]
    dc_gain = 23.0 * 0.43 / (9.6 * 0.54)
    rest = 200.0 + (820.0 - 870.0) / dc_gain  # the actuator at the 820 rad/s the step starts from
    ref = reference_run({"plant": {"num": [23.0, 9.89], "den": [1.0, 10.14, 5.184]}, "delay": 0.0,
                         "controller": {"type": "PI", **DESIGN.parameters},
                         "actuator": [["rate_limit", {"rate": 10000.0}],
                                      ["saturation", {"min": -rest, "max": 255.0 - rest}]],
                         "sensor": [], "dt": 0.001, "step": 100.0, "t_step": 0.0}, horizon=128.0, longest=128.0)
    assert ref["verdict"] == "limit_cycle"
    assert verdict["limit_cycle"]["amplitude"] == pytest.approx(ref["amplitude"], rel=0.01)
    assert verdict["limit_cycle"]["period"] == pytest.approx(ref["period"], rel=0.02)
    # no final value, so nothing measured towards one on the run shown
    assert all(design["nonlinear"][k] is None for k in ("rise_time", "overshoot", "settling_time", "final_value"))
    assert "ends in a sustained oscillation of 308.3 rad/s" in report.data["verdict"]
    assert report.data["design_warning"].startswith("Nonlinear step check: the design's simulated step 820 -> 920")


def test_a_step_that_settles_keeps_its_measured_numbers(report):
    p3 = report.data["runs"]["reference"]
    assert p3["step_verdict"]["verdict"] == "settled"
    # towards the final value of the verdict's 8 s run (the 1 s run shown ends 1.3 rad/s above it, under the sensor's
    # 1.2 rad/s quantizer); the seed paper measured 0.05 s
    assert p3["nonlinear"]["rise_time"] == pytest.approx(0.05104, abs=5e-5)
    assert p3["step_verdict"]["evidence"]["horizon"] >= 6.3  # the linear loop settles after 6.3 s
    assert p3["nonlinear"]["final_value"] == pytest.approx(p3["step_verdict"]["final_value"], abs=1e-6)
    assert ("The reference P(kp=3) settles without a limit cycle (settled on a run of 8 s, beyond the 1 s shown)"
            in report.data["verdict"])
