"""The report's "Stability if the delay is in the loop" table on an open-loop unstable plant: every row said
"critical gain 0, UNSTABLE" for a P design the same report called stable (the smallest gains leave such a loop
unstable, so no stable range starts at 0). Now each row gives the stabilizing range; the numbers are a black-box
helper's (session 69), from the exact L(jw) e^(-jw T) and its negative-real-axis crossings."""

from __future__ import annotations

import json
import re

import pytest

from synth.plant import Plant
from synth.synthesis.gainset import critical_gains

SPEC = """name: unstable_p
plant: {tf: "10/((s-1)*(s+5))", delay: 0.02, input: {name: force, unit: N}, output: {name: angle, unit: deg}}
controller: {type: P, bounds: {kp: [0, 10]}}
requirements: [{type: margins, gain_margin_db: 4}, {type: bandwidth, min: 2}]
objective: {minimize: peak_sensitivity}
"""


def test_each_delay_row_gives_the_stabilizing_range_and_the_design_is_stable_in_it(run_cli, tmp_path):
    spec = tmp_path / "unstable_p.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    res = run_cli("design", str(spec), "--out", str(tmp_path / "out"), "-q")
    assert res.code == 0, res.err
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    table = data["analysis"]["delay_table"]
    # the helper's ranges for 0, 5, 10, 15, 20 ms on top of the plant's 20 ms: (0.5, k) with k below
    assert [r["critical_gain"] for r in table] == pytest.approx([20.26, 16.25, 13.58, 11.68, 10.24], abs=0.01)
    assert all(r["lowest_gain"] == pytest.approx(0.5, abs=1e-3) for r in table)
    assert data["analysis"].get("delay_warning") is None
    html = re.sub(r"<[^>]+>", " ", (tmp_path / "out" / "report.html").read_text())
    rows = html.split("in-loop delay [ms]")[1].split("Certificate")[0]
    assert rows.count("stable") == 5 and "UNSTABLE" not in rows and "lowest stabilizing gain" in rows


def test_a_gain_below_the_range_is_warned_about_and_a_stable_plant_starts_at_zero():
    from synth.controllers import Controller
    from synth.reference import delay_warning

    table = critical_gains(Plant.from_string("10/((s-1)*(s+5))"), [0.0, 0.02])
    warning = delay_warning(Controller("P", {"kp": 0.4}), table, {})
    assert warning is not None and "between 0.5 and" in warning
    assert delay_warning(Controller("P", {"kp": 1.0}), table, {}) is None
    x4 = critical_gains(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), [0.02])[0]
    assert x4["lowest_gain"] == 0.0 and x4["critical_gain"] == pytest.approx(3.69, abs=0.01)
