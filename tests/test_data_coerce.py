"""as_record: a Record from whatever the user holds (arrays, tables, a path), and identify taking them."""

from __future__ import annotations

import numpy as np
import pytest

import synth
from synth.data import Record, as_record, load_record, record_from_arrays
from synth.errors import DataError
from synth.ident.identification import identify
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

T = np.arange(0, 2, 0.01)
U = np.where(T >= 0.5, 1.0, 0.0)
Y = 1.0 + np.cumsum(U) * 0.01


def _same(r: Record, t: np.ndarray = T, u: np.ndarray = U, y: np.ndarray = Y) -> None:
    assert isinstance(r, Record)
    np.testing.assert_array_equal(r.t, t)
    np.testing.assert_array_equal(r.u, u)
    np.testing.assert_array_equal(r.y, y)


def test_from_arrays():
    r = as_record((T, U, Y))
    _same(r)
    assert (r.input.name, r.output.name, r.source) == ("input", "output", "arrays")
    _same(as_record([T.tolist(), U.tolist(), Y.tolist()]))


def test_from_arrays_with_names_and_units():
    r = as_record((T, U, Y), input="pwm", output="speed", input_unit="%", output_unit="rad/s")
    assert (r.input.label(), r.output.label()) == ("pwm [%]", "speed [rad/s]")


def test_from_n_by_3_and_3_by_n_arrays():
    _same(as_record(np.column_stack([T, U, Y])))
    _same(as_record(np.vstack([T, U, Y])))
    _same(as_record(np.column_stack([T, U, Y]).tolist()))  # a list of [t, u, y] rows


def test_from_input_and_output_with_dt():
    r = as_record((U, Y), dt=0.01)
    np.testing.assert_allclose(r.t, np.arange(U.size) * 0.01)
    np.testing.assert_array_equal(r.u, U)
    assert r.dt == pytest.approx(0.01)
    np.testing.assert_array_equal(as_record(np.column_stack([U, Y]), dt=0.01).y, Y)


def test_from_a_dict():
    _same(as_record({"t": T, "u": U, "y": Y}))
    r = as_record({"speed": Y, "time": T, "cmd": U, "current": 2 * U}, time="time", input="cmd", output="speed",
                  aux=["current"])
    _same(r)
    assert (r.input.name, r.output.name) == ("cmd", "speed")
    np.testing.assert_array_equal(r.aux["current"], 2 * U)


def test_from_a_dataframe():
    pd = pytest.importorskip("pandas")
    df = pd.DataFrame({"time": T, "cmd": U, "speed": Y, "note": ["run 1"] * T.size})
    r = as_record(df, time="time", input="cmd", output="speed", output_unit="rad/s")
    _same(r)
    assert r.output.label() == "speed [rad/s]"
    indexed = pd.DataFrame({"cmd": U, "speed": Y}, index=pd.Index(T, name="t"))
    _same(as_record(indexed, time="index", input="cmd", output="speed"))
    _same(as_record(df.drop(columns="note")))  # columns in order: time, input, output


def test_from_a_path(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text("t,pwm,speed\n" + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(T.tolist(), U.tolist(), Y.tolist())))
    r = as_record(path, input_unit="PWM")
    _same(r)
    assert (r.input.label(), r.source) == ("pwm [PWM]", str(path))
    _same(as_record(str(path), time="t", input="pwm", output="speed"))
    assert as_record(path).to_dict() == load_record(path).to_dict()


def test_a_record_is_returned_as_it_is():
    r = record_from_arrays(T, U, Y)
    assert as_record(r) is r
    assert as_record(r, output_unit="rad/s") is r


@pytest.mark.parametrize("data, options, message", [
    (42, {}, "int: not a record; give a Record, (t, u, y) arrays, columns or a CSV/MAT path"),
    ("missing.csv", {}, "missing.csv: file not found"),
    ((U, Y), {}, "arrays: got 2 arrays; give (t, u, y), or (u, y) with dt"),
    (np.column_stack([T, U, Y, Y]), {}, "arrays: got 4 arrays; give (t, u, y), or (u, y) with dt"),
    (np.zeros((2, 2, 2)), {}, "ndarray: not a record"),
    ((T, U, Y[:50]), {}, "arrays: columns have different lengths ('time' 200, 'input' 200, 'output' 50)"),
    ((T, np.zeros_like(T), Y), {}, "arrays: column 'input': the input is constant (0); nothing excites the plant"),
    ({"t": T, "u": U, "y": ["a"] * T.size}, {}, "columns: column 'y' is not numeric"),
    ({"t": T, "u": U, "y": Y}, {"output": "speed"}, "columns: output column 'speed' not found"),
])
def test_bad_forms_are_one_line_data_errors(data, options, message):
    with pytest.raises(DataError) as err:
        as_record(data, **options)
    text = str(err.value)
    assert text.startswith(message) and "\n" not in text


def test_a_non_numeric_dataframe_column_is_named():
    pd = pytest.importorskip("pandas")
    df = pd.DataFrame({"label": ["x"] * T.size, "t": T, "u": U, "y": Y})
    with pytest.raises(DataError, match=r"^DataFrame: column 'label' is not numeric$"):
        as_record(df)
    _same(as_record(df, time="t", input="u", output="y"))


def test_identify_from_arrays_equals_identify_from_the_record():
    t = np.arange(0, 3, 0.01)
    u = np.where(t >= 0.5, 1.0, 0.0)
    y = 0.5 + simulate_plant(Plant.from_string("2/(s+3)", delay=0.03), t, u)
    from_record = identify(record_from_arrays(t, u, y), "k/(s+p)", delay="fit", average="none")
    for data in ((t, u, y), np.column_stack([t, u, y])):
        from_arrays = identify(data, "k/(s+p)", delay="fit", average="none")
        assert from_arrays.fit.parameters == from_record.fit.parameters
        assert from_arrays.fit.std == from_record.fit.std
        assert from_arrays.plant.to_string(6) == from_record.plant.to_string(6) == "exp(-0.03*s)*2/(s+3)"
        assert from_arrays.to_dict()["record"] == from_record.to_dict()["record"]
    via_package = synth.identify((t, u, y), "k/(s+p)", delay="fit", average="none")
    assert via_package.fit.parameters == from_record.fit.parameters


def test_the_package_exports_the_record_builders():
    assert synth.as_record is as_record
    assert synth.record_from_arrays is record_from_arrays
    assert {"as_record", "record_from_arrays"} <= set(synth.__all__)
