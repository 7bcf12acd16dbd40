"""Records as they come: comments anywhere, units in headers, delimiters, uneven time, MAT matrices and structs.

The randomized test writes CSV files from a seed (comment placement, header unit styles, delimiters,
decimal commas, trailing separators, uneven time) and checks every loaded value against an expectation
built here from the written text, independently of the reader.
"""

from __future__ import annotations

import bisect
import itertools
import json
import random

import numpy as np
import pytest
from scipy.io import savemat

from synth.data import as_record, load_record
from synth.data.disturbance import load_disturbance
from synth.data.readers import parse_column_map, read_table, split_unit
from synth.errors import DataError

UNITS = ["V", "rad/s", "gf", "µs", "%", "N m", "A"]


def _header(name: str, unit: str, rng: random.Random, spaces: bool) -> tuple[str, str]:
    """A header for the column and the unit it states (none in the bare style)."""
    style = rng.choice(["bare", "paren", "bracket"]) if unit else "bare"
    gap = " " if spaces and rng.random() < 0.7 else ""
    text = {"bare": name, "paren": f"{name}{gap}({unit})", "bracket": f"{name}{gap}[{unit}]"}[style]
    return text, ("" if style == "bare" else unit)


def _number(x: float, comma: bool) -> str:
    text = f"{x:.6g}"
    return text.replace(".", ",") if comma else text


def _written(text: str) -> float:
    return float(text.replace(",", "."))


def _case(seed: int) -> dict:
    rng = random.Random(seed)
    delimiter = rng.choice([",", ";", "\t", " "])
    spaces = delimiter != " "
    comma = delimiter == ";" and rng.random() < 0.5
    n_levels = rng.randint(3, 12)
    runs = [rng.randint(2, 9) for _ in range(n_levels)]
    levels = [round(rng.uniform(-50, 250), 1)]
    while len(levels) < n_levels:
        x = round(rng.uniform(-50, 250), 1)
        if x != levels[-1]:
            levels.append(x)
    u_text = [_number(lv, comma) for lv, k in zip(levels, runs) for _ in range(k)]
    n = len(u_text)
    dt = rng.choice([0.001, 0.02, 0.5])
    uneven = rng.random() < 0.6
    time_unit = rng.choice(["s", "ms", ""]) if spaces else rng.choice(["s", ""])
    time_header = _header("Time" if spaces else "time", time_unit, rng, spaces)
    scale = 1e-3 if time_header[1] == "ms" else 1.0
    t_vals = [(k + (rng.uniform(-0.3, 0.3) if uneven and 0 < k < n - 1 else 0.0)) * dt / scale for k in range(n)]
    t_text = [_number(x, comma) for x in t_vals]
    y_text = [_number(rng.uniform(-1e3, 1e3), comma) for _ in range(n)]
    a_text = [_number(rng.uniform(0, 5), comma) for _ in range(n)]
    names = ["Time" if spaces else "time", "Motor cmd" if spaces else "cmd", "speed", "aux"]
    units = [time_unit, rng.choice(UNITS[:4] + ([] if not spaces else UNITS[4:])), rng.choice(UNITS[:3]), "V"]
    if not spaces:
        units = [u.replace(" ", "") for u in units]
    rest = [_header(nm, un, rng, spaces) for nm, un in zip(names[1:], units[1:])]
    header, units = [time_header[0]] + [h for h, _ in rest], [time_header[1]] + [un for _, un in rest]
    rows = [[t, u, y, a] for t, u, y, a in zip(t_text, u_text, y_text, a_text)]
    lines = [delimiter.join(header)] + [delimiter.join(r) for r in rows]
    if rng.random() < 0.5 and delimiter != " ":
        lines = [line + delimiter for line in lines]  # a trailing separator on every line
    comments = 0
    for _ in range(rng.randint(0, 6)):
        where = rng.choice(["lead", "body", "tail"])
        text = rng.choice(["# a-> Type: Steps", "#", "  # note, with; separators\t", "#12,3,4"])
        pos = {"lead": 0, "body": rng.randint(2, len(lines)), "tail": len(lines)}[where]
        lines.insert(pos, text)
        comments += 1
    if rng.random() < 0.3:
        lines.insert(rng.randint(1, len(lines)), "")  # a blank line
    return {"text": "\n".join(lines) + "\n", "header": header, "names": names, "units": units, "scale": scale,
            "t": [_written(x) * scale for x in t_text], "u": [_written(x) for x in u_text],
            "y": [_written(x) for x in y_text], "a": [_written(x) for x in a_text], "uneven": uneven,
            "levels": levels, "comments": comments, "rng": rng}


