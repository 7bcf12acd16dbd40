"""The X-4 sim-to-real case: the simulated rig's step train diagnosed against eq. 5, and the paper's numbers."""

import pytest

from synth.gap.x4_case import gap_case_applies, x4_gap_case
from synth.spec import load_spec

pytestmark = pytest.mark.xdist_group("gap_x4_case")  # one worker diagnoses the case once for the module's tests


@pytest.fixture(scope="module")
def case():
    return x4_gap_case(load_spec("specs/x4_rotor.yaml"))


def test_rig_record_uses_the_limits(case):
    rec = case["record"]
    assert rec["samples"] == 1051 and rec["dt"] == pytest.approx(0.002)
    assert rec["command_range"][1] > 255 and rec["command_range"][0] < 0  # K = 3 x 100 rad/s leaves 0-255 PWM
    assert rec["time_rate_limited"] > 0.1 and rec["time_saturated"] > 0.1
    assert case["truth"] == {"rate": 10000.0, "upper": 55.0, "lower": -200.0}


def test_diagnosis_attributes_an_actuator_limit(case):
    d = case["diagnosis"]
    assert d["gap"]["nrmse"] > 0.5  # the command's spikes through the linear model miss badly
    assert d["where"]["time_windows"] and "rise" in d["headline"]
    assert d["verdict"]["status"] == "effect" and d["verdict"]["effects"][0] in ("saturation", "rate_limit")
    best = next(e for e in d["effects"] if e["accepted"])
    assert best["shrinkage_ci"][0] > d["threshold"]


def test_rise_times_and_poles(case):
    assert case["rise_time"]["linear_model"] == pytest.approx(0.0243, abs=0.001)
    assert case["rise_time"]["simulated_rig"] == pytest.approx(0.052, abs=0.002)
    assert case["poles"]["model_fast_pole"] == pytest.approx(78.697, abs=0.01)
    assert case["poles"]["published"][-1]["fast_pole"] == pytest.approx(99.0)
    # (99 + 0.0042 - 9.6 - 0.54) / 3
    assert case["poles"]["plant_gain_for_measured_poles"] == pytest.approx(29.6214, abs=1e-4)
    assert case["poles"]["plant_gain_from_eq15_numerator"] == pytest.approx(83 / 3)
    text = " ".join(case["statements"])
    assert "Not explained by a rate limit or a saturation" in text and "k = 29.6" in text


def test_case_applies_only_to_the_seed_p_spec():
    assert gap_case_applies(load_spec("specs/x4_rotor.yaml"))
    for name in ("x4_rotor_pi", "x4_rotor_strict", "x4_rotor_from_data", "dcmotor_leadlag"):
        assert not gap_case_applies(load_spec(f"specs/{name}.yaml")), name
