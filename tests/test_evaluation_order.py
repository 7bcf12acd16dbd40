"""A requirement's value does not depend on what was evaluated before it in the same process.

The describing-function requirement keeps each plant's critical factor with the controller's gain divided out
(one evaluation per plant for a whole gain sweep). It used to divide the first loop's response by that loop's
gain, so the kept factor, and every later value, moved in its last digits with the gain that came first: the
README's main job wrote kp = 3.65879489765 on a first run and 3.65879492864 on a second in the same process.
Each order runs in a fresh interpreter here, so nothing is kept between them.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

CODE = textwrap.dedent("""
    import sys
    from synth.loop import Loop
    from synth.requirements.no_limit_cycle import NoLimitCycle
    req = NoLimitCycle(delay=(0.0, 0.02), actuator=[{"type": "rate_limit", "rate": 10000},
                       {"type": "saturation", "min": 0, "max": 255}], confirm=False)
    for kp in sys.argv[1:]:
        value = req.evaluate(Loop("23*(s+0.43)/((s+9.6)*(s+0.54))", f"P({kp})")).value
    print(repr(value))
""")


def _last_value(*gains: str) -> str:
    return subprocess.run([sys.executable, "-c", CODE, *gains], capture_output=True, text=True,
                          check=True).stdout.strip()


def test_the_describing_function_margin_is_the_same_whichever_gain_came_first() -> None:
    alone = _last_value("3.6587948976")
    assert float(alone) > 0  # a margin was computed
    assert _last_value("2.1", "3.6587948976") == alone
    assert _last_value("7.3", "3.6587948976") == alone
