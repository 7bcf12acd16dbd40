"""Spec files: the issue's exact example loads, and every kind of bad spec gets one clear line and exit 2."""

import textwrap

import pytest

from synth.spec import load_spec

EXAMPLE = """\
name: x4_rotor
description: X-4 Flyer rotor speed loop, plant of seed eq. 5
plant:
  tf: "23*(s+0.43)/((s+9.6)*(s+0.54))"
  delay: 0.0
  input: {name: throttle, unit: PWM}
  output: {name: rotor speed, unit: rad/s}
controller:
  type: P
  bounds: {kp: [0, 20]}
requirements:
  - {type: sensitivity_static, max_db: -15, plant_gain: 1.8}
  - {type: bandwidth, min: 60}
  - {type: slew_rate, rate_limit: 10000, max_error: 5, band: [0.1, 100]}
objective: {maximize: bandwidth}
"""


def test_issue_example_loads(tmp_path):
    path = tmp_path / "x4.yaml"
    path.write_text(EXAMPLE)
    spec = load_spec(path)
    assert spec.name == "x4_rotor"
    assert [r.type for r in spec.requirements] == ["sensitivity_static", "bandwidth", "slew_rate"]
    assert spec.controller.all_bounds()["kp"] == (0.0, 20.0)
    assert spec.objective.name == "bandwidth" and spec.objective.sense == "maximize"
    assert spec.nominal_plant().input.unit == "PWM"


BAD = {
    "unknown key": (EXAMPLE + "colour: red\n", "16: colour: unknown key 'colour'"),
    "unknown nested key": (EXAMPLE.replace("  delay: 0.0", "  dlay: 0.0"), "5: plant.dlay: unknown key 'dlay'; did you mean 'delay'?"),
    "missing field": (EXAMPLE.replace("controller:\n  type: P\n", "controller:\n"), "controller.type: missing (required)"),
    "missing plant model": (EXAMPLE.replace('  tf: "23*(s+0.43)/((s+9.6)*(s+0.54))"\n', ""), "3: plant: give exactly one of 'tf' (a transfer function) or 'identify'"),
    "wrong type": (EXAMPLE.replace("min: 60", "min: sixty"), "13: requirements[1].min: expected a number, got 'sixty'"),
    "negative band": (EXAMPLE.replace("band: [0.1, 100]", "band: [-1, 100]"), "requirements[2].band: band must be non-negative"),
    "reversed band": (EXAMPLE.replace("band: [0.1, 100]", "band: [100, 0.1]"), "requirements[2].band: band must be [low, high] with low < high, got [100, 0.1]"),
    "unparsable tf": (EXAMPLE.replace("((s+9.6)*(s+0.54))", "((s+9.6)*(s+0.54)"), "4: plant.tf: cannot parse transfer function"),
    "improper tf": (EXAMPLE.replace('"23*(s+0.43)/((s+9.6)*(s+0.54))"', '"23*(s+0.43)^3/((s+9.6)*(s+0.54))"'), "plant.tf: transfer function '23*(s+0.43)^3/((s+9.6)*(s+0.54))' is improper"),
    "unknown requirement": (EXAMPLE.replace("type: bandwidth", "type: bandwith"), "13: requirements[1].type: unknown requirement type 'bandwith'"),
    "unknown controller": (EXAMPLE.replace("type: P\n", "type: PD\n"), "9: controller.type: unknown controller type 'PD'"),
    "reversed bounds": (EXAMPLE.replace("[0, 20]", "[20, 0]"), "10: controller.bounds: kp: lower bound 20 is above upper bound 0"),
    "empty requirements": (EXAMPLE.split("requirements:")[0] + "requirements: []\n", "requirements: the requirement list is empty"),
    "not yaml": ("name: [x\n", "invalid YAML"),
    "key twice": (EXAMPLE + "plant: {tf: \"1/(s+1)\"}\n", "16: invalid YAML: key 'plant' given twice (first on line 3)"),
    "bound twice": (EXAMPLE.replace("{kp: [0, 20]}", "{kp: [0, 20], kp: [0, 3]}"),
                    "10: invalid YAML: key 'kp' given twice (first on line 10)"),
    "empty file": ("", "the spec file is empty"),
}


@pytest.mark.parametrize("kind", sorted(BAD))
def test_bad_spec_one_line_exit_2(kind, tmp_path, run_cli):
    text, fragment = BAD[kind]
    path = tmp_path / "bad.yaml"
    path.write_text(textwrap.dedent(text))
    for cmd in (["check", str(path), "--controller", "P(3)"], ["design", str(path), "--out", str(tmp_path / "r")]):
        res = run_cli(*cmd)
        assert res.code == 2, res.err
        assert res.out == ""
        lines = res.err.strip().splitlines()
        assert len(lines) == 1, res.err
        assert str(path) in lines[0] and fragment in lines[0], lines[0]
        assert "Traceback" not in res.err
    assert not (tmp_path / "r").exists()


def test_missing_file(run_cli, tmp_path):
    res = run_cli("check", str(tmp_path / "nope.yaml"), "--controller", "P(3)")
    assert res.code == 2 and "spec file not found" in res.err


def test_bad_controller_text(run_cli):
    res = run_cli("check", "specs/x4_rotor.yaml", "--controller", "P(3")
    assert res.code == 2 and res.err.startswith("synth check: error: --controller: cannot parse controller")


def test_spec_files_in_repo_load():
    from pathlib import Path

    for path in sorted(Path("specs").glob("*.yaml")):
        assert load_spec(path).name == path.stem
