"""Simulation verdicts a black-box helper (session 69) found wrong, each against the helper's own exact
zero-order-hold simulation of the same loop (numbers quoted from it; none computed by synth):

- a PI behind a relay-like table and a backlash chattered with period 0.02 s while its command wound towards the
  relay's threshold; synth called that a limit cycle at 6.6 s, where the chatter ends and the output rests at
  -22.7266 for good (the reference's 30 s run);
- a lead-lag on an unstable plant behind a saturation: a limit cycle whose centre still moved was measured with
  its centre at 3.7 (the reference's 500 s run: 4.104);
- a cycle's period range reached 1.09 s for cycles of 0.1-0.11 s (the lag at which the record repeats);
- a step inside a backlash's play printed a rise time and an overshoot for an output that never moved;
- a relay built as a table with flat ends held the output 33 % short of the reference without a word."""

from __future__ import annotations

import json
import math

import pytest

RELAY = """    - type: static
      table: [[-1000000.0, -26.79], [-0.03116, -26.79], [0.03116, 26.79], [1000000.0, 26.79]]
    - {type: backlash, width: 8.342}"""


def spec(tmp_path, plant: str, dt: float, actuator: str, step: str, sensor: str = "[]", delay: float = 0.0,
         kind: str = "PI"):
    path = tmp_path / "loop.yaml"
    path.write_text(f"""name: loop
plant: {{tf: "{plant}", delay: {delay}}}
controller: {{type: {kind}}}
requirements: [{{type: margins, gain_margin_db: 1}}]
simulation:
  dt: {dt}
  actuator:
{actuator}
  sensor: {sensor}
  step: {step}
""", encoding="utf-8")
    return path


def simulate(run_cli, tmp_path, path, controller: str, *extra: str) -> tuple[int, dict, str]:
    out = tmp_path / "result.json"
    res = run_cli("simulate", str(path), "-c", controller, "--json", str(out), "--out", str(tmp_path / "o"), "-q",
                  *extra)
    return res.code, json.loads(out.read_text()) if out.exists() else {}, res.out + res.err


def test_a_chatter_whose_command_still_winds_is_not_a_limit_cycle(run_cli, tmp_path):
    path = spec(tmp_path, "(0.954994*s-3.0512)/(1*s+3.03675)", 0.01, RELAY, "[0, 2.397]")
    code, data, text = simulate(run_cli, tmp_path, path, "PI(kp=1.3, ki=1.43076)")
    assert data["verdict"] == "settled" and code == 0, text
    assert data["final_value"] == pytest.approx(-22.7266, abs=1e-3)
    assert "stands still" in data["evidence"]["criterion"]  # far from the reference 2.397: said, with its cause


def test_a_cycle_whose_centre_still_moves_is_measured_once_it_stops(run_cli, tmp_path):
    path = spec(tmp_path, "1.61833/(1*s-1.27239)", 0.005, "    - {type: saturation, min: -292.7878, max: 424.7195}",
                "[0, -1.688]", delay=0.013306, kind="leadlag")
    code, data, text = simulate(run_cli, tmp_path, path, "leadlag(k=91.3755, z=3.07226, p=25.1119)")
    lc = data["limit_cycle"]
    assert data["verdict"] == "limit_cycle" and code == 1, text
    assert lc["center"] == pytest.approx(4.104, abs=0.05)  # was 3.7
    assert lc["amplitude_range"][0] <= 5.621 * 1.01 and lc["amplitude"] == pytest.approx(5.621, rel=0.02)


def test_the_period_range_holds_cycle_lengths_only(run_cli, tmp_path):
    plant = "(1.21186*s^3+11.1649*s^2+12.1319*s+3.51973)/(1*s^3+7.641*s^2+13.9308*s+4.40231)"
    path = spec(tmp_path, plant, 0.01, "    - {type: saturation, min: -5.3583, max: 3.5279}", "[0, -1.561]",
                sensor="[{type: sample_hold, rate: 18.35}]")
    code, data, text = simulate(run_cli, tmp_path, path, "PI(kp=0.9, ki=0.182658)")
    lc = data["limit_cycle"]
    assert data["verdict"] == "limit_cycle" and code == 1, text
    assert lc["period_range"][1] <= 0.111 and lc["period"] == pytest.approx(0.109, rel=0.01)  # was up to 1.09 s


def test_a_step_inside_the_backlash_play_moves_nothing_and_says_so(run_cli, tmp_path):
    path = spec(tmp_path, "(2.55844*s-19.2432)/(1*s^2+18.7728*s+5.94242)", 0.001,
                "    - {type: backlash, width: 423.5}", "[0.356, -0.22]", sensor="[{type: sample_hold, rate: 182.6}]",
                delay=0.001101, kind="P")
    code, data, text = simulate(run_cli, tmp_path, path, "P(kp=272.884)")
    assert data["verdict"] == "settled" and code == 0, text
    assert all(data[k] is None or math.isnan(data[k]) for k in ("rise_time", "overshoot"))
    assert data["settling_time"] is None
    assert "did not move" in data["evidence"]["criterion"]
    res = run_cli("simulate", str(path), "-c", "P(kp=272.884)", "--out", str(tmp_path / "o2"))
    assert "n/a: the output does not move" in res.out


def test_a_relay_table_that_holds_the_output_short_says_how_far(run_cli, tmp_path):
    path = spec(tmp_path, "1/(s+1)", 0.001,
                "    - {type: static, table: [[-1000, -2], [-0.001, -2], [0.001, 2], [1000, 2]]}", "[0, 3]")
    code, data, text = simulate(run_cli, tmp_path, path, "PI(kp=1, ki=1)")
    assert data["verdict"] == "settled" and code == 0, text
    assert data["final_value"] == pytest.approx(2.0, abs=1e-6)
    assert "33.3 % of the step short of the reference 3" in data["evidence"]["criterion"]


@pytest.mark.parametrize(("extra", "message"), [
    (("--horizon", "0.01"), "--horizon: dt 0.001 s must be at most 1/20 of the horizon"),
    (("--horizon", "10", "--max-horizon", "1"), "--max-horizon: must be at least the horizon (10 s)"),
    (("--step-time", "1e12"), "--step-time: 1e+12 s is 1e+15 samples")])
def test_horizons_the_spec_would_refuse_are_refused_on_the_command_line(run_cli, tmp_path, extra, message):
    path = spec(tmp_path, "1/(s+1)", 0.001, "    - {type: saturation, min: -1, max: 1}", "[0, 0.5]", kind="P")
    res = run_cli("simulate", str(path), "-c", "P(2)", "--out", str(tmp_path / "o"), *extra)
    lines = res.err.strip().splitlines()
    assert res.code == 2 and len(lines) == 1 and message in lines[0], res.err
