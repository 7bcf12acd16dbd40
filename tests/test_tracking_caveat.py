"""A design whose loop barely follows the reference says so in its headline verdict (issue 15, item 5).

A black-box finding: minimize control effort with only margins and an overshoot limit, and the best design is a
controller that does almost nothing (``PI(kp=5e-06, ki=0)``, |T(0)| = -104 dB). The verdict said "meets all 2
requirements"; only the step requirement's note, further down, said the loop follows a reference to 6e-06 of it.
"""

from __future__ import annotations

import json

import pytest

from synth.controllers import Controller
from synth.design import design, design_jobs, with_tracking_caveat
from synth.results import DesignResult
from synth.spec import parse_spec

IDLE_P = {"name": "idle_p", "plant": {"tf": "5/((s+1)*(s+4))", "delay": 0.05},
          "requirements": [{"type": "margins", "gain_margin_db": 6, "phase_margin_deg": 45}],
          "controller": {"type": "P", "bounds": {"kp": [0, 10]}},
          "objective": {"minimize": "control_effort"}}


def _caveats(verdict: str) -> int:
    return verdict.count("follows a slow reference to only")


def test_a_design_that_barely_acts_says_so_in_the_verdict_and_the_json(tmp_path, run_cli) -> None:
    import yaml

    path = tmp_path / "idle_p.yaml"
    path.write_text(yaml.safe_dump(IDLE_P), encoding="utf-8")
    res = run_cli("design", str(path), "--no-report", "--json", str(tmp_path / "r.json"))
    assert res.code == 0, res.err
    headline = res.out.splitlines()[1]
    assert _caveats(headline) == 1 and "|T(0)| = -" in headline
    data = json.loads((tmp_path / "r.json").read_text())
    assert _caveats(data["verdict"]) == 1
    assert data["controller"]["parameters"]["kp"] < 1e-6  # the design really is idle: the caveat is about it


def test_one_parameter_and_combined_jobs_say_it_once() -> None:
    spec = parse_spec(IDLE_P)
    result = design(spec)
    assert result.feasible and _caveats(result.verdict) == 1
    jobs, combine = design_jobs(spec)
    assert _caveats(combine([job() for job in jobs]).verdict) == 1


def test_the_caveat_joins_a_verdict_once_before_its_full_stop() -> None:
    """The several-parameter path (a PI minimizing control effort ends at kp = 5e-06, ki = 0 after 30 s of the
    polish's crawl towards kp = 0: the result is built here instead)."""
    spec = parse_spec({**IDLE_P, "controller": {"type": "PI", "bounds": {"kp": [0, 10], "ki": [0, 20]}}})
    idle = DesignResult("idle_pi", True, Controller("PI", {"kp": 5e-6, "ki": 0.0}), None, None, None, None,
                        verdict="PI(kp=5e-06, ki=0) meets all 1 requirements and keeps the loop stable.")
    once = with_tracking_caveat(spec, with_tracking_caveat(spec, idle)).verdict
    assert _caveats(once) == 1 and once.endswith("such designs.") and "stable; but its loop" in once
    assert "only 6.25e-06 of it (|T(0)| = -104 dB)" in once  # kp G(0) = 5e-6 * 5/4
    tracking = DesignResult("pi", True, Controller("PI", {"kp": 5e-6, "ki": 1e-6}), None, None, None, None,
                            verdict="ok.")
    assert with_tracking_caveat(spec, tracking).verdict == "ok."  # integral action: T(0) = 1
    failed = DesignResult("pi", False, None, None, None, None, None, verdict="infeasible.")
    assert with_tracking_caveat(spec, failed).verdict == "infeasible."


def test_a_loop_with_enough_gain_has_no_caveat() -> None:
    loud = design(parse_spec({**IDLE_P, "name": "p", "objective": {"maximize": "crossover"}}))
    assert loud.controller.parameters["kp"] > 1.0 and _caveats(loud.verdict) == 0  # |T(0)| = 1.25 k / (1 + 1.25 k)


def test_a_pi_kept_without_integral_action_says_so_in_its_verdict() -> None:
    """A black-box test: a PI design that ended at ki = 0 read as a design of kp alone ("the objective minimized over
    the exact feasible set of kp"), though ki was free; the verdict now says the design without integral action
    was kept, and against what."""
    spec = parse_spec({"name": "effort", "plant": {"tf": "(3*s+3)/(s^4+10.5*s^3+46*s^2+70.5*s+25)", "delay": 0.1},
                       "controller": {"type": "PI", "bounds": {"kp": [0, 20], "ki": [0, 20]}},
                       "requirements": [{"type": "bandwidth", "min": 0.8}, {"type": "peak_sensitivity", "max_db": 6}],
                       "objective": {"minimize": "control_effort"}})
    result = design(spec)
    assert result.feasible and result.controller.parameters["ki"] == 0.0
    kept = result.verdict.split("The design without integral action (ki = 0) was kept: ")[1]
    mine, theirs = (float(x) for x in kept.split(" dB with ki free")[0].split(" against "))
    assert mine == pytest.approx(result.objective["value"], rel=1e-5) and mine <= theirs


@pytest.mark.parametrize("plant, kp, says", [
    # an unstable plant under P control: L(0) = -2.358, T(0) = 2.358 / 1.358 = 1.7365 (a black-box test's case: its
    # step overshoot 2.2 % "met", measured from a final value 74 % beyond the reference, with no word of it)
    ("2.4/((s-0.5)*(s+3))", 1.47361, "follows a slow reference to 1.74 of it, settling 73.6 % beyond it"),
    # L(0) = -0.6: T(0) = -0.6 / 0.4 = -1.5, the output moves against the reference
    ("-2/(s+1)", 0.3, "moves against a slow reference, to 1.5 of it with the opposite sign"),
])
def test_a_loop_that_settles_beyond_or_against_the_reference(plant, kp, says) -> None:
    from synth.loop import Loop
    from synth.plant import Plant
    from synth.requirements import Bandwidth
    from synth.requirements.tracking import tracking_caveat

    loop = Loop(Plant.from_string(plant), Controller("P", {"kp": kp}))
    assert says in Bandwidth(min=0.01).evaluate(loop).message
    assert says in tracking_caveat(loop)
    within = Loop(Plant.from_string("2/(s+1)"), Controller("P", {"kp": 3.0}))  # T(0) = 6/7: -1.3 dB, no note
    assert tracking_caveat(within) == "" and "slow reference" not in Bandwidth(min=0.01).evaluate(within).message