def _held_mean(t: list[float], u: list[float], g: float, h: float) -> float:
    """The written command's mean over ``[g, g + h)``, each value held from its time to the next (zero-order hold),
    summed piece by piece."""
    total, edges = 0.0, [g] + [x for x in t if g < x < g + h] + [g + h]
    for a, b in itertools.pairwise(edges):
        total += (b - a) * u[max(0, bisect.bisect_right(t, a) - 1)]
    return total / h


def _linear(t: list[float], y: list[float], g: float) -> float:
    k = min(max(bisect.bisect_right(t, g) - 1, 0), len(t) - 2)
    w = (g - t[k]) / (t[k + 1] - t[k])
    return y[k] + w * (y[k + 1] - y[k])


@pytest.mark.parametrize("seed", range(60))
def test_random_csv_loads_to_the_values_written(tmp_path, seed):
    case = _case(seed)
    rng = case["rng"]
    path = tmp_path / "rec.csv"
    path.write_text(case["text"], encoding=rng.choice(["utf-8", "utf-8-sig"]))
    # name each column as the user sees it: the header as written, the bare name, or the name with its unit
    asked = []
    for name, unit, header in zip(case["names"], case["units"], case["header"]):
        choices = [header, name] + ([f"{name} ({unit})", f"{name} [{unit}]"] if unit and " " not in unit else [])
        asked.append(rng.choice(choices))
    r = load_record(path, asked[0], asked[1], asked[2], aux=[asked[3]])
    t, u, y, a = case["t"], case["u"], case["y"], case["a"]
    assert (r.input.name, r.input.unit) == (case["names"][1], case["units"][1])
    assert (r.output.name, r.output.unit) == (case["names"][2], case["units"][2])
    assert list(r.aux) == [case["header"][3]]
    if case["comments"]:
        assert f"skipped {case['comments']} comment line(s) starting with #" in r.notes
    if not case["uneven"]:
        np.testing.assert_allclose(r.t, t, rtol=0, atol=1e-9 * max(t))
        assert r.u.tolist() == u and r.y.tolist() == y and r.aux[case["header"][3]].tolist() == a
        assert not any(n.startswith("resampled") for n in r.notes)
        return
    assert any(n.startswith("resampled") and "zero-order hold" in n for n in r.notes)
    steps = np.diff(r.t)
    assert r.t[0] == pytest.approx(t[0]) and r.t[-1] == pytest.approx(t[-1])
    assert np.ptp(steps) <= 1e-9 * steps.mean() and steps.mean() <= np.median(np.diff(t)) * (1 + 1e-9)
    h = steps.mean()
    # each grid interval [g, g + dt) holds the written command's mean over it (the last sample: the last value)
    np.testing.assert_allclose(r.u[:-1], [_held_mean(t, u, g, h) for g in r.t[:-1]], rtol=1e-9, atol=1e-9 * 250)
    assert r.u[-1] == u[-1]
    np.testing.assert_allclose(r.y, [_linear(t, y, g) for g in r.t], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(r.aux[case["header"][3]], [_linear(t, a, g) for g in r.t], rtol=1e-9, atol=1e-9)
    # a level over two grid intervals or more holds its written value exactly on at least one (not a ramp)
    starts = np.r_[0, np.flatnonzero(np.diff(u)) + 1]
    for first, level in zip(starts, case["levels"]):
        end = t[starts[starts > first][0]] if np.any(starts > first) else t[-1]
        if end - t[first] >= 2 * h * (1 + 1e-9):
            assert level in r.u.tolist()


def test_split_unit_styles():
    assert split_unit("Motor Optical Speed (rad/s)") == ("Motor Optical Speed", "rad/s")
    assert split_unit("Torque (N·m)") == ("Torque", "N·m")
    assert split_unit("x [m/s^2]") == ("x", "m/s^2")
    assert split_unit("data[12]") == ("data[12]", "")
    assert split_unit("()") == ("()", "")


@pytest.mark.parametrize(("unit", "scale"), [("msec", 1e-3), ("millis", 1e-3), ("MS", 1e-3), ("usec", 1e-6),
                                           ("seconds", 1.0), ("minutes", 60.0)])
def test_other_spellings_of_a_time_unit_are_converted(tmp_path, unit, scale):
    """Found by a black-box test: ``Time [msec]`` was taken for seconds (a 0.3 s time constant identified as
    300 s, a 5 Hz spike put at 0.0 rad/s)."""
    p = tmp_path / "r.csv"
    p.write_text(f"Time [{unit}],u,y\n" + "".join(f"{k * 10},{int(k > 3)},{k * k}\n" for k in range(10)))
    r = load_record(p, "Time", "u", "y")
    assert r.t[1] == pytest.approx(10 * scale, rel=1e-12)
    assert r.notes == ((f"time column 'Time [{unit}]' converted from {unit} to s",) if scale != 1.0 else ())


def test_a_time_column_in_a_unit_that_is_no_time_is_refused_in_one_line(tmp_path, run_cli):
    p = tmp_path / "r.csv"
    p.write_text("t [furlong],u,y\n" + "".join(f"{k},{int(k > 3)},{k * k}\n" for k in range(10)))
    with pytest.raises(DataError, match=r"r.csv: time column 't \[furlong\]' is in 'furlong', not a time unit"):
        load_record(p, "t", "u", "y")
    res = run_cli("identify", "--data", str(p), "--time", "t", "--input", "u", "--output", "y", "--structure",
                  "K/(T*s+1)", "--out", str(tmp_path / "out"))
    assert res.code == 2 and len(res.err.strip().splitlines()) == 1 and "furlong" in res.err


@pytest.mark.parametrize("form", ["units row", "percent comment", "excel sep"])
def test_a_units_row_a_matlab_comment_and_an_excel_separator_line_are_read(tmp_path, form):
    """Found by a black-box test: each of these was refused with "no numeric columns found"."""
    rows = "".join(f"{k * 10};{int(k > 3)};{k * k}\n" for k in range(10))
    text = {"units row": "t;u;y\nms;V;rad/s\n" + rows, "percent comment": "% logged by MATLAB\nt;u;y\n" + rows,
            "excel sep": "sep=;\nt;u;y\n" + rows}[form]
    p = tmp_path / "r.csv"
    p.write_text(text)
    r = load_record(p, "t", "u", "y")
    assert r.y.tolist() == [float(k * k) for k in range(10)] and r.u.tolist() == [float(k > 3) for k in range(10)]
    if form == "units row":  # the time in ms, the signals' units from the row
        assert r.dt == 0.01 and r.input.unit == "V" and r.output.unit == "rad/s"
        assert "read the units from the row under the header" in r.notes
    else:
        assert r.dt == 10.0 and r.output.unit == ""


def test_time_in_ms_is_converted_and_noted(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("Time (ms),u,y\n" + "".join(f"{k * 10},{int(k > 3)},{k * k}\n" for k in range(10)))
    r = load_record(p)
    assert r.dt == 0.01 and r.notes == ("time column 'Time (ms)' converted from ms to s",)


def test_single_column_with_a_unit_in_its_header(tmp_path):
    p = tmp_path / "d.csv"
    p.write_text("# hover\nmotor speed (rad/s)\n" + "".join(f"{(-1) ** k * k}\n" for k in range(40)))
    r = load_disturbance(p, None, "motor speed", dt=0.01)
    assert (r.name, r.unit, r.x.size) == ("motor speed", "rad/s", 40)


def test_repeated_time_stamp_keeps_the_last_sample(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("t,u,y\n0,1000,0\n0,1010,1\n0.05,1020,2\n0.1,1030,3\n0.15,1040,4\n")
    r = load_record(p)
    assert r.t.tolist() == [0, 0.05, 0.1, 0.15] and r.u.tolist() == [1010, 1020, 1030, 1040]
    assert r.notes[0].startswith("repeated time stamps: 1 sample(s)")


def test_rounded_time_column_is_an_error(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("t,u,y\n" + "".join(f"{round(k * 0.001, 2)},{int(k > 50)},{k}\n" for k in range(100)))
    with pytest.raises(DataError, match=r"column 't': 89 of 100 samples repeat the time stamp before them \(first "
                                        r"at sample 1\); is the time rounded\? give the sample interval \(dt\) instead"):
        load_record(p)


def test_text_column_stops_only_when_used(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("t,u,y,msg\n0,0,0,\n1,1,1,started\n2,1,2,\n")
    assert load_record(p, "t", "u", "y").n == 3
    with pytest.raises(DataError, match=r"r.csv: line 3: column 'msg': 'started' is not a number$"):
        load_record(p, "t", "u", "y", aux=["msg"])


@pytest.mark.parametrize("body", ["0,0,0,5\n1,1,1,6\n2,1,2,7\n", "0,0,0,5\n1,1,1,x\n2,1,2,7\n"])  # fast, cell by cell
def test_a_header_written_twice_stops_only_when_used(tmp_path, body):
    p = tmp_path / "r.csv"
    p.write_text("t,u,y,y\n" + body)  # which 'y' is the output? once the dict kept the last silently
    with pytest.raises(DataError, match=r"r.csv: column 'y' appears 2 times in the header \(columns 3, 4\); rename"):
        load_record(p, "t", "u", "y")
    table = read_table(p)  # the other columns still load
    assert table.find("t") == "t" and table.columns["u"].tolist() == [0.0, 1.0, 1.0]


def test_ambiguous_name_asks_for_the_unit(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("t,u,Speed (RPM),Speed (rad/s)\n0,0,0,0\n1,1,10,1.05\n2,1,20,2.1\n")
    with pytest.raises(DataError, match=r"column 'Speed' is ambiguous \('Speed \(RPM\)', 'Speed \(rad/s\)'\)"):
        load_record(p, "t", "u", "Speed")
    assert load_record(p, "t", "u", "speed [rad/s]").output.unit == "rad/s"


def test_missing_csv_column_lists_the_columns(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("# log\nTime (s),ESC signal (µs),Thrust (gf)\n0,1000,0\n1,1010,1\n2,1020,2\n")
    with pytest.raises(DataError, match=r"output column 'Trust' not found; did you mean 'Thrust \(gf\)'\? "
                                        r"columns are Time \(s\), ESC signal \(µs\), Thrust \(gf\)$"):
        load_record(p, "Time", "ESC signal", "Trust")
    with pytest.raises(DataError, match=r"signal column 'rpm' not found; columns are Time \(s\), ESC"):
        load_disturbance(p, "Time", "rpm")


def _mat(tmp_path, transpose: bool = False):
    t = np.arange(400) * 0.005
    u = np.where((t % 1.0) < 0.5, 1.0, -1.0)
    acc = np.vstack([np.sin(t), np.cos(t), u * 0.3 + t])
    p = tmp_path / "sweep.mat"
    savemat(p, {"run": {"t": t, "cmd": u, "info": {"gain": 2.0, "y": 2 * u}}, "acc": acc.T if transpose else acc,
                "J": 1.2e-4, "label": "test"})
    return p, t, u, acc


@pytest.mark.parametrize("transpose", [False, True])
def test_mat_matrix_and_struct_columns(tmp_path, transpose):
    p, _, u, acc = _mat(tmp_path, transpose)
    tab = read_table(p)
    assert sorted(tab.columns) == ["acc[0]", "acc[1]", "acc[2]", "run.cmd", "run.info.y", "run.t"]
    np.testing.assert_array_equal(tab.columns["acc[2]"], acc[2])
    r = load_record(p, "run.t", "run.cmd", "accel_z", columns={"acc[2]": "accel_z"})
    np.testing.assert_array_equal(r.y, acc[2])
    assert r.output.name == "accel_z" and r.dt == 0.005
    r = as_record(str(p), time="run.t", input="run.cmd", output="run.info.y")
    np.testing.assert_array_equal(r.y, 2 * u)


def test_missing_mat_column_lists_the_columns(tmp_path):
    p, *_ = _mat(tmp_path)
    with pytest.raises(DataError, match=r"output column 'acc\[3\]' not found; did you mean 'acc\[2\]'\? columns are "
                                        r"run.t, run.cmd, run.info.y, acc\[0\], acc\[1\], acc\[2\], label$"):
        load_record(p, "run.t", "run.cmd", "acc[3]")
    with pytest.raises(DataError, match=r"columns map: column 'acc\[7\]' not found"):
        load_record(p, "run.t", "run.cmd", "x", columns={"acc[7]": "x"})
    with pytest.raises(DataError, match=r"sweep.mat: columns map: two columns would be named 'run.t'$"):
        load_record(p, "run.t", "run.cmd", "acc[1]", columns={"acc[0]": "run.t"})


def test_column_map_parsing():
    assert parse_column_map(None) == {} and parse_column_map([]) == {}
    assert parse_column_map(" acc[0] = accel_x ,") == {"acc[0]": "accel_x"}
    with pytest.raises(DataError, match="--columns: expected OLD=NEW"):
        parse_column_map(["=x"])


def test_dataframe_like_columns_with_units_and_map():
    cols = {"Time (s)": np.arange(5) * 0.1, "Voltage [V]": [0, 1, 1, 1, 1.0], "speed (rad/s)": np.arange(5.0)}
    r = as_record(cols, time="Time", input="Voltage", output="speed")
    assert (r.input.label(), r.output.label()) == ("Voltage [V]", "speed [rad/s]")
    r = as_record(cols, time="Time", input="volts", output="speed", columns={"Voltage": "volts"})
    assert r.input.label() == "volts [V]"


def test_identify_cli_on_a_mat_matrix_with_a_columns_map(run_cli, tmp_path):
    t = np.arange(0, 4, 0.01)
    u = np.where(t >= 0.5, 1.0, 0.0)
    y = 2.0 * (1 - np.exp(-np.clip(t - 0.5, 0, None) / 0.3)) + 0.001 * np.sin(37 * t)
    p = tmp_path / "step.mat"
    savemat(p, {"log": np.column_stack([t, u, y])})
    res = run_cli("identify", "--data", str(p), "--columns", "log[0]=t,log[1]=volt", "--columns", "log[2]=speed",
                  "--time", "t", "--input", "volt", "--output", "speed", "--structure", "K/(T*s+1)",
                  "--no-figures", "--out", str(tmp_path / "o"), "--json", "-", "--quiet")
    assert res.code == 0, res.err
    out = json.loads(res.out)
    assert out["parameters"]["K"] == pytest.approx(2.0, rel=0.01) and out["parameters"]["T"] == pytest.approx(0.3, rel=0.01)
    assert out["record"]["input"] == {"name": "volt", "unit": ""}
    res = run_cli("identify", "--data", str(p), "--time", "log[0]", "--input", "log[1]", "--output", "speed",
                  "--structure", "K/(T*s+1)", "--out", str(tmp_path / "o2"))
    assert res.code == 2 and "output column 'speed' not found; columns are log[0], log[1], log[2]" in res.err


def test_hq_frd_with_units_in_the_header(run_cli, tmp_path):
    p = tmp_path / "frd.csv"
    w = np.logspace(-1, 1.5, 80)
    h = 1 / ((1j * w) ** 2 + 1j * w + 1) * np.exp(-0.1j * w)
    phase = np.degrees(np.unwrap(np.angle(h)))
    rows = "".join(f"{a},{20 * np.log10(abs(b))},{c}\n" for a, b, c in zip(w, h, phase))
    p.write_text("# frd\nomega (rad/s),mag_db [dB],phase_deg (deg)\n" + rows)
    res = run_cli("hq", "--frd", str(p), "--columns", "omega=w", "--json", "-")
    assert res.code == 0, res.err
    res = run_cli("hq", "--frd", str(p), "--json", "-")
    assert res.code == 2 and "column 'w' not found; found omega (rad/s), mag_db [dB], phase_deg (deg)" in res.err


@pytest.mark.parametrize("header, picked, message", [
    ("t,u,y,z", {}, r"line 3: column 'u': 'abc' is not a number$"),  # by position: never the next numeric column
    ("t,u,y", {}, r"line 3: column 'u': 'abc' is not a number$"),
    ("t,u,u", {}, r"column 'u' appears 2 times in the header \(columns 2, 3\)"),
])
def test_a_column_picked_by_position_is_the_files(tmp_path, header, picked, message):
    """Found by a black-box test of ``synth identify``: a text cell dropped its column, and the default columns
    (time, input, output by position) shifted onto the next ones (y -> z fitted as input -> output, exit 0)."""
    p = tmp_path / "r.csv"
    rows = [[0, 0, 0, 1], [1, "abc" if header != "t,u,u" else 1, 1, 6], [2, 1, 2, 11], [3, 1, 3, 16]]
    width = len(header.split(","))
    p.write_text(header + "\n" + "".join(",".join(map(str, r[:width])) + "\n" for r in rows))
    with pytest.raises(DataError, match=message):
        load_record(p, **picked)


@pytest.mark.parametrize("roles, message", [
    ({"input": "y", "output": "y"}, "column 'y' is given as both the input and the output column"),
    ({"time": "t", "input": "t", "output": "y"}, "column 't' is given as both the time and the input column"),
    ({"input": "u", "output": "y", "aux": ["u"]}, "column 'u' is given as both the input and the aux column"),
])
def test_one_column_in_two_roles_is_one_line(tmp_path, roles, message):
    """A KeyError traceback before (the column was taken out of the table twice)."""
    p = tmp_path / "r.csv"
    p.write_text("t,u,y\n0,0,0\n1,1,1\n2,1,2\n3,1,3\n")
    with pytest.raises(DataError, match=message):
        load_record(p, **roles)


def test_resampled_command_edges_stay_where_they_were_written():
    """Jittered stamps (4-6 ms), a command that changes only at stamps: after resampling, the one sample inside
    which an edge falls holds the interval's mean command, from which the edge's written time comes back exactly
    (the value at each interval's start moved edges 0.5 interval later on average; the one at its middle up to
    half an interval either way, errors 10 times a fit's reported std)."""
    from synth.data import record_from_arrays

    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(0.004, 0.006, 20_000))
    t -= t[0]
    levels = np.repeat(rng.choice([-1.0, 1.0], 400), 50)  # a level every 50 stamps (about 0.25 s)
    r = record_from_arrays(t, levels, np.sin(t))
    dt = r.t[1] - r.t[0]
    written = t[np.flatnonzero(np.diff(levels)) + 1]
    before = levels[np.flatnonzero(np.diff(levels))]
    after = levels[np.flatnonzero(np.diff(levels)) + 1]
    inside = np.searchsorted(r.t, written, side="right") - 1  # the grid interval holding each edge
    fraction_after = (r.u[inside] - before) / (after - before)  # the share of the interval at the new level
    recovered = r.t[inside] + (1.0 - fraction_after) * dt
    np.testing.assert_allclose(recovered, written, rtol=0, atol=1e-9 * dt)
    others = np.setdiff1d(np.arange(r.t.size), inside)
    assert np.all(np.isin(r.u[others], [-1.0, 1.0]))  # every other sample holds a written level exactly


def test_a_command_change_hidden_in_a_gap_of_the_time_stamps_is_noted(tmp_path, run_cli):
    """Found by a black-box test: a 0.3 s dropout hiding one edge of a step train put K 3 % off (44 of its standard
    errors) without a word. The record now says that the command changed inside the gap, and identify prints how
    the record was read; the same dropout where the command holds is only resampled."""
    from synth.data import record_from_arrays

    t = np.arange(0.0, 40.0, 0.01)
    u = ((t % 4.0) >= 2.0) * 1.0
    y = np.cumsum(u) * 0.01
    for start, hidden in ((23.9, True), (24.9, False)):  # the command changes every 2 s: at 24 s, not at 25 s
        keep = (t <= start) | (t >= start + 0.3)
        rec = record_from_arrays(t[keep], u[keep], y[keep])
        noted = [n for n in rec.notes if "changed inside a" in n]
        assert bool(noted) == hidden, (start, rec.notes)
        assert any(n.startswith("resampled") for n in rec.notes)
    keep = (t <= 23.9) | (t >= 24.2)  # the edge at 24 s falls in the gap
    path = tmp_path / "g.csv"
    np.savetxt(path, np.c_[t[keep], u[keep], y[keep]], delimiter=",", header="t,u,y", comments="")
    res = run_cli("identify", "--data", str(path), "--structure", "K/s", "--average", "none", "--no-figures",
                  "--out", str(tmp_path / "o"))
    assert "note: 'u' changed inside a 0.31 s gap in the time stamps (t = 23.89-24.2 s)" in res.out, res.out + res.err


@pytest.mark.parametrize("delimiter", [",", ";", "\t", " "])
def test_a_file_without_a_header_row_is_read_with_its_columns_named_by_position(tmp_path, delimiter):
    """A logger's plain numbers (no header): the first line is data, not names (it used to be read as a header of
    numbers: "column '0' appears 2 times in the header")."""
    rng = np.random.default_rng(len(delimiter) + ord(delimiter))
    data = np.c_[np.arange(50) * 0.01, np.repeat([0.0, 1.0], 25), rng.normal(size=50)]
    path = tmp_path / "plain.csv"
    path.write_text("\n".join(delimiter.join(f"{x:.9g}" for x in row) for row in data) + "\n")
    table = read_table(path)
    assert list(table.columns) == ["col1", "col2", "col3"]
    assert np.allclose(table.columns["col3"], data[:, 2], rtol=1e-8, atol=0)
    assert any("no header row" in note for note in table.notes)
    record = load_record(path)  # time, input, output in file order
    assert record.n == 50 and record.y[0] == pytest.approx(data[0, 2], rel=1e-8)


def test_a_column_without_a_name_above_numbers_is_kept_and_noted_and_a_trailing_separator_is_not(tmp_path):
    path = tmp_path / "gap.csv"
    path.write_text("t,u,,y,\n0,0,5,0.5,\n0.01,1,6,0.25,\n0.02,1,7,0.125,\n")
    table = read_table(path)
    assert list(table.columns) == ["t", "u", "col3", "y"]  # the trailing separator's empty column is dropped
    assert table.columns["col3"].tolist() == [5.0, 6.0, 7.0]
    assert table.notes == ("column 3 has no name in the header: called col3",)
    record = load_record(path, time="t", input="u", output="y")
    assert record.y.tolist() == [0.5, 0.25, 0.125]
    assert load_record(path).y.tolist() == [5.0, 6.0, 7.0]  # by position: the file's third column


@pytest.mark.parametrize("dt", [0.0, -0.01, float("nan"), float("inf")])
def test_a_sample_interval_that_is_not_positive_is_named_as_such(tmp_path, run_cli, dt):
    path = tmp_path / "r.csv"
    path.write_text("u,y\n" + "\n".join(f"{k // 10},{k * 0.1}" for k in range(40)) + "\n")
    with pytest.raises(DataError, match="sample interval must be a finite number > 0 s"):
        load_record(path, dt=dt)
    res = run_cli("identify", "--data", str(path), "--structure", "K/(T*s+1)", "--dt", str(dt), "--no-figures",
                  "--out", str(tmp_path / "out"))
    assert res.code == 2 and "dt: the sample interval" in res.err and len(res.err.strip().splitlines()) == 1
