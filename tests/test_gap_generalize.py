"""The generalizing benchmark's truth (scipy reference) against synth's effects, a seeded sample of it, and the
amplitude-dependent damping effect on a record simulated by the reference."""

import numpy as np
import pytest

from benchmarks.gap.generalize import diagnose_problem
from benchmarks.gap.problems import case_list, experiment, make_problem, random_plant
from benchmarks.gap.reference import TruePlant, simulate_reference
from synth.gap.diagnose import diagnose
from synth.gap.effects import AmplitudeDampingEffect, make_effect
from synth.plant import Plant


def exact(f: float) -> dict:
    """Effects whose discrete model is the continuous one sampled exactly (held command); ``f`` the fastest time
    constant."""
    return {None: {}, "delay": {"delay": 0.7 * f}, "lag": {"tau": 0.5 * f}, "resonance": {"wn": 1.5 / f, "zeta": 0.2},
            "deadzone": {"width": 0.4, "center": 0.5}, "backlash": {"width": 0.5}, "saturation": {"upper": 1.2},
            "quantization": {"step": 0.3, "offset": 0.1}, "drift": {"slope": 0.02 / f},
            "static_nonlinearity": {"a2": -0.4, "a3": 0.3, "center": 0.8, "scale": 0.9}}


def continuous(f: float, gain: float) -> dict:
    """Continuous-time effects: the discrete model differs within a sample."""
    return {"rate_limit": {"rate": 0.3 / f}, "supply_sag": {"sag": 0.3, "tau": 4 * f},
            "duffing": {"cubic": 0.3 / gain**2}, "amplitude_damping": {"drag": 0.3 * f**2 / gain},
            "direction": {"tau_up": 3 * f, "tau_down": 0.6 * f, "delay_up": 0.6 * f, "delay_down": 0.0}}


@pytest.fixture(scope="module")
def seeded_record():
    rng = np.random.default_rng(5)
    draw = random_plant(rng, "third_order", 1000)
    t, u = experiment(rng, "steps", draw, 1000)
    u = (u - u.min()) / np.ptp(u) * 1.8  # the effects' parameters above are in these units
    G = Plant(np.array(draw.plant.num), np.array(draw.plant.den), draw.plant.delay)
    return draw, G, t, u


def _synth(G, name, t, u, params):
    eff = make_effect(name).bind([], G)
    return eff.apply(G, t, u, {**eff.off(), **params})


def test_reference_and_synth_agree_on_exactly_sampled_effects(seeded_record):
    draw, G, t, u = seeded_record
    y_lin = simulate_reference(draw.plant, t, u)
    for name, params in exact(draw.fast).items():
        y_ref = simulate_reference(draw.plant, t, u, name, params)
        y = _synth(G, name or "delay", t, u, params or {"delay": 0.0})
        assert np.max(np.abs(y - y_ref)) < 1e-6 * np.ptp(y_lin), name
        if name is not None:
            assert np.sqrt(np.mean((y_ref - y_lin) ** 2)) > 1e-3 * np.ptp(y_lin), name  # the effect acts


def test_reference_and_synth_agree_within_a_sample_on_continuous_effects(seeded_record):
    draw, G, t, u = seeded_record
    y_lin = simulate_reference(draw.plant, t, u)
    for name, params in continuous(draw.fast, draw.plant.gain).items():
        y_ref = simulate_reference(draw.plant, t, u, name, params)
        effect = np.sqrt(np.mean((y_ref - y_lin) ** 2))
        diff = np.sqrt(np.mean((_synth(G, name, t, u, params) - y_ref) ** 2))
        assert effect > 1e-3 * np.ptp(y_lin) and diff < 0.15 * effect, (name, diff / effect)


@pytest.mark.parametrize("family", ["first_order", "resonant", "third_order"])
def test_superposition_agrees_with_the_piecewise_integration_and_the_exact_sampling(family):
    """The linear effects' fast path (one step response, superposed) against the piecewise ``solve_ivp``
    integration (one call per command change) and, without delay, the exact zero-order-hold recursion."""
    from scipy.linalg import expm

    from benchmarks.gap.problems import supply_voltage

    rng = np.random.default_rng(8)
    draw = random_plant(rng, family, 1000)
    t, u = experiment(rng, "noise", draw, 1000)
    v = supply_voltage(rng, t, u, draw.settle)
    span = np.ptp(simulate_reference(draw.plant, t, u))
    for name, params in {None: {}, "delay": {"delay": 2.37 * (t[1] - t[0])}, "lag": {"tau": 0.5 * draw.fast},
                         "backlash": {"width": 0.2 * np.ptp(u)},
                         "measured_sag": {"sag": 0.5, "v_nominal": 12.6, "u_rest": float(u.min())}}.items():
        fast = simulate_reference(draw.plant, t, u, name, params, aux=v)
        slow = simulate_reference(draw.plant, t, u, name, params, aux=v, method="piecewise")
        assert np.max(np.abs(fast - slow)) < 1e-8 * span, name
    P = TruePlant(draw.plant.num, draw.plant.den)
    A, B, C, D = P.state_space()
    m = A.shape[0]
    M = expm(np.block([[A, B[:, None]], [np.zeros((1, m + 1))]]) * (t[1] - t[0]))
    x, y = -np.linalg.solve(A, B * u[0]), np.empty(t.size)
    for k in range(t.size):  # the output at a sample sees the value held before it
        y[k] = C @ x + D * u[max(k - 1, 0)]
        x = M[:m, :m] @ x + M[:m, m] * u[k]
    assert np.max(np.abs(simulate_reference(P, t, u) - y)) < 1e-10 * span


def test_seeded_benchmark_sample_is_named_with_its_shrinkage():
    """Two seeded problems of the benchmark, each diagnosed with four of its candidates (all of them: 10-40 s)."""
    lengths = (1000,)
    names = ("deadzone", "backlash", "saturation", "static_nonlinearity")
    index = next(i for i, c in enumerate(case_list(lengths)) if c[0] == "deadzone" and c[4] == "steps")
    p = make_problem(3, index, lengths)
    dg = diagnose_problem(p, names=names)
    assert dg.verdict["effects"][0] == "deadzone"
    named = next(e for e in dg.effects if e.effect == "deadzone")
    assert abs(named.shrinkage - p.true_shrinkage) <= 0.05
    free = next(i for i, c in enumerate(case_list(lengths)) if c[0] is None and c[4] == "steps")
    assert diagnose_problem(make_problem(3, free, lengths), names=names).verdict["effects"] in ([], ["parameter_mismatch"])


def test_amplitude_damping_recovers_the_drag_of_a_reference_record():
    P = TruePlant((400.0,), (1.0, 4.0, 400.0))
    t = np.arange(0, 12, 0.01)
    rng = np.random.default_rng(1)
    u = np.repeat(rng.normal(size=t.size // 10), 10) * np.linspace(0.2, 1.0, t.size)
    a, v = AmplitudeDampingEffect.scales(t, u, Plant.from_string("400/(s^2+4*s+400)"))
    truth = 0.5 * a / v**2  # the force at the fastest rate is half the output amplitude
    y = simulate_reference(P, t, u, "amplitude_damping", {"drag": truth}) + 0.002 * rng.normal(size=t.size)
    dg = diagnose(Plant.from_string("410/(s^2+4.1*s+395)"), (t, u, y), candidates=["amplitude_damping"],
                  max_effects=1, n_null=9)
    assert dg.verdict["effects"] == ["amplitude_damping"]
    assert dg.attribution.effects[0].parameters["drag"] == pytest.approx(truth, rel=0.15)  # measured 0.92 x truth
