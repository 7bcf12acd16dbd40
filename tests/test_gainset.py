"""The exact feasible gain set, against a dense brute-force scan."""

import numpy as np
import pytest

from synth.check import check
from synth.design import design
from synth.plant import Plant
from synth.spec import load_spec, parse_spec
from synth.synthesis.gainset import ScalarFamily, critical_gains, feasible_gain_set

from .conftest import X4_PLANT


def test_x4_gain_set_and_seed_minimum_gain():
    spec = load_spec("specs/x4_rotor.yaml")
    gs = feasible_gain_set(list(spec.requirements), spec.plants(), ScalarFamily("P", "kp", {}), (0, 20))
    assert len(gs.intervals) == 1
    iv = gs.intervals[0]
    assert iv.lo == pytest.approx((10 ** (15 / 20) - 1) / 1.8, abs=1e-9)  # closed form
    assert iv.lo == pytest.approx(2.57, abs=0.01)
    assert iv.lo_binding == ["sensitivity_static"]
    assert iv.hi == 20.0 and "slew_rate" in iv.hi_binding
    assert gs.contains(3.0)
    bw = gs.per_requirement["bandwidth"][0][0]
    assert bw == pytest.approx(1.99, abs=0.01)


def _brute_force(spec, ks):
    return np.array([check(spec, f"P({k})").feasible for k in ks])


def test_gain_set_agrees_with_brute_force_with_delay_and_margins():
    spec = parse_spec(f"""
name: delayed
plant: {{tf: "{X4_PLANT}", delay: 0.01}}
controller: {{type: P, bounds: {{kp: [0, 8]}}}}
requirements:
  - {{type: margins, gain_margin_db: 3, phase_margin_deg: 40}}
  - {{type: bandwidth, min: 40}}
  - {{type: peak_sensitivity, max_db: 8}}
""")
    gs = feasible_gain_set(list(spec.requirements), spec.plants(), ScalarFamily("P", "kp", {}), (0, 8))
    ks = np.linspace(0, 8, 401)
    brute = _brute_force(spec, ks)
    exact = np.array([gs.contains(k) for k in ks])
    # the only allowed disagreements sit within 1e-6 of an interval end
    ends = [e for iv in gs.intervals for e in (iv.lo, iv.hi)]
    mismatch = ks[brute != exact]
    assert all(min(abs(k - e) for e in ends) < 1e-6 for k in mismatch)
    assert gs.intervals, "expected a non-empty set"
    for iv in gs.intervals:
        for end, names in ((iv.lo, iv.lo_binding), (iv.hi, iv.hi_binding)):
            assert names, f"no binding requirement named at {end}"


def test_stability_boundary_is_exact_in_gain_set():
    spec = parse_spec(f"""
name: unstable_above
plant: {{tf: "{X4_PLANT}", delay: 0.02}}
controller: {{type: P, bounds: {{kp: [0, 20]}}}}
requirements:
  - {{type: bandwidth, min: 10}}
""")
    gs = feasible_gain_set(list(spec.requirements), spec.plants(), ScalarFamily("P", "kp", {}), (0, 20))
    # the end is where the closed-loop root crossing at 84 rad/s is STABILITY_FLOOR x 0.43 rad/s (4.3e-7) left
    # of the axis: just inside the exact D-decomposition gain
    crit = critical_gains(Plant.from_string(X4_PLANT), [0.02])[0]["critical_gain"]
    assert crit * (1 - 1e-7) <= gs.intervals[-1].hi <= crit
    assert "stability" in gs.intervals[-1].hi_binding


def test_conflicting_requirements_are_named():
    spec = parse_spec(f"""
name: conflict
plant: {{tf: "{X4_PLANT}"}}
controller: {{type: P, bounds: {{kp: [0, 20]}}}}
requirements:
  - {{type: sensitivity_static, max_db: -15, plant_gain: 1.8}}
  - {{type: slew_rate, rate_limit: 15, max_error: 1, band: [0.1, 100]}}
""")
    result = design(spec)
    assert not result.feasible and result.controller is None
    assert ("sensitivity_static", "slew_rate") in result.gain_set.conflicts()
    assert "sensitivity_static and slew_rate conflict" in result.verdict


def test_non_affine_parameter_uses_sampled_stability():
    # PID with everything fixed but the derivative filter tf: not affine in tf
    spec = parse_spec(f"""
name: tf_only
plant: {{tf: "{X4_PLANT}", delay: 0.005}}
controller: {{type: PID, bounds: {{kp: [1, 1], ki: [2, 2], kd: [0.05, 0.05], tf: [0.0005, 0.05]}}}}
requirements:
  - {{type: peak_sensitivity, max_db: 6}}
""")
    fam = ScalarFamily("PID", "tf", {"kp": 1.0, "ki": 2.0, "kd": 0.05})
    assert fam.affine_parts(0.0005, 0.05) is None
    gs = feasible_gain_set(list(spec.requirements), spec.plants(), fam, (0.0005, 0.05))
    ts = np.linspace(0.0005, 0.05, 200)
    brute = np.array([check(spec, f"PID(1, 2, 0.05, {t})").feasible for t in ts])
    exact = np.array([gs.contains(t) for t in ts])
    assert np.mean(brute == exact) > 0.98


def test_plant_variants_take_the_worst_case():
    spec = parse_spec(f"""
name: robust
plant:
  tf: "{X4_PLANT}"
  variants:
    - {{label: low battery, gain: 0.85}}
    - {{label: full battery, gain: 1.1}}
controller: {{type: P, bounds: {{kp: [0, 20]}}}}
requirements:
  - {{type: sensitivity_static, max_db: -15}}
""")
    assert [p.label for p in spec.plants()] == ["nominal", "low battery", "full battery"]
    res = check(spec, "P(3)")
    assert res.requirements[1].plant == "low battery"  # lowest gain binds the static sensitivity
    gs = feasible_gain_set(list(spec.requirements), spec.plants(), ScalarFamily("P", "kp", {}), (0, 20))
    g_low = 0.85 * 23 * 0.43 / (9.6 * 0.54)
    assert gs.intervals[0].lo == pytest.approx((10 ** 0.75 - 1) / g_low, rel=1e-9)


def test_variant_validation(run_cli, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(f"""name: v
plant:
  tf: "{X4_PLANT}"
  variants: [{{label: nominal, gain: 2}}]
controller: {{type: P}}
requirements: [{{type: bandwidth, min: 1}}]
""")
    res = run_cli("check", str(bad), "--controller", "P(1)")
    assert res.code == 2 and "plant labels must be unique; repeated: nominal" in res.err
