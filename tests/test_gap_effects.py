"""Effect library and the joint re-fit of nominal + effect (noise-free recovery, nesting, block equations)."""

from __future__ import annotations

import numpy as np
import pytest

from synth.errors import ModelError
from synth.gap.attribution.refit import fit_augmented, nominal_structure
from synth.gap.effects import EFFECTS, make_effect
from synth.ident.simulate import simulate_plant
from synth.plant import Plant
from synth.sim.blocks import RateLimit

G = Plant.from_string("2/(0.2*s+1)")
G_OFF = Plant.from_string("2.1/(0.21*s+1)")  # 5 % mismatch
T = np.arange(0, 12, 0.01)
U = np.array([0.0, 1.0, 0.3, 1.5, 0.6, 1.2, 0.1, 0.9])[(T // 1.5).astype(int) % 8]


@pytest.mark.parametrize("name", sorted(EFFECTS))
def test_every_effect_switched_off_is_the_nominal_model(name):
    eff = make_effect(name)
    y = eff.apply(G, T, U, {}, offset=0.5)
    assert np.max(np.abs(y - (simulate_plant(G, T, U) + 0.5))) < 1e-12


def test_input_blocks_are_the_simulator_blocks():
    v = make_effect("rate_limit").input_map(U, 0.01, {"rate": 3.0})
    assert np.array_equal(v, RateLimit(3.0).apply(U, 0.01))
    assert np.max(np.abs(np.diff(v))) <= 3.0 * 0.01 + 1e-12


def test_lag_placements_give_the_same_output_and_differ_from_nominal():
    a = make_effect("lag").apply(G, T, U, {"tau": 0.05})
    b = make_effect("lag(sensor)").apply(G, T, U, {"tau": 0.05})
    assert np.array_equal(a, b)
    assert np.max(np.abs(a - simulate_plant(G, T, U))) > 0.1


def test_nominal_structure_keeps_zero_coefficients():
    formula, values = nominal_structure(Plant.from_string("3/(s*(s+2))"))
    assert formula == "(n0)/(s^2+d1*s)" and values == {"n0": 3.0, "d1": 2.0}


def test_rate_limit_and_nominal_recovered_from_a_mismatched_start():
    y = make_effect("rate_limit").apply(G, T, U, {"rate": 2.0}) + 0.3
    fit = fit_augmented(G_OFF, T, U, y, make_effect("rate_limit"))
    assert fit.params["rate"] == pytest.approx(2.0, rel=0.01)
    assert fit.nominal["n0"] == pytest.approx(10.0, rel=0.01) and fit.nominal["d0"] == pytest.approx(5.0, rel=0.01)
    assert fit.offset == pytest.approx(0.3, abs=1e-3)
    assert fit.ssr < 1e-3 * np.sum((y - y.mean()) ** 2)


def test_refit_alone_cannot_absorb_a_rate_limit():
    y = make_effect("rate_limit").apply(G, T, U, {"rate": 2.0})
    alone = fit_augmented(G_OFF, T, U, y)
    with_rl = fit_augmented(G_OFF, T, U, y, make_effect("rate_limit"))
    assert with_rl.ssr < 0.01 * alone.ssr


def test_static_nonlinearity_and_drift_are_basis_least_squares():
    sn = make_effect("static_nonlinearity")
    center, scale = 0.75, 0.75
    y = sn.apply(G, T, U, {"a2": 0.1, "a3": -0.05, "center": center, "scale": scale})
    fit = fit_augmented(G_OFF, T, U, y, sn)
    assert fit.params["a2"] == pytest.approx(0.1, abs=0.005) and fit.params["a3"] == pytest.approx(-0.05, abs=0.005)
    drift = make_effect("drift(quadratic)")
    y = drift.apply(G, T, U, {"slope": 0.02, "curvature": -0.001})
    fit = fit_augmented(G_OFF, T, U, y, drift)
    assert fit.params["slope"] == pytest.approx(0.02, rel=0.02)
    assert fit.params["curvature"] == pytest.approx(-0.001, rel=0.05)


def test_saturation_limit_recovered_with_a_profile_interval():
    y = make_effect("saturation").apply(G, T, U, {"upper": 1.1}) + 0.01 * np.random.default_rng(0).normal(size=T.size)
    fit = fit_augmented(G_OFF, T, U, y, make_effect("saturation"))
    assert fit.params["upper"] == pytest.approx(1.1, abs=0.01)
    lo, hi = fit.parameter_ci["upper"]
    assert lo <= fit.params["upper"] <= hi and hi - lo < 0.05


def test_a_negative_lower_limit_gets_a_profile_interval_around_it():
    """A saturation's lower limit is negative: its interval is profiled in the log of its magnitude (it was
    ``(x, x)``: only positive parameters were profiled), and a value fitted twice counts at its lower SSR."""
    u = U - 0.8  # from -0.8 to 0.7: the lower limit -0.5 is reached, no upper limit is
    y = make_effect("saturation").apply(G, T, u, {"lower": -0.5}) + 0.01 * np.random.default_rng(0).normal(size=T.size)
    fit = fit_augmented(G_OFF, T, u, y, make_effect("saturation"))
    assert fit.params["lower"] == pytest.approx(-0.5, abs=0.005) and fit.params["upper"] == np.inf
    lo, hi = fit.parameter_ci["lower"]
    assert lo < fit.params["lower"] < hi and hi - lo < 0.02


def test_unknown_effect_and_bad_placement():
    with pytest.raises(ModelError, match="unknown effect"):
        make_effect("flux_capacitor")
    from synth.gap.effects import LagEffect

    with pytest.raises(ModelError, match="placement"):
        LagEffect("elsewhere")
