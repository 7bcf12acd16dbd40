"""Gaps in a log's time stamps: found, their made-up samples left out of averages and fits.

A black-box test found that a 0.3 s logging dropout hiding one edge of a step train put the gain 3 % off (44 of
its standard errors) with exit 0. The references here are written apart from synth: the truth simulated with
``scipy.signal.lsim`` (zero-order hold, delay as whole samples), the dropout cut out of the log by hand.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from synth.data import record_from_arrays
from synth.data.gaps import find_gaps, gap_mask, gap_weights
from synth.errors import DataError, FitError
from synth.ident.identification import identify
from synth.ident.steps import average_steps, find_steps, late_steps


def _train(rng: np.random.Generator, second_order: bool, hide_edge: bool):
    """A square-wave step train logged every 10 ms with a 0.15-0.5 s dropout, hiding an edge or not; the truth."""
    dt = 0.01
    half = float(rng.choice([1.5, 2.0, 2.5]))  # seconds between edges
    t = np.arange(0.0, 20 * 2 * half, dt)
    u = (np.floor(t / half) % 2 == 1) * 1.0
    k, t1 = float(rng.uniform(0.5, 4.0)), float(rng.uniform(0.08, 0.25))
    t2 = float(rng.uniform(0.02, 0.06)) if second_order else 0.0
    delay = dt * int(rng.integers(0, 6))
    den = np.polymul([t1, 1.0], [t2, 1.0]) if second_order else [t1, 1.0]
    shift = round(delay / dt)
    u_late = np.r_[np.zeros(shift), u[:u.size - shift]]
    y = _zoh(k, den, u_late, dt) + 0.01 * k * rng.standard_normal(t.size)
    edge = half * int(rng.integers(8, 30))  # an edge in the middle of the train
    length = float(rng.uniform(0.15, 0.5))
    start = edge - float(rng.uniform(0.05, length - 0.05)) if hide_edge else edge + 0.5 * half
    keep = (t <= start) | (t >= start + length)
    truth = {"K": k, "T1" if second_order else "T": t1, **({"T2": t2} if second_order else {}), "delay": delay}
    return t[keep], u[keep], y[keep], truth


def _zoh(k: float, den, u: np.ndarray, dt: float) -> np.ndarray:
    """The plant k/den driven by ``u`` held between samples (scipy's exact zero-order-hold discretization)."""
    num, dd, _ = signal.cont2discrete(([k], den), dt, method="zoh")
    return signal.lfilter(np.ravel(num), dd, u)


def test_gaps_are_found_and_their_made_up_samples_masked():
    t = np.r_[np.arange(0, 1, 0.01), np.arange(1.3, 2, 0.01)]
    assert [(round(a, 6), round(b, 6)) for a, b in find_gaps(t)] == [(0.99, 1.3)]
    grid = np.round(np.arange(0, 2, 0.01), 10)
    masked = grid[gap_mask(grid, find_gaps(t))]
    np.testing.assert_allclose(masked, np.round(np.arange(1.0, 1.3 - 1e-9, 0.01), 10))  # 1.00 ... 1.29
    u = (grid >= 1.3) * 1.0  # the command changed inside the gap: its settling is left out too
    w = gap_weights(grid, u, find_gaps(t), settle=0.2)
    assert np.all(w[(grid > 0.995) & (grid < 1.495)] == 0) and np.all(w[grid < 0.985] == 1)
    assert np.all(w[grid > 1.505] == 1)
    w_flat = gap_weights(grid, np.ones(grid.size), find_gaps(t), settle=0.2)
    assert np.array_equal(w_flat == 0, gap_mask(grid, find_gaps(t)))  # no change hidden: only the made-up samples


def test_a_record_keeps_its_gaps_through_a_segment_and_in_json():
    t = np.r_[np.arange(0, 1, 0.01), np.arange(1.3, 3, 0.01)]
    rec = record_from_arrays(t, (t > 2) * 1.0, np.sin(t))
    assert [tuple(round(x, 6) for x in g) for g in rec.gaps] == [(0.99, 1.3)]
    assert rec.to_dict()["gaps"] == [[0.99, 1.3]]
    assert rec.segment(0.5, 2.0).gaps == rec.gaps and rec.segment(1.5, 2.5).gaps == ()
    assert record_from_arrays(np.arange(0, 3, 0.01), (np.arange(300) > 100) * 1.0, np.arange(300.0)).gaps == ()


@pytest.mark.parametrize("mode", ["cycle", "edge"])
def test_averages_leave_out_the_windows_a_gap_touches(mode):
    t = np.arange(0.0, 40.0, 0.01)
    u = ((t % 4.0) >= 2.0) * 1.0
    y = _zoh(2.5, [0.2, 1.0], u, 0.01)
    keep = (t <= 24.9) | (t >= 25.2)  # the edges are every 2 s: this dropout hides none
    keep_hidden = (t <= 23.85) | (t >= 24.2)  # this one hides the edge at 24 s
    for kept, late_count in ((keep, 0), (keep_hidden, 1)):
        rec = record_from_arrays(t[kept], u[kept], y[kept])
        steps = find_steps(rec)
        assert int(late_steps(rec, steps).sum()) == late_count
        avg = average_steps(rec, steps, mode)
        assert avg.in_gaps >= 1 and avg.mode == mode
        # what is averaged is the clean response: the window's final value is the truth's gain
        assert avg.step_size == pytest.approx(2.5, rel=2e-3)


def test_a_hidden_edge_no_longer_biases_the_fit_on_random_trains():
    """Random first- and second-order trains, each with a dropout hiding an edge: every parameter within 4
    reported standard errors of the truth, with the default averaging and with none (the old code: 44 of them)."""
    rng = np.random.default_rng(20261205)
    for case in range(4):
        second = case % 2 == 1
        t, u, y, truth = _train(rng, second, hide_edge=True)
        structure = "K/((T1*s+1)*(T2*s+1))" if second else "K/(T*s+1)"
        for average in ("auto", "none") if case < 2 else ("auto",):
            res = identify((t, u, y), structure, delay="fit", average=average, compare_directions=False)
            fit = res.fit
            for name, value in truth.items():
                z = abs(fit.parameters[name] - value) / fit.std[name]
                assert z < 4.0, (case, average, name, fit.parameters, truth, fit.std)
            if average == "auto" and res.average is not None:
                assert res.average.in_gaps >= 1



def test_a_record_not_at_rest_keeps_the_settling_after_a_hidden_edge_out_of_its_fit():
    """The fit that leaves out a start not at rest (synth.ident.unknown_start) weights the settling after the
    hidden edge 0 as well, and lands within 4 reported std of the truth."""
    rng = np.random.default_rng(5)
    for _ in range(2):
        t, u, y, truth = _train(rng, False, hide_edge=True)
        i = int(np.flatnonzero(np.diff(u))[0]) + 5  # five samples after the first edge: the plant is moving
        res = identify((t[i:], u[i:], y[i:]), "K/(T*s+1)", delay="fit", average="none", compare_directions=False)
        assert "does not start at rest" in res.whole_record_note
        fit = res.fit
        (before, after), = find_gaps(t[i:])
        settling = (fit.t > before + 1e-6) & (fit.t < after + truth["T"])  # the logged sample at `before` counts
        assert settling.any() and np.all(fit.weights[settling] == 0)
        for name, value in truth.items():
            assert abs(fit.parameters[name] - value) < 4.0 * fit.std[name], (name, fit.parameters, truth, fit.std)


def _square(period: float, n: int, delay_samples: int, gaps: list[tuple[float, float]], seed: int):
    """K = 2, T = 0.5 behind a whole-sample delay, a square wave of ``period`` from 2 s, 10 ms stamps, 1 % noise;
    the stamps inside each ``(start, end)`` of ``gaps`` removed."""
    t = np.arange(n) * 0.01
    u = (np.floor((t - 2.0) / (period / 2)) % 2 == 0) * (t >= 2.0) * 1.0
    y = _zoh(2.0, [0.5, 1.0], np.r_[np.zeros(delay_samples), u[: n - delay_samples]], 0.01)
    y = y + 0.02 * np.random.default_rng(seed).standard_normal(n)
    keep = np.ones(n, bool)
    for a, b in gaps:
        keep &= (t < a) | (t >= b)
    return t[keep], u[keep], y[keep]


def _within(fit, truth: dict[str, float], z: float = 4.0) -> None:
    for name, value in truth.items():
        assert abs(fit.parameters[name] - value) < z * fit.std[name], (name, fit.parameters, fit.std)


def test_black_box_findings_on_gaps_hiding_edges():
    """A black-box helper's cases (its own generator; rebuilt here): each was 5-227 reported std off.
    (a) a delay and an edge hidden, the whole record from rest chosen over the periodic average: the delay 5.7
    std low; (b) every edge hidden: nothing was dropped, K 19 std low; (c) all but three hidden: three down edges
    whose windows ran over the next edges, K 199 std low. Both are now refused (exit 1): the edges come every 2 s
    and the model takes 3.5 s to settle after each, so nothing is left that the lost timing does not bend;
    (d) a 7 s gap hiding two edges, the command at one level
    at both its ends: K 7 % low."""
    t, u, y = _square(4.0, 3000, 3, [(23.95, 24.2)], 0)
    _within(identify((t, u, y), "K/(T*s+1)", delay="fit", compare_directions=False).fit,
            {"K": 2.0, "T": 0.5, "delay": 0.03})
    every = [(e - 0.05, e + 0.15) for e in np.arange(4.0, 30.0, 2.0)]
    for gaps in (every, [g for k, g in enumerate(every) if k % 4 != 3]):
        t, u, y = _square(4.0, 3000, 0, gaps, 1)
        with pytest.raises(DataError, match="every step window holds samples that a gap"):
            average_steps(record_from_arrays(t, u, y), mode="edge")
        with pytest.raises(FitError, match="gaps in the log hide command changes, and with the model's settling"):
            identify((t, u, y), "K/(T*s+1)", delay="fit", compare_directions=False)  # not a biased result
    t, u, y = _square(4.0, 3000, 0, [(11.5, 18.5)], 2)
    _within(identify((t, u, y), "K/(T*s+1)", delay="fit", compare_directions=False).fit, {"K": 2.0, "T": 0.5})


@pytest.mark.parametrize("dt", [0.01, 0.002, 1 / 3])
def test_a_ramp_logged_with_a_dropout_keeps_the_logs_own_grid(dt: float) -> None:
    """A command changing at every stamp (a ramp), logged regularly but for one dropout: the grid is the log's own
    interval and every logged sample is on it, as logged. The ramp's changes, a rounding below the interval
    apart, had made one interval more over the record (0.0099983 s for 0.01 s: every sample interpolated, the
    noise smoothed, and diagnose's noise floor 39 % low)."""
    t = np.arange(6000) * dt
    u = 0.5 * t
    y = np.random.default_rng(0).normal(size=t.size)
    keep = (t < 1020 * dt) | (t > 1050 * dt)
    rec = record_from_arrays(t[keep], u[keep], y[keep])
    assert rec.n == 6000 and rec.t[1] - rec.t[0] == pytest.approx(dt, rel=1e-12)
    on_grid = np.flatnonzero(keep)
    assert np.max(np.abs(rec.y[on_grid] - y[keep])) < 1e-9  # the logged samples themselves, not interpolated
    assert len(rec.gaps) == 1
