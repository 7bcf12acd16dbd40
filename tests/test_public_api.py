"""The public API takes what users hold: specs as mappings, text, paths or streams; python-control
models in and out of Plant, Loop and Controller; bad input as one-line SynthError subclasses."""

from __future__ import annotations

import io

import control
import numpy as np
import pytest
import yaml

import synth
from synth.controllers import Controller, as_controller
from synth.errors import ModelError, SpecError, SynthError
from synth.loop import Loop
from synth.plant import Plant, as_plant
from synth.spec import Spec, load_spec, parse_spec

from .conftest import ROOT, X4_PLANT

X4_SPEC = ROOT / "specs" / "x4_rotor.yaml"
X4_NUM = [23.0, 23.0 * 0.43]
X4_DEN = np.polymul([1.0, 9.6], [1.0, 0.54])
W = np.array([0.1, 1.0, 7.0, 60.0, 400.0])


def _one_line(exc: pytest.ExceptionInfo) -> str:
    text = str(exc.value)
    assert "\n" not in text and text.strip() == text
    return text


# ------------------------------------------------------------------------------------------- parse_spec
def test_parse_spec_from_mapping_text_path_and_stream_are_equal(tmp_path):
    text = X4_SPEC.read_text()
    from_path = load_spec(X4_SPEC)
    copy = tmp_path / "x4.yaml"
    copy.write_text(text)
    same = [
        parse_spec(X4_SPEC),
        parse_spec(str(X4_SPEC)),
        parse_spec(str(copy)),
        parse_spec(text),
        parse_spec(io.StringIO(text)),
        parse_spec(yaml.safe_load(text)),
        synth.parse_spec(yaml.safe_load(text)),
    ]
    with copy.open() as stream:
        same.append(parse_spec(stream))
    for spec in same:
        assert isinstance(spec, Spec)
        assert spec == from_path
    assert parse_spec(from_path) is from_path
    assert [r.type for r in same[-1].requirements] == ["sensitivity_static", "bandwidth", "slew_rate"]


def test_parse_spec_mapping_with_numpy_numbers():
    data = {"name": "demo", "plant": {"tf": X4_PLANT}, "controller": {"type": "P", "bounds": {"kp": np.array([0.0, 20.0])}},
            "requirements": [{"type": "bandwidth", "min": np.float64(60)}]}
    spec = parse_spec(data)
    assert spec.controller.all_bounds()["kp"] == (0.0, 20.0)
    assert spec.requirements[0].min == 60.0
    assert synth.check(spec, "P(3)").feasible


@pytest.mark.parametrize(("given", "fragment"), [
    ({"name": "x", "plant": {"tf": "1/(s+1)"}, "controller": {"type": "P"},
      "requirements": [{"type": "bandwidth", "min": "fast"}]},
     "<spec>: requirements[0].min: expected a number, got 'fast'"),
    ({"name": "x", "plant": {"tf": "1/(s+1)", "dlay": 0.1}, "controller": {"type": "P"},
      "requirements": [{"type": "bandwidth", "min": 2}]},
     "<spec>: plant.dlay: unknown key 'dlay'; did you mean 'delay'?"),
    ({"name": "x"}, "<spec>: plant: missing (required)"),
    ("nope.yaml", "nope.yaml: spec file not found"),
    ("just words", "'just words' is neither a spec file nor a spec's YAML text"),
    ("name: [x\n", "invalid YAML: expected ',' or ']'"),
    (3.5, "<spec>: cannot read a spec from a float"),
    ({(1, 2): 3}, "<spec>: the spec mapping cannot be read"),
])
def test_parse_spec_bad_input_is_one_line_spec_error(given, fragment):
    with pytest.raises(SpecError) as exc:
        parse_spec(given)
    assert fragment in _one_line(exc)
    assert isinstance(exc.value, SynthError)


def test_parse_spec_source_names_the_mapping():
    with pytest.raises(SpecError, match=r"^mine\.yaml: plant: missing \(required\)$"):
        parse_spec({"name": "x"}, source="mine.yaml")


