"""The disk margin and the edge distance see a lightly damped mode's peak between their grid points. Found by a
black-box test: a plant mode of damping 0.003 at 1234 rad/s under PI(3.702, 18.51) has a disk margin of 0.667
(|S| 6.02 dB at 1233.98 rad/s), and `synth check` reported 1.04 (met against 0.8); with damping 1e-5 at 1000 rad/s a
design was certified with a disk margin of 0.8 and an edge distance of 0.637 where both are 0.05.

The reference here is a dense evaluation of S = 1/(1 + L) written out with numpy: a log grid plus 200,001 even points
within 2 % of the mode (spacing 2e-7 of the mode), its largest point refined by scipy's bounded scalar search."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from synth.controllers import Controller
from synth.edge import edge_distance
from synth.loop import Loop
from synth.plant import Plant
from synth.requirements.disk_margin import DiskMargin


def _dense_S(num: np.ndarray, den: np.ndarray, kp: float, ki: float, mode: float) -> tuple[np.ndarray, np.ndarray]:
    w = np.union1d(np.geomspace(1e-4, 1e6, 200_001), np.linspace(0.98 * mode, 1.02 * mode, 200_001))
    return w, _S(num, den, kp, ki, w)


def _S(num: np.ndarray, den: np.ndarray, kp: float, ki: float, w: np.ndarray) -> np.ndarray:
    s = 1j * np.asarray(w, float)
    return 1.0 / (1.0 + np.polyval(num, s) / np.polyval(den, s) * (kp + ki / s))


def _dense_max(num: np.ndarray, den: np.ndarray, kp: float, ki: float, mode: float, c: float) -> float:
    """max |S + c|: the dense grid's largest point refined by bounded scalar minimization between its neighbours."""
    w, S = _dense_S(num, den, kp, ki, mode)
    i = int(np.clip(np.argmax(np.abs(S + c)), 1, w.size - 2))
    best = minimize_scalar(lambda x: -abs(_S(num, den, kp, ki, np.array([x]))[0] + c), bounds=(w[i - 1], w[i + 1]),
                           method="bounded", options={"xatol": 1e-12 * w[i]})
    return max(float(np.abs(S[i] + c)), -float(best.fun))


@pytest.mark.parametrize("seed", range(3))
def test_random_lightly_damped_modes_against_a_dense_grid(seed):
    rng = np.random.default_rng(seed)
    checked = hidden = 0
    for _ in range(60):
        if checked == 8:
            break
        # a PI loop crossing over near the plant's pole, and a mode far above it whose resonance reaches |L| = u:
        # the mode's peak of |S| is the highest, and the grid's points beside it lie far down its skirt
        pole = float(np.exp(rng.uniform(np.log(0.3), np.log(3.0))))
        kp = float(rng.uniform(1.0, 4.0))
        ki = kp * pole * float(rng.uniform(1.0, 5.0))
        mode = float(np.exp(rng.uniform(np.log(300.0), np.log(5e3))))
        u = float(rng.uniform(0.3, 0.9))
        zeta = kp * pole / (2.0 * u * mode)
        num = np.array([pole * mode**2])
        den = np.polymul([1.0, pole], [1.0, 2.0 * zeta * mode, mode**2])
        loop = Loop(Plant(num, den), Controller("PI", {"kp": kp, "ki": ki}))
        if not loop.stability().stable:
            continue
        alpha = 1.0 / _dense_max(num, den, kp, ki, mode, -0.5)
        assert DiskMargin(min=0.5).evaluate(loop).value == pytest.approx(alpha, rel=2e-3)
        distance = 1.0 / _dense_max(num, den, kp, ki, mode, 0.0)
        assert edge_distance([loop.plant], loop.controller).distance == pytest.approx(distance, rel=2e-3)
        checked += 1
        grid = np.geomspace(1e-3, 1e6, 721)  # 80 points per decade, none at the mode
        plain = np.abs(_S(num, den, kp, ki, grid) - 0.5)
        near = np.abs(grid / mode - 1.0) < 0.03
        hidden += bool(np.sqrt(2.0) * np.max(plain[near]) < 1.0 / alpha)  # the grid beside it more than 3 dB down
    assert checked == 8 and hidden >= 4  # most peaks hide between the points of a plain grid


def test_the_reported_disk_margin_case():
    loop = Loop(Plant.from_string("1522756/((s+1)*(s^2+7.404*s+1522756))"), Controller("PI", {"kp": 3.702, "ki": 18.51}))
    result = DiskMargin(min=0.8).evaluate(loop)
    assert not result.met and result.value == pytest.approx(0.6666, abs=2e-4)
    assert result.binding_frequency == pytest.approx(1234.0, rel=1e-3)


def test_a_design_behind_a_sharp_mode_keeps_its_disk_margin_by_the_dense_grid():
    """The black-box test's design: 1e6/((s+1)(s^2 + 0.02 s + 1e6)) (damping 1e-5 at 1000 rad/s), PI, disk margin
    >= 0.8, maximize ki. Certified before with PI(0.019, 1.382), whose disk margin is 0.051."""
    from synth.design import design
    from synth.spec import parse_spec

    result = design(parse_spec("""
name: sharp
plant: {tf: "1e6/((s+1)*(s^2+0.02*s+1e6))"}
controller: {type: PI, bounds: {kp: [0, 1], ki: [0, 5]}}
requirements:
  - {type: disk_margin, min: 0.8}
objective: {maximize: integral_gain}"""))
    assert result.feasible
    kp, ki = result.controller.parameters["kp"], result.controller.parameters["ki"]
    num, den = np.array([1e6]), np.polymul([1.0, 1.0], [1.0, 0.02, 1e6])
    assert 1.0 / _dense_max(num, den, kp, ki, 1000.0, -0.5) >= 0.8 * (1 - 1e-3)
