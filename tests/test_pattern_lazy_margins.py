"""The pattern search on the exact check reads the check's slack only to break ties between equal scores; the
gain margins in that slack are computed only then (synth.synthesis.pattern, synth.check.margin_slack). The search
takes the same path as with every check computing them."""

from __future__ import annotations

import pytest

import synth.synthesis.pattern as pattern
from synth.check import quick_check
from synth.controllers import Controller
from synth.spec import parse_spec

CASES = [
    ({"name": "pi", "plant": {"tf": "10/((s+1)*(s+5))", "delay": 0.05}, "requirements": [
        {"type": "peak_sensitivity", "max_db": 6}], "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 20]}},
      "objective": {"maximize": "integral_gain"}}, Controller("PI", {"kp": 1.0, "ki": 2.0})),
    ({"name": "ll", "plant": {"tf": "4/((s+1)*(s+2)*(s+3))", "delay": 0.1}, "requirements": [
        {"type": "peak_sensitivity", "max_db": 6}, {"type": "margins", "phase_margin_deg": 45}],
      "controller": {"type": "leadlag", "bounds": {"k": [0, 10], "z": [0.1, 10], "p": [0.5, 50]}},
      "objective": {"maximize": "bandwidth"}}, Controller("leadlag", {"k": 1.0, "z": 1.0, "p": 5.0})),
]


@pytest.mark.parametrize("case", range(len(CASES)))
def test_the_search_is_the_same_with_the_margins_left_for_ties(case: int, monkeypatch) -> None:
    raw, start = CASES[case]
    spec = parse_spec(raw)
    terms = [(raw["objective"]["maximize"], "maximize", 1.0)]
    calls = []

    def counted(spec, controller):
        calls.append(controller)
        return margin_slack(spec, controller)

    margin_slack = pattern.margin_slack
    monkeypatch.setattr(pattern, "margin_slack", counted)
    lazy = pattern.pattern_search(spec, start, terms)
    lazy_calls = len(calls)
    # every check with its gain margins in the slack, as before: the same path, the same answer
    monkeypatch.setattr(pattern, "quick_check", lambda spec, c, per_decade, margins=True: quick_check(spec, c, per_decade))
    eager = pattern.pattern_search(spec, start, terms)
    assert lazy.controller.parameters == eager.controller.parameters and lazy.checks == eager.checks
    assert lazy.improved
    assert lazy_calls < 0.5 * lazy.checks, (lazy_calls, lazy.checks)
