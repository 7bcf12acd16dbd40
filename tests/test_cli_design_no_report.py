"""``synth design --no-report`` runs a PI's two designs (with and without integral action) on both cores, as the
report path does, and returns what the library's ``synth.design`` returns: the better of the two. Here the one
without integral action wins (PI(kp=5, ki=0) against PI(kp=5, ki=5)), so a path that kept only the first job's
design would differ."""

from __future__ import annotations

import io
import json
from contextlib import redirect_stdout
from pathlib import Path

from synth.cli import main
from synth.design import design, design_jobs
from synth.spec import load_spec

SPEC = """name: pi_two_jobs
plant: {tf: "10/((s+1)*(s+5))"}
controller: {type: PI, bounds: {kp: [0, 5], ki: [0, 5]}}
requirements:
  - {type: peak_sensitivity, max_db: 6}
objective: {maximize: bandwidth}
"""


def test_no_report_design_is_the_library_design_of_both_jobs(tmp_path: Path) -> None:
    spec_file = tmp_path / "pi.yaml"
    spec_file.write_text(SPEC)
    out = tmp_path / "out.json"
    with redirect_stdout(io.StringIO()):
        assert main(["design", str(spec_file), "--no-report", "--json", str(out), "--quiet"]) == 0
    got = json.loads(out.read_text())
    spec = load_spec(spec_file)
    expected = design(spec)
    jobs, _ = design_jobs(spec)
    assert len(jobs) == 2
    assert got["controller"]["parameters"] == expected.controller.parameters == {"kp": 5.0, "ki": 0.0}
    assert got["verdict"] == expected.verdict
    assert jobs[0]().controller.parameters["ki"] > 0  # the first job alone: the design with integral action
