"""An infeasible spec names the requirements that conflict, with prices, and returns no solution."""

import json

import pytest

from synth.design import design
from synth.spec import parse_spec

X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"


def test_conflicting_pair_is_named_with_prices():
    # A brute-force scan (stable PI loops, kp <= 20, ki <= 500, 20 ms delay) finds max |S| below
    # 10 rad/s of -12.1 dB at best with Ms <= 6 dB, but only -6.9 dB with Ms <= 3 dB: each requirement
    # can be met alone, not both (the waterbed effect); the bandwidth floor is not part of the conflict.
    spec = parse_spec(f"""
name: conflict
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: PI, bounds: {{kp: [0, 20], ki: [0, 500]}}}}
requirements:
  - {{type: sensitivity, max_db: -10, band: [0, 10]}}
  - {{type: peak_sensitivity, max_db: 3}}
  - {{type: bandwidth, min: 1}}
objective: {{maximize: integral_gain}}
""")
    result = design(spec)
    assert not result.feasible and result.controller is None
    diag = result.extras["diagnosis"]
    assert diag["conflicting"] == ["sensitivity", "peak_sensitivity"]
    by_name = {r["name"]: r for r in diag["requirements"]}
    assert by_name["sensitivity"]["price"] > 0 and by_name["peak_sensitivity"]["price"] > 0
    assert diag["total_elastic_slack"] > 0
    assert "could not meet together): sensitivity, peak_sensitivity" in result.verdict
    assert "do not prove that none exists" in result.verdict  # a search, not a proof
    assert result.compromise is not None and not result.compromise.feasible


def test_relaxing_the_conflict_makes_it_feasible():
    spec = parse_spec(f"""
name: relaxed
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: PI, bounds: {{kp: [0, 20], ki: [0, 500]}}}}
requirements:
  - {{type: sensitivity, max_db: -15, band: [0, 3]}}
  - {{type: peak_sensitivity, max_db: 6}}
objective: {{maximize: integral_gain}}
""")
    result = design(spec)
    assert result.feasible and result.certificate.passed
    assert result.check.requirements[1].value <= -15.0


@pytest.mark.slow
def test_requirement_unreachable_alone_is_the_whole_conflict_and_the_cli_exits_1(run_cli, tmp_path):
    # -15 dB up to 30 rad/s: brute force gives -8.1 dB at best for any stable PI loop with this delay
    path = tmp_path / "alone.yaml"
    path.write_text(f"""name: alone
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: PI, bounds: {{kp: [0, 20], ki: [0, 500]}}}}
requirements:
  - {{type: sensitivity, max_db: -15, band: [0, 30]}}
  - {{type: peak_sensitivity, max_db: 6}}
""")
    res = run_cli("design", str(path), "--out", str(tmp_path / "r"))
    assert res.code == 1 and "INFEASIBLE" in res.out and "Conflicting requirements" in res.out
    assert (tmp_path / "r" / "report.html").exists()
    result = json.loads((tmp_path / "r" / "result.json").read_text())
    assert not result["feasible"] and result["diagnosis"]["conflicting"] == ["sensitivity"]
