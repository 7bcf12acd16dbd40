"""Real records as they come (../shared/data): each test checks numbers the folder's README.txt documents.

- esc_thrust_stand_1s: RCbenchmark CSV logs with units in every header, a BOM, trailing commas, a text
  column, repeated and jittered time stamps; the ESC command is a staircase and must stay one (its integral kept).
- hsm150_two_motor_steps: MAT files whose record is a 20000 x 7 matrix ``data``.
- silverbox_duffing: CSV without a time column (fs = 10^7 / 2^14 Hz), quoted headers, trailing commas.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.data import load_record
from synth.data.readers import read_table
from tests.conftest import shared_path

ESC = "esc_thrust_stand_1s"
# README: rows, duration [s], typical interval [s], first/last ESC command [us], increment [us]
ESC_FILES = {
    "StepsTest20230615_2023-06-15_174003.csv": (2001, 47.0, 0.023, 1000.0, 2000.0, 0.5),
    "StepsTest20230624_2023-06-24_190243.csv": (101, 5.0, 0.050, 1000.0, 2000.0, 10.0),
    "StepsTest_2020-06-16_220513.csv": (21, 67.0, 3.5, 1300.0, 1960.0, 33.0),
}


@pytest.mark.parametrize("name", list(ESC_FILES))
def test_esc_log_reads_with_units_and_the_readme_shape(name):
    rows, duration, interval, first, last, _ = ESC_FILES[name]
    tab = read_table(shared_path("data", ESC, name))
    # README: "2001 x 20 numeric (+App message, +trailing empty)"; the trailing empty header is dropped
    assert len(tab.names()) == 21 and tab.names()[-1] == "App message"
    assert all(v.size == rows for v in tab.columns.values())
    assert tab.units["Time (s)"] == "s" and tab.units["Voltage (V)"] == "V" and tab.units["ESC signal (µs)"] == "µs"
    t, esc = tab.columns[tab.find("Time")], tab.columns[tab.find("ESC signal")]
    assert t[-1] - t[0] == pytest.approx(duration, abs=0.6)
    assert np.median(np.diff(t)) == pytest.approx(interval, rel=0.1)
    assert (esc[0], esc[-1]) == (first, last)
    assert np.all(np.diff(t) >= 0) and np.all(np.diff(esc) >= 0)  # README: monotonic, non-decreasing


@pytest.mark.parametrize("name", list(ESC_FILES))
def test_esc_command_stays_a_staircase_after_resampling(name):
    rows, _, _, first, last, step = ESC_FILES[name]
    path = shared_path("data", ESC, name)
    native = read_table(path).columns["Time (s)"]
    repeated = int(np.sum(np.diff(native) == 0))  # a level logged at the same instant as the next cannot be kept
    r = load_record(path, "Time (s)", "ESC signal", "Thrust", aux=["Voltage"])
    assert (r.input.label(), r.output.label()) == ("ESC signal [µs]", "Thrust [gf]")
    # README: first -> last in `step` increments, one level per row, non-decreasing. Each grid interval holds the
    # logged command's mean over it (each row's level held to the next row's stamp), so the staircase's integral
    # is kept at every grid point; a level over two grid intervals or more keeps its value exactly on one of them
    dt = float(r.t[1] - r.t[0])
    native_u = read_table(path).columns["ESC signal (µs)"]
    keep = np.r_[np.diff(native) > 0, True]  # the last of the rows sharing a stamp
    stamps, values = native[keep], native_u[keep]
    assert values.size == rows - repeated  # one level per row, less one per repeated stamp
    integral = np.r_[0.0, np.cumsum(values[:-1] * np.diff(stamps))]
    np.testing.assert_allclose(np.cumsum(r.u[:-1]) * dt, np.interp(r.t[1:], stamps, integral), rtol=1e-9)
    assert np.all(np.diff(r.u) >= -1e-9 * last) and r.u.min() >= first  # still a non-decreasing staircase
    long = values[:-1][np.diff(stamps) >= 2 * dt * (1 + 1e-9)]
    assert np.all(np.isin(long, r.u))
    exact = r.u[np.isin(r.u, values)]
    assert np.allclose((exact - first) / step, np.round((exact - first) / step))
    assert r.u[-1] == last and r.u.max() == last and native_u[-1] == last
    assert any("zero-order hold" in n for n in r.notes) and any("'Thrust (gf)'" in n for n in r.notes)
    assert (repeated > 0) == any(n.startswith("repeated time stamps") for n in r.notes)


def test_esc_supply_sag_and_peaks_as_the_readme_states():
    tab = read_table(shared_path("data", ESC, "StepsTest20230615_2023-06-15_174003.csv"))
    v, i, f = (tab.columns[tab.find(k)] for k in ("Voltage", "Current", "Thrust"))
    assert (round(v[0], 2), round(v.min(), 2)) == (4.01, 3.14)  # "Supply sags 4.01 -> 3.14 V"
    assert round(i.max(), 2) == 4.42 and round(f.max(), 1) == 25.7  # "current rises to 4.42 A; thrust up to 25.7 gf"
    tab = read_table(shared_path("data", ESC, "StepsTest_2020-06-16_220513.csv"))
    rpm, v = tab.columns[tab.find("Motor Electrical Speed (RPM)")], tab.columns[tab.find("voltage")]
    assert (round(rpm.min() / 1e3, 1), round(rpm.max() / 1e3, 1)) == (16.8, 43.1)  # "RPM (16.8k-43.1k)"
    assert (round(v[0], 2), round(v[-1], 2)) == (11.82, 10.91)  # "voltage 11.82 -> 10.91 V (3S)"


def test_esc_log_with_the_issue_trailing_comment_loads(tmp_path):
    """Issue 16: a trailing "# a-> Type: ..." line stopped the loader; comments before the header too."""
    text = shared_path("data", ESC, "StepsTest20230624_2023-06-24_190243.csv").read_text(encoding="utf-8-sig")
    lines = text.splitlines()
    p = tmp_path / "log.csv"
    p.write_text("# RCbenchmark log\n" + "\n".join([*lines[:40], "# a-> Type: Steps, note", *lines[40:]])
                 + "\n# a-> Type: Steps test finished\n", encoding="utf-8")
    r = load_record(p, "Time", "ESC signal (µs)", "Thrust (gf)")
    plain = load_record(shared_path("data", ESC, "StepsTest20230624_2023-06-24_190243.csv"), "Time",
                        "ESC signal (µs)", "Thrust (gf)")
    assert r.notes[0] == "skipped 3 comment line(s) starting with #"
    assert r.t.tolist() == plain.t.tolist() and r.u.tolist() == plain.u.tolist() and r.y.tolist() == plain.y.tolist()
    assert r.u.min() >= 1000.0 and r.u[-1] == 2000.0 and r.u.size >= 100  # README: 101 rows, 1000 -> 2000 us


HSM = "hsm150_two_motor_steps"


def test_hsm150_matrix_columns_and_step_at_ten_seconds():
    path = shared_path("data", HSM, "idf_neg_0.04_1.mat")
    tab = read_table(path)
    # README: data (20000 x 7) plus 20000-sample vectors Iz1, Iz, Im1, Im; scalars (J, B, ...) are no columns
    assert sorted(tab.columns) == ["Im", "Im1", "Iz", "Iz1"] + [f"data[{k}]" for k in range(7)]
    cols = {"data[0]": "t", "data[4]": "torque", "data[3]": "velocity"}
    r = load_record(path, "t", "torque", "velocity", columns=cols, input_unit="N m", output_unit="rad/s")
    assert (r.n, r.dt, r.duration) == (20000, 0.001, 19.999)  # 1 kHz, 20 s per run
    assert np.unique(r.u).tolist() == [-0.04, -0.03]  # -0.030 -> -0.040 N m
    assert r.t[np.flatnonzero(np.diff(r.u)) + 1].tolist() == [10.0]  # second step at t = 10.000 s
    assert r.notes == ()


@pytest.mark.parametrize(("run", "plateau"), [(1, -143), (2, -157), (3, -159)])
def test_hsm150_run_to_run_plateaus(run, plateau):
    """README: "neg_0.04 plateau -143 / -157 / -159 rad/s" (2-s means before the second step)."""
    r = load_record(shared_path("data", HSM, f"idf_neg_0.04_{run}.mat"), "data[0]", "data[4]", "data[3]")
    assert r.y[(r.t >= 8) & (r.t < 10)].mean() == pytest.approx(plateau, abs=1)


# README: file name -> torque levels [N m]; first plateau [rad/s]; incremental gain [rad/s per 0.010 N m]
HSM_RUNS = {"neg_0.04": ((-0.030, -0.040), (-170, -143), (40, 46)), "neg_0.045": ((-0.030, -0.045), (-170, -143), None),
            "pos_0.06": ((0.050, 0.060), (139, 147), (71, 97)), "pos_0.065": ((0.050, 0.065), (139, 147), None)}


@pytest.mark.parametrize("run", [1, 2, 3])
@pytest.mark.parametrize("kind", list(HSM_RUNS))
def test_hsm150_levels_plateaus_and_direction_gains(kind, run):
    levels, plateau, gain = HSM_RUNS[kind]
    r = load_record(shared_path("data", HSM, f"idf_{kind}_{run}.mat"), "data[0]", "data[4]", "data[3]")
    assert (r.u[0], r.u[-1]) == levels and r.t[np.flatnonzero(np.diff(r.u)) + 1].tolist() == [10.0]
    first = r.y[(r.t >= 8) & (r.t < 10)].mean()
    assert plateau[0] - 1 <= first <= plateau[1] + 1  # "-0.030 N m gives about -143..-170 rad/s", "+139..+147"
    if gain:  # "negative runs ~ -40..-46 rad/s per -0.010 N m, positive runs ~ +71..+97 rad/s per +0.010 N m"
        second = r.y[r.t >= 18].mean()
        assert gain[0] - 1 <= (second - first) / ((levels[1] - levels[0]) / 0.010) <= gain[1] + 1


def test_hsm150_columns_map_on_the_cli(run_cli):
    path = shared_path("data", HSM, "idf_pos_0.06_1.mat")
    res = run_cli("psd", "--data", str(path), "--columns", "data[0]=t,data[3]=speed", "--time", "t",
                  "--signal", "speed", "--unit", "rad/s", "--json", "-")
    assert res.code == 0, res.err
    rec = json.loads(res.out)["records"][0]
    assert (rec["samples"], rec["dt"], rec["signal"]) == (20000, 0.001, "speed")
    res = run_cli("psd", "--data", str(path), "--columns", "data[9]=speed", "--signal", "speed", "--dt", "0.001")
    assert res.code == 2 and "columns map: column 'data[9]' not found" in res.err and "data[6]" in res.err


SILVERBOX = "silverbox_duffing"
FS = 1e7 / 2**14  # README: fs = 10^7 / 2^14 = 610.3515625 Hz


@pytest.mark.parametrize(("name", "names", "std_v1", "std_v2"), [
    ("SNLS80mV.csv", ["V1", "V2"], 21.9, 53.4),
    ("Schroeder80mV.csv", ["Ovld2", "Ovld1", "V1", "V2"], 26.8, 63.0),
])
def test_silverbox_columns_rate_and_levels(name, names, std_v1, std_v2):
    path = shared_path("data", SILVERBOX, name)
    assert read_table(path).names() == names  # the trailing comma's empty column is dropped
    r = load_record(path, input="V1", output="V2", dt=1 / FS, input_unit="V", output_unit="V")
    assert r.n == 131072 and r.fs == pytest.approx(610.3515625, rel=1e-9)
    assert r.duration == pytest.approx(131071 / FS)
    assert (round(1e3 * r.u.std(), 1), round(1e3 * r.y.std(), 1)) == (std_v1, std_v2)  # mV, README
    if name == "SNLS80mV.csv":  # README: V1 -0.123..0.149 V, V2 -0.300..0.276 V
        assert [round(x, 3) for x in (r.u.min(), r.u.max(), r.y.min(), r.y.max())] == [-0.123, 0.149, -0.3, 0.276]


def test_silverbox_missing_column_lists_what_was_found():
    from synth.errors import DataError

    with pytest.raises(DataError, match=r"output column 'V3' not found; columns are V1, V2$"):
        load_record(shared_path("data", SILVERBOX, "SNLS80mV.csv"), input="V1", output="V3", dt=1 / FS)


def test_silverbox_without_a_time_column_is_identified_with_dt(run_cli, tmp_path):
    """Found by a black-box test: ``identify`` had no ``--dt``, so the Silverbox record (no time column; fs = 10^7 /
    2^14 Hz per its README) could not be identified ("column 'V1' is given as both the time and the input
    column"). With ``--dt`` the whole record's resonance is 71.0 Hz: just above the README's own check on the
    arrow part's windows (68.2-70.6 Hz, rising with the amplitude as the cubic stiffness hardens); a wrong
    sample interval would move it in proportion."""
    path = shared_path("data", "silverbox_duffing", "SNLS80mV.csv")
    res = run_cli("identify", "--data", str(path), "--input", "V1", "--output", "V2", "--dt", str(2.0 ** 14 / 1e7),
                  "--structure", "K*w^2/(s^2+2*z*w*s+w^2)", "--no-figures", "--out", str(tmp_path / "o"),
                  "--json", str(tmp_path / "fit.json"))
    assert res.code == 0, res.err
    fit = json.loads((tmp_path / "fit.json").read_text())
    hz = fit["parameters"]["w"] / (2 * np.pi)
    assert 67.0 <= hz <= 72.0, hz
    assert fit["record"]["dt"] == pytest.approx(2.0 ** 14 / 1e7, rel=1e-9)
