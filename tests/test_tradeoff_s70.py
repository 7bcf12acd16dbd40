"""Trade-off sweeps found wrong by a black-box helper (session 70): Pareto marks where an objective is infinite."""

from __future__ import annotations

import math

import numpy as np
import pytest

from synth.synthesis.tradeoff import Sweep, TradeoffPoint, mark_pareto

TOL = 1e-6


def front_by_hand(points, signs, sense):
    """The non-dominated feasible points, one pair at a time; infinite objectives compared exactly, finite ones
    within TOL times the largest finite objective (written apart from synth)."""
    feasible = [p for p in points if p.feasible and p.objective is not None]
    finite = [abs(p.objective) for p in feasible if math.isfinite(p.objective)]
    tol = TOL * (max([*finite, 0.0]) or 1.0)
    ys = 1.0 if sense == "maximize" else -1.0

    def at_least(a, b):
        return a >= b if math.isinf(a) or math.isinf(b) else a >= b - tol

    def above(a, b):
        return a > b if math.isinf(a) or math.isinf(b) else a > b + tol

    front = set()
    for p in feasible:
        dominated = False
        for q in feasible:
            strict_ge = all(s * q.values[k] >= s * p.values[k] for k, s in zip(sorted(p.values), signs))
            stricter = any(s * q.values[k] > s * p.values[k] for k, s in zip(sorted(p.values), signs))
            if strict_ge and at_least(ys * q.objective, ys * p.objective) and (
                    stricter or above(ys * q.objective, ys * p.objective)):
                dominated = True
                break
        if not dominated:
            front.add(id(p))
    return front


def test_tied_infinite_objectives_leave_only_the_strictest_point():
    """minimize control_effort at kp = 0 is -inf dB at every phase-margin floor: only the strictest floor (60 deg)
    is on the front; an infinite tie tolerance (inf - inf = nan) had marked all three."""
    points = [TradeoffPoint({"requirements.margins.phase_margin_deg": pm}, True, -math.inf, None, [], {}, "", 0.0)
              for pm in (30.0, 45.0, 60.0)]
    mark_pareto(points, [Sweep("requirements.margins.phase_margin_deg", [])], "minimize", +1)
    assert [p.pareto for p in points] == [False, False, True]


@pytest.mark.parametrize("seed", range(40))
def test_front_with_infinite_objectives_matches_the_pairwise_filter(seed):
    rng = np.random.default_rng(7000 + seed)
    n = int(rng.integers(2, 30))
    signs = [int(rng.choice([-1, 1])), int(rng.choice([-1, 1]))]
    sense = str(rng.choice(["maximize", "minimize"]))
    points = []
    for _ in range(n):
        values = {"a": float(rng.integers(0, 4)), "b": float(rng.integers(0, 4))}
        r = rng.random()
        objective = -math.inf if r < 0.25 else math.inf if r < 0.4 else float(rng.integers(0, 5)) * 10.0
        points.append(TradeoffPoint(values, bool(rng.random() > 0.1), objective, None, [], {}, "", 0.0))
    mark_pareto(points, [Sweep("a", []), Sweep("b", [])], sense, signs)
    expected = front_by_hand(points, signs, sense)
    assert {id(p) for p in points if p.pareto} == expected
    if any(p.feasible for p in points):
        assert expected


def _spec(tmp_path, text):
    from synth.spec import load_spec

    path = tmp_path / "spec.yaml"
    path.write_text(text)
    return load_spec(path)


def test_parameters_at_their_bounds_are_named_as_binding(tmp_path):
    """A PI whose kp and ki both sit at their upper bounds (bandwidth maximized on an unstable first-order plant):
    the binding column was empty; a P design's gain set names its bounds, a PI's now does too."""
    from synth.synthesis.tradeoff import Sweep, tradeoff

    spec = _spec(tmp_path, """
name: pi_at_bounds
plant: {tf: "1.316/(s-0.6039538977)"}
controller: {type: PI, bounds: {kp: [0, 4.602], ki: [0, 4.714]}}
requirements:
  - {type: bandwidth, min: 0.37}
  - {type: disk_margin, min: 0.344}
objective: {maximize: bandwidth}
""")
    (point,) = tradeoff(spec, [Sweep.parse("requirements.bandwidth.min=0.259")], workers=1).points
    assert point.feasible
    assert point.controller == pytest.approx({"kp": 4.602, "ki": 4.714}, rel=1e-6)
    assert point.binding == ["bounds (kp <= 4.602)", "bounds (ki <= 4.714)"]
    assert all(s > 1.0 for label, s in point.slacks.items())  # no requirement is near its bound


def test_requirements_far_from_their_bounds_are_not_binding(tmp_path):
    """P on an integrating plant, peak |S| minimized: the design sits where the loop stops being stable in
    practice, and every requirement that presumes stability ends there too; disk margin (slack 1.39 Np) and delay
    margin (17 Np) were listed as binding it."""
    from synth.synthesis.tradeoff import Sweep, tradeoff

    spec = _spec(tmp_path, """
name: p_integrating
plant: {tf: "0.52/((s+0.3573652389)*s)"}
controller: {type: P, bounds: {kp: [0, 1.204]}}
requirements:
  - {type: peak_sensitivity, max_db: 3.8}
  - {type: disk_margin, min: 0.499}
  - {type: delay_margin, min: 0.1176}
objective: {minimize: peak_sensitivity}
""")
    (point,) = tradeoff(spec, [Sweep.parse("requirements.peak_sensitivity.max_db=1.8")], workers=1).points
    assert point.feasible
    assert point.slacks["disk_margin"] > 1.0 and point.slacks["delay_margin"] > 10.0
    assert not {"disk_margin", "delay_margin"} & set(point.binding)


def test_a_gain_sets_bound_is_printed_as_the_spec_wrote_it(tmp_path):
    """The feasible set of P on 5.873/(s + 9.88) behind 11.1 ms starts 3e-13 above the bound 0: its end was
    printed 'bounds (kp >= 3.06102e-13)', the end's value, not the bound's."""
    from synth import design

    result = design(_spec(tmp_path, """
name: p_first_order
plant: {tf: "5.873/(s+9.877654089)", delay: 0.0111}
controller: {type: P, bounds: {kp: [0, 13.147]}}
requirements:
  - {type: bandwidth, min: 2.218}
  - {type: margins, phase_margin_deg: 44.0}
  - {type: peak_sensitivity, max_db: 1.64}
objective: {minimize: peak_sensitivity}
"""))
    ends = [b for iv in result.gain_set.intervals for b in iv.lo_binding + iv.hi_binding if b.startswith("bounds")]
    assert ends == ["bounds (kp >= 0)"]
