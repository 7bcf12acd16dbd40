"""``quick_check`` gives ``check``'s verdict and smallest slack on random loops (it only leaves out the work a
failure makes unnecessary: the gain margins and the requirements after the first that fails)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.check import check, quick_check
from synth.controllers import Controller
from synth.spec import parse_spec

REQUIREMENTS = [
    {"type": "sensitivity", "max_db": -6, "band": [0.01, 0.5]},
    {"type": "peak_sensitivity", "max_db": 6},
    {"type": "margins", "gain_margin_db": 6, "phase_margin_deg": 40},
    {"type": "bandwidth", "min": 0.5},
    {"type": "step_response", "max_overshoot": 15},
]


def _case(seed: int) -> tuple[dict, Controller]:
    rng = np.random.default_rng(seed)
    poles = -(10.0 ** rng.uniform(-0.7, 1.0, int(rng.integers(1, 4))))
    if rng.random() < 0.2:
        poles[0] = -poles[0] * 0.3  # an open-loop unstable pole
    den = np.poly(poles)
    gain = float(10.0 ** rng.uniform(-0.3, 0.7)) * abs(den[-1])
    terms = " + ".join(f"{c:.9g}*s^{len(den) - 1 - i}" for i, c in enumerate(den))
    delay = float(rng.choice([0.0, 0.0, 0.02, 0.1]))
    chosen = [REQUIREMENTS[i] for i in sorted(rng.choice(len(REQUIREMENTS), int(rng.integers(1, 4)), replace=False))]
    kind = "PI" if rng.random() < 0.6 else "PID"
    params = {"kp": float(rng.uniform(0, 3)), "ki": float(rng.uniform(0, 3))}
    if kind == "PID":
        params |= {"kd": float(rng.uniform(0, 0.5)), "tf": 0.02}
    spec = {"name": f"q{seed}", "plant": {"tf": f"{gain:.9g}/({terms})", "delay": delay},
            "controller": {"type": kind}, "requirements": chosen}
    return spec, Controller(kind, params)


@pytest.mark.parametrize("seed", range(40))
def test_quick_check_is_checks_verdict_and_slack(seed: int):
    spec_dict, controller = _case(seed)
    spec = parse_spec(spec_dict)
    with np.errstate(all="ignore"):
        full = check(spec, controller)
        quick = quick_check(spec, controller)
    assert quick.feasible == full.feasible
    if full.feasible:
        assert quick.min_slack == min(r.slack for r in full.requirements)
    else:
        assert quick.min_slack == -np.inf


def test_the_sample_holds_both_verdicts():
    verdicts = set()
    for seed in range(40):
        spec_dict, controller = _case(seed)
        with np.errstate(all="ignore"):
            verdicts.add(check(parse_spec(spec_dict), controller).feasible)
    assert verdicts == {True, False}
