"""Specs mutated at random (the way a typo or a wrong paste mutates them): one line and exit 2, never a traceback.

The cases are ones a seeded fuzz of the repository's specs found (``type`` given as a list, a plant delay of
1e308 s); the fuzz itself mutated 2,000 specs for ``synth check`` (seeds 0-4 and 11) with no other escape."""

from __future__ import annotations

import json

import pytest
import yaml

X4 = {"name": "x4", "plant": {"tf": "23*(s+0.43)/((s+9.6)*(s+0.54))"}, "controller": {"type": "P"},
      "requirements": [{"type": "sensitivity", "max_db": -15, "band": [0, 5]}, {"type": "bandwidth", "min": 30}]}


def _spec(tmp_path, **changes):
    data = {**X4, **changes}
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return str(path)


@pytest.mark.parametrize("kind", [[1], {"a": 1}, 3.5, None])
@pytest.mark.parametrize("simulation", [False, True])
def test_a_requirement_type_that_is_not_a_name_is_an_unknown_type(run_cli, tmp_path, kind, simulation):
    """A list or mapping as a requirement's ``type`` (with a ``simulation:`` block the entries are read before
    validation, which looked the type up in a table and raised TypeError)."""
    changes = {"requirements": [X4["requirements"][0], {"type": kind, "min": 30}]}
    if simulation:
        changes["simulation"] = {"dt": 0.001, "horizon": 1.0}
    r = run_cli("check", _spec(tmp_path, **changes), "--controller", "P(3)")
    assert r.code == 2, r.err
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.err
    assert "requirements" in lines[0] and "type" in lines[0]


def test_a_delay_too_long_to_grid_is_one_line(run_cli, tmp_path):
    """A plant delay of 1e308 s puts the frequency grid's lower end at 1e-310 rad/s: the grid cannot be made,
    and the check says so instead of an OverflowError traceback. The loop's stability cannot be counted either,
    and a requirement that presumes a stable loop says so without a grid."""
    path = _spec(tmp_path, plant={**X4["plant"], "delay": 1e308})
    r = run_cli("check", path, "--controller", "P(3)")
    assert r.code == 1 and "Traceback" not in r.err
    assert r.out.count("closed loop not certified stable") == 3  # the stability row and both requirements
    r = run_cli("design", path, "--no-report", "--force")  # its stability set grids the frequencies
    assert r.code == 2 and "Traceback" not in r.err
    assert r.err.strip().splitlines() == [r.err.strip()] and "cannot grid the frequencies" in r.err


def test_a_long_delay_within_range_is_still_checked(run_cli, tmp_path):
    """The guard is on the grid, not on the delay: a dead-time process of an hour is checked as before."""
    spec = _spec(tmp_path, plant={"tf": "1/(3600*s+1)", "delay": 3600.0},
                 requirements=[{"type": "margins", "gain_margin_db": 6, "phase_margin_deg": 45}])
    r = run_cli("check", spec, "--controller", "P(0.5)")
    assert r.code == 0, r.err


@pytest.mark.parametrize("requirement, key", [
    ({"type": "peak_sensitivity", "max_db": 6, "band": [5, 0.1]}, "band"),
    ({"type": "peak_complementary", "max_db": 3, "band": [1, 1]}, "band"),
    ({"type": "peak_sensitivity", "max_db": 6, "band": [-1, 1]}, "band"),
    ({"type": "peak_control_sensitivity", "max_db": 20, "band": [0, float("inf")]}, "band"),
    ({"type": "peak_sensitivity", "max_db": float("nan")}, "max_db"),
    ({"type": "sensitivity", "max_db": float("nan"), "band": [0, 5]}, "max_db"),
    ({"type": "sensitivity_static", "max_db": -10, "plant_gain": 0}, "plant_gain"),
    ({"type": "sensitivity_static", "max_db": -10, "plant_gain": float("nan")}, "plant_gain"),
])
def test_a_peak_band_or_bound_that_cannot_be_checked_is_one_line(run_cli, tmp_path, requirement, key):
    """Found by a black-box test of ``synth check``: a peak requirement's band was checked only when evaluated (a
    ValueError traceback, exit 1), ``plant_gain: 0`` divided by zero, and a NaN bound was accepted and printed as
    "+nan NOT MET" beside a message that said "met"."""
    r = run_cli("check", _spec(tmp_path, requirements=[requirement]), "--controller", "PI(1, 1)")
    assert r.code == 2 and "Traceback" not in r.err, r.err
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and f"requirements[0].{key}" in lines[0], lines


@pytest.mark.parametrize("plant, controller, expected_db", [
    ("s/(s+1)^2", "P(1)", 0.0),  # the plant's DC gain is 0: S(0) = 1 whatever the controller
    ("1/(s*(s+1))", "leadlag(k=1, z=0, p=1)", -6.0206),  # C(0) = 0 meets the plant's pole at 0: L(0) = 1
])
def test_static_sensitivity_on_a_plant_without_a_finite_dc_gain(run_cli, tmp_path, plant, controller, expected_db):
    """``plant_gain`` left to the model, whose DC gain is 0 or infinite: S(0) from the loop's exact L(0) (a
    ZeroDivisionError traceback before, and NaN dB for the limit ``0 * inf``)."""
    spec = _spec(tmp_path, plant={"tf": plant}, controller={"type": "leadlag" if "leadlag" in controller else "P"},
                 requirements=[{"type": "sensitivity_static", "max_db": -3}])
    json_path = tmp_path / "out.json"
    r = run_cli("check", spec, "--controller", controller, "--json", str(json_path))
    assert r.code in (0, 1) and "Traceback" not in r.err, r.err
    data = json.loads(json_path.read_text(encoding="utf-8"))
    static = next(q for q in data["requirements"] if q["type"] == "sensitivity_static")
    assert static["value"] == pytest.approx(expected_db, abs=1e-3)
    assert static["met"] == (expected_db <= -3)


def test_a_loop_whose_response_overflows_is_one_line(run_cli, tmp_path):
    """Found by a black-box test: ``1/(s+1)^400`` behind 0.1 s; ``(j w)^400`` overflows beyond 6 rad/s and the
    Nyquist count's winding came out NaN (a ValueError traceback, exit 1)."""
    spec = _spec(tmp_path, plant={"tf": "1/(s+1)^400", "delay": 0.1}, controller={"type": "PI"},
                 requirements=[{"type": "disk_margin", "min": 0.5}])
    r = run_cli("check", spec, "--controller", "PI(kp=0.8, ki=0.6)")
    assert r.code == 2 and "Traceback" not in r.err
    assert r.err.strip().splitlines() == [r.err.strip()] and "overflows floating point" in r.err


@pytest.mark.parametrize("changes, message", [
    ({"plant": {"tf": "2/((s+1)*(0.5*s+1))", "variants": [{"label": "z", "delay": -0.1}]}},
     "plant.variants[0].delay: must be >= 0.0, got -0.1"),  # 'delay' is also a simulation block's tag
    ({"requirements": [{"type": "no_limit_cycle", "actuator": []}]},
     "requirements[0].actuator: needs at least 1 item(s), got []"),  # a list of blocks, not a pair of numbers
])
def test_messages_name_the_key_and_the_kind_of_value(run_cli, tmp_path, changes, message):
    """Found by a black-box test: the variant's key was dropped from the path, and an empty block list was asked
    for "exactly 2 numbers [low, high]"."""
    r = run_cli("check", _spec(tmp_path, **changes), "--controller", "P(1)")
    assert r.code == 2 and message in r.err, r.err
