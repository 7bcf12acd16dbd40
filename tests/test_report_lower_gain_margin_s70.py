"""The design report's closed-loop table gives both gain limits of a loop that has a lower one (session 70)."""

from __future__ import annotations

import json
import math
import re

import pytest

from synth.cli import main

SPEC = """
name: unstable_p
plant: {tf: "10/((s-1)*(s+5))"}
controller: {type: P, bounds: {kp: [0.6, 10]}}
requirements:
  - {type: margins, phase_margin_deg: 30}
objective: {maximize: low_frequency_gain}
"""


def test_an_unstable_plants_gain_margin_row_shows_the_lower_limit(tmp_path):
    """10/((s - 1)(s + 5)) under P is stable only for kp > 0.5: the row said 'inf dB' (upward only) although the
    loop turns unstable when its gain falls by 19.8 dB at the design's kp = 4.89."""
    spec = tmp_path / "spec.yaml"
    spec.write_text(SPEC)
    out = tmp_path / "out"
    assert main(["design", str(spec), "--out", str(out), "-q"]) == 0
    result = json.loads((out / "result.json").read_text())
    kp = result["controller"]["parameters"]["kp"]
    lower = result["analysis"]["loops"]["design"]["margins"]["lower_gain_margin_db"]
    assert lower == pytest.approx(20 * math.log10(0.5 / kp), abs=1e-3)  # the loop's gain at kp = 0.5
    html = (out / "report.html").read_text()
    row = re.search(r"gain / phase / delay margin</th>(.*?)</tr>", html).group(1)
    assert 'data-json="/analysis/loops/design/margins/lower_gain_margin_db"' in row
    assert f"{lower:.4g}" in row and " dB to " in row
