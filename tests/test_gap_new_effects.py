"""The effects of issue 17 on simulated records: direction, cubic spring, measured supply; non-default; reasons."""

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.gap.diagnose import diagnose
from synth.gap.effects import DEFAULT_CANDIDATES, make_effect
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

G = Plant.from_string("2/(0.2*s+1)")


def test_new_effects_are_not_default_candidates_and_say_why():
    for name in ("direction", "duffing", "amplitude_damping", "measured_sag(V)", "aux_input(V)"):
        eff = make_effect(name)
        assert eff.label not in DEFAULT_CANDIDATES and eff.excluded_because
    assert make_effect("measured_sag(Battery V)").aux_channel == "Battery V"


def test_direction_names_slow_up_fast_down():
    t = np.arange(0, 24, 0.01)
    u = np.array([0.0, 1.0, 0.4, 1.5, 0.2, 1.1, 0.0, 0.8])[(t // 1.5).astype(int) % 8]
    truth = {"tau_up": 0.15, "tau_down": 0.0}
    y = make_effect("direction").apply(G, t, u, truth) + 0.005 * np.random.default_rng(0).normal(size=t.size)
    dg = diagnose(Plant.from_string("2.06/(0.21*s+1)"), (t, u, y), candidates=["direction", "lag"], max_effects=1,
                  n_null=9)
    assert dg.verdict["effects"] == ["direction"]
    p = next(e for e in dg.attribution.effects if e.effect == "direction").parameters
    assert p["tau_up"] > 0.1 and p["tau_down"] < 0.05


def test_duffing_recovers_a_hardening_spring():
    P = Plant.from_string("400/(s^2+4*s+400)")
    t = np.arange(0, 20, 0.005)
    rng = np.random.default_rng(1)
    u = np.repeat(rng.normal(size=t.size // 20), 20) * np.linspace(0.2, 1.0, t.size)
    a = float(np.max(np.abs(simulate_plant(P, t, u))))
    truth = 0.2 / a**2  # the spring adds 60 % to the tangent stiffness at the largest amplitude
    y = make_effect("duffing").bind([], P).apply(P, t, u, {"cubic": truth})
    y = y + 0.002 * rng.normal(size=t.size)
    dg = diagnose(P, (t, u, y), candidates=["duffing"], max_effects=1, n_null=9)
    assert dg.verdict["effects"] == ["duffing"]
    cubic = dg.attribution.effects[0].parameters["cubic"]
    assert cubic == pytest.approx(truth, rel=0.2)


def test_measured_voltage_drives_the_sag_and_the_verdict_says_how_much():
    t = np.arange(0, 24, 0.01)
    u = np.array([0.0, 1.0, 0.4, 1.5, 0.2, 1.1, 0.0, 0.8])[(t // 1.5).astype(int) % 8]
    v = 12.0 - 1.5 * (np.sin(0.37 * t) > 0.3)  # a measured supply that sags independently of the command
    y = simulate_plant(G, t, u * v / 12.0) + 0.005 * np.random.default_rng(2).normal(size=t.size)
    rec = record_from_arrays(t, u, y, aux={"V": v})
    dg = diagnose(G, rec, candidates=["measured_sag(V)", "supply_sag", "delay"], max_effects=1, n_null=9)
    assert dg.verdict["effects"] == ["measured_sag(V)"]
    sag = next(e for e in dg.attribution.effects if e.effect == "measured_sag(V)")
    assert sag.parameters["sag"] == pytest.approx(1.0, abs=0.1)
    assert dg.verdict["aux"][0]["channel"] == "V" and dg.verdict["aux"][0]["accepted"]
    assert "V 0.9" in dg.summary or "V 1.0" in dg.summary
    # with the channel the default candidates include the aux-driven effects; without it they do not
    assert "measured_sag(V)" in dg.to_dict()["verdict"]["effects"]
    with pytest.raises(Exception, match="no column 'W'"):
        diagnose(G, rec, candidates=["measured_sag(W)"], n_null=3)


def test_cli_aux_drives_the_sag_and_prints_what_it_explained(run_cli, tmp_path):
    t = np.arange(0, 24, 0.01)
    u = np.array([0.0, 1.0, 0.4, 1.5, 0.2, 1.1, 0.0, 0.8])[(t // 1.5).astype(int) % 8]
    v = 12.0 - 1.5 * (np.sin(0.37 * t) > 0.3)
    y = simulate_plant(G, t, u * v / 12.0) + 0.005 * np.random.default_rng(2).normal(size=t.size)
    path = tmp_path / "run.csv"
    np.savetxt(path, np.c_[t, u, y, v], delimiter=",", header="t,u,y,V", comments="")
    r = run_cli("diagnose", "--plant", "2/(0.2*s+1)", "--data", str(path), "--aux", "V", "--candidates",
                "measured_sag(V),delay", "--no-report", "--json", str(tmp_path / "gap.json"))
    assert r.code == 0, r.err
    assert "aux V: measured_sag(V) shrinkage" in r.out and "accepted" in r.out
    import json

    data = json.loads((tmp_path / "gap.json").read_text())
    assert data["verdict"]["effects"] == ["measured_sag(V)"] and data["verdict"]["aux"][0]["channel"] == "V"
    assert "not_carried" in data["verdict"]
