"""A plant variant's own ``exp(-tau*s)`` in its ``tf`` adds to its ``delay`` (docs/spec-format.md, ``variants``).

A black-box helper (session 74, robust designs against its own reference) found the variant's ``delay`` replacing
the delay written in its own ``tf``: ``tf: ...*exp(-0.2*s)`` with ``delay: 0.1`` was checked behind 0.1 s instead
of 0.3 s, with ``delay: 0`` behind none, and a phase-margin requirement the 0.3 s loop misses was "met".
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.check import check
from synth.controllers import Controller
from synth.spec import parse_spec

RATIONAL = "1/((s+1)*(s+2))"


def _spec(phase_margin: float, others: bool = True) -> str:
    more = ("\n    - {label: delay_only, delay: 0.3}"
            f'\n    - {{label: gain_and_tf, gain: 2, tf: "{RATIONAL}"}}') if others else ""
    return f"""
name: variant_delays
plant:
  tf: "{RATIONAL}"
  delay: 0.05
  variants:
    - {{label: own_exp_and_delay, tf: "{RATIONAL}*exp(-0.2*s)", delay: 0.1}}
    - {{label: own_exp_no_delay, tf: "{RATIONAL}*exp(-0.2*s)"}}
    - {{label: own_exp_delay_zero, tf: "{RATIONAL}*exp(-0.2*s)", delay: 0}}{more}
controller: {{type: P, bounds: {{kp: [0, 10]}}}}
requirements:
  - {{type: margins, phase_margin_deg: {phase_margin}}}
"""


def _phase_margin(k: float, delay: float) -> float:
    """Of ``k/((s+1)(s+2)) e^(-delay s)``: the crossover from ``(w^2 + 1)(w^2 + 4) = k^2``."""
    w = np.sqrt((-5 + np.sqrt(9 + 4 * k * k)) / 2)
    return 180.0 - np.degrees(np.arctan(w) + np.arctan(w / 2) + w * delay)


def test_every_variant_has_the_delay_its_keys_add_up_to() -> None:
    plants = {p.label: p for p in parse_spec(_spec(45)).plants()}
    assert plants["nominal"].delay == pytest.approx(0.05)
    assert plants["own_exp_and_delay"].delay == pytest.approx(0.3)
    assert plants["own_exp_no_delay"].delay == pytest.approx(0.25)  # the nominal's 0.05 and its own 0.2
    assert plants["own_exp_delay_zero"].delay == pytest.approx(0.2)
    assert plants["delay_only"].delay == pytest.approx(0.3)
    assert plants["gain_and_tf"].dc_gain() == pytest.approx(1.0)  # 2 x the variant's own tf (its DC gain 1/2)
    assert plants["gain_and_tf"].delay == pytest.approx(0.05)


def test_a_phase_margin_the_longest_delay_misses_is_not_met() -> None:
    required = 0.5 * (_phase_margin(3.0, 0.25) + _phase_margin(3.0, 0.3))  # met behind 0.25 s, missed behind 0.3 s
    res = check(parse_spec(_spec(required, others=False)), Controller("P", {"kp": 3.0}))
    assert not res.feasible
    margins = {r.type: r for r in res.requirements}["margins"]
    assert margins.details["phase_margin_deg"] == pytest.approx(_phase_margin(3.0, 0.3), abs=0.05)