# --------------------------------------------------------------------------------- python-control in
def test_loop_from_control_tf_has_the_margins_of_the_plant_string():
    by_text = Loop(Plant.from_string(X4_PLANT), Controller("P", {"kp": 3.0}))
    for plant in (control.tf(X4_NUM, X4_DEN), control.tf2ss(control.tf(X4_NUM, X4_DEN)), X4_PLANT, (X4_NUM, X4_DEN)):
        loop = Loop(plant, "P(3)")
        assert isinstance(loop.plant, Plant) and isinstance(loop.controller, Controller)
        assert loop.margins().phase_margin_deg == pytest.approx(by_text.margins().phase_margin_deg, rel=1e-9)
        assert loop.margins().gain_crossover == pytest.approx(by_text.margins().gain_crossover, rel=1e-9)
        assert loop.bandwidth() == pytest.approx(by_text.bandwidth(), rel=1e-9)
        np.testing.assert_allclose(loop.L(W), by_text.L(W), rtol=1e-9)
    assert by_text.bandwidth() == pytest.approx(83.16, abs=0.01)


def test_loop_from_control_with_delay_matches_the_plant_string_with_delay():
    by_text = Loop(Plant.from_string(X4_PLANT, delay=0.02), "P(3)")
    by_control = Loop(Plant.from_control(control.tf(X4_NUM, X4_DEN), delay=0.02), "P(3)")
    assert by_control.margins().gain_margin_db == pytest.approx(by_text.margins().gain_margin_db, rel=1e-9)
    assert by_control.margins().gain_margin_db == pytest.approx(1.79, abs=0.01)
    assert by_control.margins().phase_crossover == pytest.approx(84.28, abs=0.01)
    assert as_plant(control.tf(X4_NUM, X4_DEN), delay=0.02).delay == 0.02


def test_issue_example_loop_of_a_control_tf_and_a_controller():
    loop = synth.Loop(control.tf([23], [1, 10]), synth.Controller("P", {"kp": 3}))
    # L = 69/(s+10): |L| = 1 at w = sqrt(69^2 - 10^2); T = 69/(s+79) is 3 dB down at 79 sqrt(10^0.3 - 1)
    assert loop.crossover() == pytest.approx(np.sqrt(69.0**2 - 10.0**2), rel=1e-12)
    assert loop.bandwidth() == pytest.approx(79.0 * np.sqrt(10**0.3 - 1), rel=1e-6)
    assert loop.bandwidth() == pytest.approx(control.bandwidth(control.feedback(control.tf([69], [1, 10]))), rel=1e-6)
    assert loop.stability().stable


def test_margins_agree_with_python_control():
    G = control.tf(X4_NUM, X4_DEN)
    for text in ("P(3)", "PI(kp=0.5, ki=4)", "leadlag(k=20, z=5, p=50)", "PID(1, 2, 0.1, 0.01)"):
        C = Controller.from_string(text)
        _gm, pm, _w_gm, w_pm = control.margin(C.to_control() * G)
        m = Loop(G, C).margins()
        assert m.gain_crossover is not None
        assert m.phase_margin_deg == pytest.approx(pm, abs=1e-6)
        assert m.gain_crossover == pytest.approx(w_pm, rel=1e-6)


# -------------------------------------------------------------------------------- python-control out
@pytest.mark.parametrize("text", ["P(3)", "PI(kp=1.2, ki=20)", "PID(1, 2, 0.1, 0.01)", "leadlag(k=2, z=1, p=10)",
                                  "rational(b0=2, b1=1, a0=0, a1=10)"])
def test_controller_to_control_round_trip(text):
    C = Controller.from_string(text)
    sys = C.to_control()
    assert isinstance(sys, control.TransferFunction) and sys.isctime()
    np.testing.assert_allclose(sys(1j * W), C.freqresp(W), rtol=1e-12)
    np.testing.assert_allclose(sys.num[0][0], C.tf()[0])
    np.testing.assert_allclose(sys.den[0][0], C.tf()[1])


