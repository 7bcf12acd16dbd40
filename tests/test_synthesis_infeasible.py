"""An infeasible spec names the requirements that conflict, with prices, and returns no solution."""


from synth.design import design
from synth.spec import parse_spec

X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"


def test_conflicting_requirements_are_named_with_prices():
    # with a 20 ms loop delay, strong attenuation up to 30 rad/s needs a crossover beyond what
    # a 6 dB peak sensitivity allows (the waterbed effect): the two conflict
    spec = parse_spec(f"""
name: conflict
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: PI, bounds: {{kp: [0, 20], ki: [0, 500]}}}}
requirements:
  - {{type: sensitivity, max_db: -15, band: [0, 30]}}
  - {{type: peak_sensitivity, max_db: 6}}
  - {{type: bandwidth, min: 1}}
objective: {{maximize: integral_gain}}
""")
    result = design(spec)
    assert not result.feasible and result.controller is None
    diag = result.extras["diagnosis"]
    assert set(diag["conflicting"]) == {"sensitivity", "peak_sensitivity"}
    by_name = {r["name"]: r for r in diag["requirements"]}
    assert by_name["sensitivity"]["violated"] and by_name["sensitivity"]["exact_slack"] < 0
    assert not by_name["peak_sensitivity"]["violated"] and by_name["peak_sensitivity"]["price"] > 0
    assert not by_name["bandwidth"]["violated"] and "bandwidth" not in diag["conflicting"]
    assert "Conflicting requirements: sensitivity, peak_sensitivity" in result.verdict
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


def test_infeasible_cli_exit_code(run_cli, tmp_path):
    path = tmp_path / "conflict.yaml"
    path.write_text(f"""name: conflict
plant: {{tf: "{X4}", delay: 0.02}}
controller: {{type: PI, bounds: {{kp: [0, 20], ki: [0, 500]}}}}
requirements:
  - {{type: sensitivity, max_db: -15, band: [0, 30]}}
  - {{type: peak_sensitivity, max_db: 6}}
""")
    res = run_cli("design", str(path), "--out", str(tmp_path / "r"))
    assert res.code == 1 and "INFEASIBLE" in res.out and "Conflicting requirements" in res.out
    assert (tmp_path / "r" / "report.html").exists()
