"""A PI design that wins without integral action (ki = 0) gets its report: the gain-set figure is drawn over kp
with ki fixed at 0 (it refused the spec as bad input, exit 2, because the figure asked the two-parameter spec for
a one-parameter family)."""

from __future__ import annotations

import json

SPEC = """\
name: pi_without_integral
plant:
  tf: "2/(s*(s+1))"
controller:
  type: PI
  bounds: {kp: [0, 5], ki: [0, 2]}
requirements:
  - {type: peak_sensitivity, max_db: 6}
objective: {maximize: bandwidth}
"""


def test_the_report_of_a_pi_design_without_integral_action_is_written(tmp_path, run_cli):
    spec = tmp_path / "pi.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    out = tmp_path / "report"
    res = run_cli("design", str(spec), "--out", str(out), "-q")
    assert res.code == 0, res.err
    data = json.loads((out / "result.json").read_text())
    assert data["controller"]["parameters"]["ki"] == 0.0
    assert data["gain_set_detail"]["parameter"] == "kp"
    hi = data["gain_set_detail"]["intervals"][-1]["hi"]
    assert abs(data["controller"]["parameters"]["kp"] - hi) < 1e-6 * hi  # bandwidth grows with kp up to |S| = 6 dB
    assert (out / "gain_set.png").stat().st_size > 10_000 and (out / "report.html").exists()