def test_plant_to_control_exact_without_delay_and_back():
    G = Plant.from_string(X4_PLANT)
    sys = G.to_control()
    np.testing.assert_allclose(sys(1j * W), G.freqresp(W), rtol=1e-12)
    assert control.dcgain(sys) == pytest.approx(G.dc_gain(), rel=1e-12)
    back = Plant.from_control(sys)
    np.testing.assert_allclose(back.num, G.num, rtol=1e-14)
    np.testing.assert_allclose(back.den, G.den, rtol=1e-14)
    assert back.delay == 0.0


@pytest.mark.parametrize("order", [1, 3, 6])
def test_plant_to_control_with_delay_is_the_given_pade(order):
    G = Plant.from_string(X4_PLANT, delay=0.02)
    sys = G.to_control(pade_order=order)
    pnum, pden = control.pade(0.02, order)
    expected = control.tf(X4_NUM, X4_DEN) * control.tf(pnum, pden)
    np.testing.assert_allclose(sys(1j * W), expected(1j * W), rtol=1e-10)
    assert sys.den[0][0].size == 2 + 1 + order  # two plant poles, `order` Pade poles
    # the Pade approximation is all-pass: magnitudes are exact, phase close below 1/delay
    np.testing.assert_allclose(np.abs(sys(1j * W)), np.abs(G.freqresp(W)), rtol=1e-9)
    low = W[W < 10]
    np.testing.assert_allclose(sys(1j * low), G.freqresp(low), rtol=2e-2)


def test_plant_to_control_never_drops_a_delay():
    G = Plant.from_string(X4_PLANT, delay=0.02)
    with pytest.raises(ModelError) as exc:
        G.to_control()
    assert "pade_order" in _one_line(exc) and "0.02 s delay" in str(exc.value)
    for bad in (0, -1, 2.5, True):
        with pytest.raises(ModelError, match="pade_order must be a whole number >= 1"):
            G.to_control(pade_order=bad)


# ---------------------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(("model", "fragment"), [
    (control.tf([1.0], [1.0, -0.5], 0.01), "discrete-time model (dt = 0.01)"),
    (control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]], True), "discrete-time model"),
    (control.tf([[[1.0], [2.0]]], [[[1.0, 1.0], [1.0, 2.0]]]), "has 2 input(s) and 1 output(s)"),
    (control.ss(-np.eye(2), np.eye(2), np.eye(2), np.zeros((2, 2))), "has 2 input(s) and 2 output(s)"),
    (control.tf([1.0, 0.0, 0.0], [1.0, 1.0]), "improper transfer function"),
])
def test_discrete_mimo_or_improper_control_models_are_model_errors(model, fragment):
    for make in (Plant.from_control, as_plant, lambda m: Loop(m, "P(1)")):
        with pytest.raises(ModelError) as exc:
            make(model)
        assert fragment in _one_line(exc)


def test_other_types_are_model_errors():
    with pytest.raises(ModelError, match="expected a python-control TransferFunction or StateSpace, got list"):
        Plant.from_control([1.0, 2.0])
    with pytest.raises(ModelError, match="cannot make a plant from a float"):
        Loop(2.0, "P(1)")
    with pytest.raises(ModelError, match="cannot make a controller from a TransferFunction"):
        Loop(X4_PLANT, control.tf([3.0], [1.0]))
    with pytest.raises(ModelError) as exc:
        Loop(X4_PLANT, "P(3")
    assert "cannot parse controller 'P(3'" in _one_line(exc)
    assert as_controller("P(3)") == Controller("P", {"kp": 3.0})


def test_one_line_yaml_text_is_text_and_a_yaml_name_is_a_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "pi.yml").write_text((ROOT / "specs" / "x4_rotor_pi.yaml").read_text())
    assert parse_spec("pi.yml").controller.type == "PI"
    flow = "{name: x, plant: {tf: '1/(s+1)'}, controller: {type: P}, requirements: [{type: bandwidth, min: 2}]}"
    assert parse_spec(flow).requirements[0].min == 2.0
