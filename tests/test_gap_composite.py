"""Two effects in series (synth.gap.attribution.composite): the chain, the factor, the joint re-fit of the second on top
of the first."""

from __future__ import annotations

import numpy as np
import pytest

from synth.errors import ModelError
from synth.gap.attribution.composite import NestedEffect, numeric_factor
from synth.gap.attribution.refit import fit_augmented
from synth.gap.attribution.screen import screen_effect
from synth.gap.effects import Effect, Params, coulomb_force, make_effect
from synth.ident.simulate import simulate_plant
from synth.ident.structure import parse_structure
from synth.plant import Plant
from synth.sim.blocks import DeadZone, RateLimit

G = Plant.from_string("2/(0.2*s+1)")  # n0 = 10, d0 = 5 in the re-fit's monic form
G_OFF = Plant.from_string("2.1/(0.21*s+1)")  # 5 % mismatch
DRIVE = Plant.from_string("1/(s*(s+1))")  # position of a mass with viscous friction
T = np.arange(0, 8, 0.01)
DT = 0.01
U = np.array([0.0, 1.0, 0.3, 1.5, 0.6, 1.2, 0.1, 0.9])[(T // 1.0).astype(int) % 8]
SIGMA = 0.01
SNL = {"a2": 0.15, "a3": -0.1, "center": 0.75, "scale": 0.75}


def _snl(u: np.ndarray, p: Params) -> np.ndarray:
    h = p["scale"]
    x = (u - p["center"]) / h
    return u + p["a2"] * h * x**2 + p["a3"] * h * x**3


def _lag(plant: Plant, tau: float) -> Plant:
    return Plant(plant.num, np.polymul(plant.den, [tau, 1.0]), plant.delay)


def _noisy(y: np.ndarray, seed: int) -> np.ndarray:
    return y + SIGMA * np.random.default_rng(seed).standard_normal(y.size)


def _seeded(effect: NestedEffect, grid: list[Params]) -> NestedEffect:
    """The effect with its own search grid (as the diagnosis seeds the joint fit from the screen)."""
    sub = type("Seeded", (type(effect),), {"grid": lambda self, t, u, plant: [dict(g) for g in grid]})
    return sub(effect.first, effect.first_params, effect.second)


def _assert_nominal(fit, n0=10.0, d0=5.0, rel=0.01):
    assert fit.nominal["n0"] == pytest.approx(n0, rel=rel)
    assert fit.nominal["d0"] == pytest.approx(d0, rel=rel)


# ------------------------------------------------------------------------------------------ the model
CHAINS = [
    ("static_nonlinearity", SNL, "saturation(output)", {"upper": 2.4},
     lambda: np.clip(simulate_plant(G, T, _snl(U, SNL)) + 0.3, -np.inf, 2.4)),
    ("lag", {"tau": 0.05}, "rate_limit", {"rate": 4.0},
     lambda: simulate_plant(_lag(G, 0.05), T, RateLimit(4.0).apply(U, DT)) + 0.3),
    ("saturation", {"upper": 1.2}, "drift", {"slope": 0.05},
     lambda: simulate_plant(G, T, np.minimum(U, 1.2)) + 0.3 + 0.05 * T),
    ("resonance", {"wn": 30.0, "zeta": 0.1}, "delay", {"delay": 0.05},
     lambda: simulate_plant(Plant(G.num * 900.0, np.polymul(G.den, [1.0, 6.0, 900.0]), 0.05), T, U) + 0.3),
    ("rate_limit", {"rate": 3.0}, "static_nonlinearity", SNL,
     lambda: simulate_plant(G, T, _snl(RateLimit(3.0).apply(U, DT), SNL)) + 0.3),
    ("saturation(output)", {"upper": 2.0}, "lag", {"tau": 0.05},
     lambda: np.minimum(simulate_plant(_lag(G, 0.05), T, U) + 0.3, 2.0)),
    ("lag", {"tau": 0.05}, "lag(sensor)", {"tau": 0.02},
     lambda: simulate_plant(_lag(_lag(G, 0.05), 0.02), T, U) + 0.3),
]


@pytest.mark.parametrize("first,p1,second,p2,chain", CHAINS, ids=[f"{c[0]}+{c[2]}" for c in CHAINS])
def test_apply_is_the_chain_first_then_second(first, p1, second, p2, chain):
    y = NestedEffect(first, p1, second).apply(G, T, U, p2, offset=0.3)
    assert np.max(np.abs(y - chain())) < 1e-12


def test_plant_dependent_input_first_or_second_is_the_chain():
    """Coulomb friction computed on the command it sees, with the drive's own model."""
    u = 1.6 * np.sin(0.8 * T)
    fric = NestedEffect("friction", {"fc": 0.4}, "saturation(output)").apply(DRIVE, T, u, {"upper": 1.0})
    hand = np.minimum(simulate_plant(DRIVE, T, u + coulomb_force(DRIVE, u, DT, 0.4)), 1.0)
    assert np.max(np.abs(fric - hand)) < 1e-12
    v1 = DeadZone(0.3, 0.0).apply(u, DT)
    dz = NestedEffect("deadzone", {"width": 0.3, "center": 0.0}, "friction").apply(DRIVE, T, u, {"fc": 0.4})
    hand = simulate_plant(DRIVE, T, v1 + coulomb_force(DRIVE, v1, DT, 0.4))
    assert np.max(np.abs(dz - hand)) < 1e-12
    assert np.max(np.abs(dz - simulate_plant(DRIVE, T, v1))) > 0.1  # the friction acts


def test_nested_first_effect_makes_three_in_series():
    inner = NestedEffect("lag", {"tau": 0.05}, "rate_limit")
    e = NestedEffect(inner, {"rate": 4.0}, "drift")
    assert e.label == "lag+rate_limit+drift" and e.parameter_names == make_effect("drift").parameter_names
    hand = simulate_plant(_lag(G, 0.05), T, RateLimit(4.0).apply(U, DT)) + 0.02 * T
    assert np.max(np.abs(e.apply(G, T, U, {"slope": 0.02}) - hand)) < 1e-12


def test_first_effect_off_is_the_second_alone():
    for first in ("delay", "lag", "resonance", "rate_limit", "saturation(output)", "quantization"):
        e = NestedEffect(first, {}, "rate_limit")
        assert np.max(np.abs(e.apply(G, T, U, {"rate": 2.0}) - make_effect("rate_limit").apply(G, T, U, {"rate": 2.0}))) \
            < 1e-12


def test_factor_is_the_first_factor_in_numbers_times_the_second_in_its_symbols():
    e = NestedEffect("resonance", {"wn": 30.0, "zeta": 0.1}, "resonance")
    p = {"wn": 12.0, "zeta": 0.3}
    st = parse_structure(f"(n0)/(s+d0)*{e.factor(p)}")
    assert st.parameters == ("n0", "d0", "zeta")  # the first's damping is a number, the second's a symbol
    H = st.plant({"n0": 10.0, "d0": 5.0, **e.to_factor(p)})
    A = e.augment_plant(G, p)
    w = np.geomspace(0.1, 300, 50)
    assert np.max(np.abs(H.freqresp(w) - A.freqresp(w)) / np.abs(A.freqresp(w))) < 1e-12
    assert numeric_factor(Plant.from_string("1")) is None
    assert NestedEffect("rate_limit", {"rate": 1.0}, "drift").factor({}) is None


def test_description_is_the_second_and_the_first_is_fixed():
    e = NestedEffect("static_nonlinearity", SNL, "saturation(output)")
    assert e.label == "static_nonlinearity+saturation(output)"
    assert (e.parameter_names, e.grid_names, e.basis_names, e.factor_names) == (("lower", "upper"), ("lower", "upper"),
                                                                                 (), ())
    assert e.off() == make_effect("saturation(output)").off() and not e.screenable and not e.needs_plant
    d = e.to_dict()
    assert d["effect"] == e.label and d["first"]["effect"] == "static_nonlinearity"
    assert d["second"]["effect"] == "saturation(output)" and d["first_parameters"] == SNL
    assert NestedEffect("lag", {"tau": 0.05}, "rate_limit").screenable
    assert NestedEffect("friction", {"fc": 0.1}, "drift").needs_plant
    assert hash(e) == hash(NestedEffect("static_nonlinearity", dict(SNL), "saturation(output)"))
    # the second's grid is built on what it sees: the first's output and the model augmented by the first
    g = NestedEffect("saturation", {"upper": 1.0}, "rate_limit").grid(T, U, G)
    assert g == make_effect("rate_limit").grid(T, np.minimum(U, 1.0), G)


UNSUPPORTED = [
    ("delay", {"delay": 0.02}, "lag", "fixed delay"),
    ("drift", {"slope": 0.1}, "rate_limit", "output terms"),
    ("saturation(output)", {"upper": 1.0}, "drift", "output map"),
    ("friction", {"fc": 0.1}, "friction", "both need the linear model"),
    ("friction", {"fc": 0.1}, "lag", "linear factor"),
    ("friction", {"fc": 0.1}, "rate_limit", "input block"),
    ("lag", {"tau": 0.05}, "friction", "velocity model"),
    ("lag", {"width": 0.05}, "rate_limit", "no parameter width"),
]


@pytest.mark.parametrize("first,p1,second,words", UNSUPPORTED, ids=[f"{c[0]}+{c[2]}" for c in UNSUPPORTED])
def test_unsupported_combination_raises_naming_both(first, p1, second, words):
    with pytest.raises(ModelError) as info:
        NestedEffect(first, p1, second)
    text = str(info.value)
    assert f"{make_effect(first).label}+{make_effect(second).label}" in text and words in text
    assert "\n" not in text


def test_nested_second_effect_raises():
    with pytest.raises(ModelError, match="single effect"):
        NestedEffect("lag", {"tau": 0.05}, NestedEffect("rate_limit", {"rate": 1.0}, "drift"))


# ------------------------------------------------------------------------------------------ the joint re-fit
def test_fit_clipping_on_top_of_a_static_nonlinearity():
    e = NestedEffect("static_nonlinearity", SNL, "saturation(output)")
    t, u = T[:600], U[:600]  # two clipped steps; every point of a clipping fit alternates censoring and the fit
    y = _noisy(e.apply(G, t, u, {"upper": 2.4}, offset=0.3), 1)
    # the search grid is the clipping's own, from the measured output (the seeded search below keeps the test fast)
    assert e.data_grid(t, u, y, G_OFF) == make_effect("saturation(output)").data_grid(t, _snl(u, SNL), y, G_OFF)
    fit = fit_augmented(G_OFF, t, u, y, _seeded(e, [{"upper": x} for x in (2.3, 2.37, 2.45)]))
    assert fit.params["upper"] == pytest.approx(2.4, abs=0.01) and fit.params["lower"] == -np.inf
    _assert_nominal(fit)
    assert fit.offset == pytest.approx(0.3, abs=0.01)
    assert fit.ssr / t.size < 1.2 * SIGMA**2  # the noise, nothing left
    assert np.max(np.abs(fit.predict(t, u) - e.apply(G, t, u, {"upper": 2.4}, offset=0.3))) < 0.02
    # without the accepted nonlinearity the clipping and the re-fit cannot explain the record
    alone = fit_augmented(G_OFF, t, u, y, _seeded(NestedEffect("static_nonlinearity", {}, "saturation(output)"),
                                                  [{"upper": 2.4}]), refine=False)
    assert alone.ssr > 5 * fit.ssr


def test_fit_rate_limit_on_top_of_a_lag():
    e = NestedEffect("lag", {"tau": 0.05}, "rate_limit")
    y = _noisy(e.apply(G, T, U, {"rate": 4.0}, offset=0.3), 2)
    seeded = _seeded(e, [{"rate": r} for r in (2.0, 3.0, 4.5, 6.0, 8.0)])
    fit = fit_augmented(G_OFF, T, U, y, seeded)
    assert fit.params["rate"] == pytest.approx(4.0, rel=0.02)
    _assert_nominal(fit)
    assert fit.ssr / T.size < 1.2 * SIGMA**2
    # without the accepted lag the same search must bend the nominal pole to mimic it: a worse fit
    alone = fit_augmented(G_OFF, T, U, y, _seeded(NestedEffect("lag", {}, "rate_limit"), [{"rate": 4.0}]))
    assert alone.ssr > 3 * fit.ssr and alone.nominal["d0"] < 4.9


def test_fit_drift_on_top_of_an_input_saturation():
    e = NestedEffect("saturation", {"upper": 1.2}, "drift")
    y = _noisy(e.apply(G, T, U, {"slope": 0.05}, offset=0.3), 3)
    fit = fit_augmented(G_OFF, T, U, y, e)
    assert fit.params["slope"] == pytest.approx(0.05, abs=0.002)
    assert fit.parameter_ci["slope"][0] < 0.05 < fit.parameter_ci["slope"][1]
    _assert_nominal(fit)
    assert fit.ssr / T.size < 1.2 * SIGMA**2


def test_fit_static_nonlinearity_on_top_of_a_rate_limit():
    e = NestedEffect("rate_limit", {"rate": 3.0}, "static_nonlinearity")
    y = _noisy(e.apply(G, T, U, SNL, offset=0.3), 4)
    fit = fit_augmented(G_OFF, T, U, y, e)
    assert fit.params["a2"] == pytest.approx(0.15, abs=0.01)
    assert fit.params["a3"] == pytest.approx(-0.1, abs=0.01)
    _assert_nominal(fit)


def test_fit_delay_on_top_of_a_resonance():
    e = NestedEffect("resonance", {"wn": 30.0, "zeta": 0.1}, "delay")
    y = _noisy(e.apply(G, T, U, {"delay": 0.05}, offset=0.3), 5)
    fit = fit_augmented(G_OFF, T, U, y, e)
    assert fit.params["delay"] == pytest.approx(0.05, abs=0.002)
    _assert_nominal(fit)
    assert fit.plant.delay == 0.0  # the extra delay is the effect's, the nominal keeps its own


def test_screen_rate_limit_on_top_of_a_lag():
    e = NestedEffect("lag", {"tau": 0.05}, "rate_limit")
    y = _noisy(e.apply(G, T, U, {"rate": 4.0}, offset=0.3), 6)
    s = screen_effect(e, [("nominal", G_OFF), ("refit", G)], T, U, y, T, U)
    assert s.params["rate"] == pytest.approx(4.0, rel=0.1)
    assert s.ssr / T.size < 2 * SIGMA**2


def test_is_an_effect():
    assert isinstance(NestedEffect("lag", {"tau": 0.05}, "rate_limit"), Effect)
