"""Command quantizer with an unknown step and lattice offset: dense joint search, diagnosis, resonance damping bound."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.gap.attribution.refit import fit_augmented
from synth.gap.effects import QuantizationEffect, ResonanceEffect
from synth.gap.effects.quantization import quantizer_grid
from synth.ident.simulate import simulate_plant
from synth.plant import Plant
from synth.sim.blocks import Quantizer

G = Plant.from_string("2/(0.2*s+1)")
G_OFF = Plant.from_string("2.1/(0.21*s+1)")  # 5 % mismatch
T = np.arange(0, 16, 0.01)
# a band-limited multisine around an operating point: many distinct command values, as a real sweep
U = 3.0 + 0.9 * np.sin(1.1 * T) + 0.6 * np.sin(2.9 * T + 0.4) + 0.4 * np.sin(6.3 * T + 1.3)
STEP, OFFSET = 0.35, 0.12  # the lattice is 0.12 + k 0.35: not through zero


def _record(noise: float, seed: int = 0):
    y = simulate_quantized(G, T, U)
    y = y + noise * np.random.default_rng(seed).standard_normal(T.size)
    return record_from_arrays(T, U, y)


def simulate_quantized(plant: Plant, t: np.ndarray, u: np.ndarray) -> np.ndarray:
    return QuantizationEffect().apply(plant, t, u, {"step": STEP, "offset": OFFSET})


def test_input_map_is_the_simulator_quantizer_with_offset():
    v = QuantizationEffect().input_map(U, 0.01, {"step": STEP, "offset": OFFSET})
    assert np.array_equal(v, Quantizer(STEP, OFFSET).apply(U, 0.01))
    assert np.allclose(((v - OFFSET) / STEP) % 1.0 * (1 - ((v - OFFSET) / STEP) % 1.0), 0.0, atol=1e-9)


def test_dense_search_recovers_step_and_offset_noise_free():
    y = simulate_quantized(G, T, U)
    g = quantizer_grid(G, T, U, y)[0]
    assert g["step"] == pytest.approx(STEP, rel=0.01)
    lattice_miss = (g["offset"] - OFFSET + 0.5 * STEP) % STEP - 0.5 * STEP  # offsets equal modulo the step
    assert abs(lattice_miss) < 0.02 * STEP


def test_joint_refit_from_the_mismatched_nominal_finds_the_step():
    k = T.size // 2
    y = simulate_quantized(G, T, U)
    fit = fit_augmented(G_OFF, T[:k], U[:k], y[:k], QuantizationEffect())
    assert fit.params["step"] == pytest.approx(STEP, rel=0.05)
    # a few samples within a hair of a rounding boundary may land in the neighbouring level
    assert fit.ssr < 1e-4 * float(np.sum((y[:k] - y[:k].mean()) ** 2))


def test_noisy_record_is_diagnosed_as_quantization_with_the_step_within_5_percent():
    rec = _record(noise=0.01)
    dg = diagnose_effects(G_OFF, rec, options=DiagnoseOptions(n_null=49))
    assert dg.verdict["effects"][:1] == ["quantization"], dg.verdict
    q = next(e for e in dg.effects if e.effect == "quantization")
    assert q.accepted and q.fit == "joint"
    assert q.parameters["step"] == pytest.approx(STEP, rel=0.05)


def test_effect_free_record_does_not_name_quantization():
    y = simulate_plant(G, T, U) + 0.01 * np.random.default_rng(1).standard_normal(T.size)
    dg = diagnose_effects(G_OFF, record_from_arrays(T, U, y),
                          options=DiagnoseOptions(candidates=["quantization"], n_null=49))
    assert "quantization" not in dg.verdict["effects"]


def test_resonance_damping_stays_at_most_one():
    e = ResonanceEffect()
    for z in (0.0, 0.3, 5.0, 1e8, np.inf):
        assert 0.0 <= e.from_factor({"zeta": z})["zeta"] <= 1.0
    assert e.from_factor(e.to_factor({"zeta": 0.15}))["zeta"] == pytest.approx(0.15)
    assert e.from_factor(e.to_factor({"zeta": 1.7}))["zeta"] < 1.0  # an out-of-range start is clamped
    # an overdamped second-order factor (zeta 2) in the truth: the joint fit's damping stays <= 1
    wn, k = 30.0, T.size // 2
    truth = Plant(G.num * wn**2, np.polymul(G.den, [1.0, 2 * 2.0 * wn, wn**2]))
    y = simulate_plant(truth, T, U)
    fit = fit_augmented(G_OFF, T[:k], U[:k], y[:k], ResonanceEffect())
    assert 0.0 <= fit.params["zeta"] <= 1.0
    assert all(0.0 <= p["zeta"] <= 1.0 for p, _ in fit.profile)
