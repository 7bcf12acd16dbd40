"""The exact stabilizing set over a gain range when the delay is long against the plant: beyond the critical gain
the D-decomposition has a boundary for every turn of the delay's phase (3184 of them for ``1/(s+1) e^(-20 s)`` up
to a gain of 1000), and counting each piece took 110 s of a P design. A piece after one with ``n`` right-half-plane
roots holds at least ``n`` minus the roots that can cross at the boundary between them, so only a few pieces are
counted. Checked against the critical gain in closed form and, on random loops, against a direct count at many
gains."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

import synth.stability_sets as stability_sets
from synth.stability import closed_loop_stability
from synth.stability_sets import affine_stability_intervals

P = (np.array([1.0]), np.array([1.0]))


def test_a_long_delay_is_counted_at_a_few_pieces(monkeypatch: pytest.MonkeyPatch) -> None:
    counted = []
    original = stability_sets.closed_loop_stability
    monkeypatch.setattr(stability_sets, "closed_loop_stability",
                        lambda *a, **k: counted.append(1) or original(*a, **k))
    tau = 20.0
    intervals = affine_stability_intervals(None, P, np.array([1.0]), np.array([1.0, 1.0]), tau, 0.0, 1000.0)
    # 1/(s+1) e^(-tau s): the phase reaches -pi where tau w + atan(w) = pi, the critical gain is |jw + 1| there
    w = brentq(lambda x: tau * x + np.arctan(x) - np.pi, 1e-9, np.pi / tau)
    assert len(intervals) == 1 and intervals[0].lo == 0.0
    assert intervals[0].hi == pytest.approx(np.hypot(w, 1.0), rel=1e-9)
    assert len(counted) <= 20  # 3184 before


@pytest.mark.parametrize("seed", range(12))
def test_the_intervals_agree_with_a_direct_count_at_many_gains(seed: int) -> None:
    rng = np.random.default_rng(seed)
    poles = -rng.uniform(0.2, 5.0, rng.integers(1, 4))
    poles[0] *= rng.choice([1.0, -0.3])  # some open-loop unstable
    den = np.poly(poles)
    num = np.array([rng.uniform(0.5, 5.0)])
    tau = rng.uniform(0.5, 8.0) / np.max(np.abs(poles))
    c1 = P if rng.random() < 0.5 else (np.array([1.0, 0.5]), np.array([1.0, 0.0]))  # P, or a PI's shape
    hi = 50.0
    intervals = affine_stability_intervals(None, c1, num, den, tau, 0.0, hi)
    gains = np.linspace(0.0, hi, 401)[1:]
    for k in gains:
        inside = any(iv.lo < k < iv.hi for iv in intervals)
        near = any(min(abs(k - iv.lo), abs(k - iv.hi)) < 1e-6 * max(1.0, k) for iv in intervals)
        if near:
            continue
        stable = closed_loop_stability(np.polymul(k * c1[0], num), np.polymul(c1[1], den), tau).stable
        assert stable == inside, (seed, k, intervals)


def test_many_pieces_keep_stability_exact_and_bound_the_counts_below(monkeypatch: pytest.MonkeyPatch) -> None:
    from synth.stability_sets import COUNTED_PIECES, affine_root_counts

    num, den, tau = np.array([1.0]), np.array([1.0, 1.0]), 20.0
    gains = np.concatenate([np.linspace(0.01, 3.0, 60), np.geomspace(3.0, 900.0, 120)])
    counted = []
    original = stability_sets.closed_loop_stability
    monkeypatch.setattr(stability_sets, "closed_loop_stability",
                        lambda *a, **k: counted.append(1) or original(*a, **k))
    counts = affine_root_counts(None, P, num, den, tau, gains)
    monkeypatch.undo()
    assert len(counted) < COUNTED_PIECES  # about 180 pieces hold a gain
    direct = np.array([closed_loop_stability(k * num, den, tau).unstable_poles for k in gains])
    assert np.array_equal(counts > 0, direct > 0)  # stable and unstable exact
    assert np.all(counts <= direct) and np.all(counts[direct > 0] >= 1)  # a lower bound where not counted
    assert np.array_equal(counts[gains < 1.0], direct[gains < 1.0])


def test_a_delay_beyond_resolution_is_one_line_naming_the_delay(run_cli, tmp_path) -> None:
    from synth.errors import ModelError
    from synth.stability_sets import stability_boundaries

    with pytest.raises(ModelError, match="check that the delay is in seconds") as info:
        stability_boundaries(None, P, np.array([1.0]), np.array([1.0, 1.0]), 1e6, 1000.0)
    assert info.value.where == "plant.delay"
    spec = tmp_path / "slow.yaml"
    spec.write_text('name: slow\nplant: {tf: "1/(s+1)", delay: 1000000}\ncontroller: {type: P}\n'
                    "requirements: [{type: bandwidth, min: 0.001}]\n")
    res = run_cli("design", str(spec), "--out", str(tmp_path / "out"))
    assert res.code == 2 and "Traceback" not in res.err
    assert len(res.err.strip().splitlines()) == 1 and "plant.delay" in res.err


def test_a_count_beyond_resolution_is_not_certified_and_an_overflow_is_one_line(run_cli, tmp_path) -> None:
    from synth.errors import ModelError
    from synth.polynomials import largest_crossing

    result = closed_loop_stability(np.array([1e9]), np.array([1.0, 1.0]), 20.0)  # 797 GiB of phase samples before
    assert not result.stable and result.unstable_poles >= 1
    assert result.describe().startswith("closed loop not certified stable (not counted")
    assert closed_loop_stability(np.array([1e3]), np.array([1.0, 1.0]), 20.0).unstable_poles > 1  # still counted
    with pytest.raises(ModelError, match="overflows double precision"):
        largest_crossing(np.array([1e300]), np.array([1.0, 1.0]), 0.5)
    spec = tmp_path / "x4.yaml"
    spec.write_text('name: x4\nplant: {tf: "23*(s+0.43)/((s+9.6)*(s+0.54))"}\ncontroller: {type: P}\n'
                    "requirements: [{type: bandwidth, min: 1}]\n")
    res = run_cli("check", str(spec), "--controller", "P(1e300)")
    assert res.code == 2 and "Traceback" not in res.err and "overflows double precision" in res.err
    delayed = tmp_path / "delayed.yaml"
    delayed.write_text('name: d\nplant: {tf: "1/(s+1)", delay: 20}\ncontroller: {type: P}\n'
                       "requirements: [{type: bandwidth, min: 0.001}]\n")
    res = run_cli("check", str(delayed), "--controller", "P(1e9)")
    assert res.code == 1 and "Traceback" not in res.err
    assert "not certified" in res.out and "unstable root" not in res.out.split("\n - ")[0]
