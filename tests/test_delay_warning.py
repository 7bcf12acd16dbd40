"""The design report's verdict says when the design is unstable at a delay of the spec's delay table.

specs/x4_rotor.yaml's design, P(kp=20), meets its three requirements with no delay in the loop, and its report's
verdict said so without a word that 5 ms of in-loop delay makes it unstable (its delay table marked it UNSTABLE
there; the identified plant has 20 ms; a black-box review). Independent numbers: the continuous loop's delay
margin is PM/wc at its one gain crossover.
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.controllers import Controller
from synth.reference import compare
from synth.spec import load_spec


def _delay_margin(kp: float) -> float:
    w = np.logspace(1, 4, 400001)
    L = kp * 23 * (1j * w + 0.43) / ((1j * w + 9.6) * (1j * w + 0.54))
    k = int(np.argmin(np.abs(np.abs(L) - 1)))
    return float((np.pi + np.angle(L[k])) / w[k])


def test_the_design_unstable_with_5_ms_says_so():
    out = compare(load_spec("specs/x4_rotor.yaml"), Controller("P", {"kp": 20.0}))
    warning = out["delay_warning"]
    assert warning.startswith("P(kp=20) is unstable with 5 ms of delay in the loop (critical gain 13.9")
    assert f"its exact delay margin is {1000 * _delay_margin(20.0):.3g} ms" in warning  # 3.46 ms


def test_a_design_stable_over_the_table_has_no_warning():
    out = compare(load_spec("specs/x4_rotor.yaml"), Controller("P", {"kp": 3.0}))
    assert out["delay_warning"] is None
    assert _delay_margin(3.0) > 0.02  # 25 ms: stable over the whole 0-20 ms table
    assert out["loops"]["design"]["margins"]["delay_margin"] == pytest.approx(_delay_margin(3.0), rel=1e-4)
