"""The objective's value in the plant's own units where the spec gives them (the verdicts printed "u/y" and
"u/(y*s)", the documented placeholders, beside "DC gain 0.2845 l/min/%"; a black-box helper, session 69)."""

from __future__ import annotations

import json
from pathlib import Path

import synth

ROOT = Path(__file__).resolve().parents[1]


def test_a_pi_maximizing_its_integral_gain_states_it_in_the_plants_units():
    spec = synth.parse_spec({
        "name": "flow", "plant": {"tf": "2/(s+1)", "input": {"name": "valve", "unit": "%"},
                                  "output": {"name": "flow", "unit": "l/min"}},
        "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}},
        "requirements": [{"type": "peak_sensitivity", "max_db": 6}], "objective": {"maximize": "integral_gain"}})
    result = synth.design(spec)
    assert result.feasible and result.objective["unit"] == "%/((l/min)*s)"
    assert "%/((l/min)*s))" in result.verdict and "u/(y*s)" not in result.verdict


def test_the_committed_lead_lag_report_states_volts_per_rpm():
    data = json.loads((ROOT / "reports" / "dcmotor_leadlag" / "result.json").read_text())
    assert data["objective"]["unit"] == "V/rpm" and "u/y" not in data["verdict"]
    assert "u/y" not in (ROOT / "reports" / "dcmotor_leadlag" / "report.html").read_text().replace('"u/y"', "")
