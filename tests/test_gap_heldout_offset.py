"""The output offset on a validation record: another run has its own operating point and sensor zero."""

from __future__ import annotations

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.errors import ModelError
from synth.gap.attribution.heldout import DiagnoseOptions, diagnose_effects
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

TRUE = Plant.from_string("2/(0.2*s+1)", delay=0.05)
NOMINAL = Plant.from_string("2/(0.2*s+1)")
T = np.arange(0.0, 12.0, 0.01)


def _run(seed: int, shift: float, zero: float) -> tuple[object, np.ndarray]:
    """A step train with a command offset ``shift`` and a sensor zero ``zero``, noise 0.01."""
    u = np.where((T % 2.0) >= 1.0, 1.0, 0.0) + shift
    clean = simulate_plant(TRUE, T, u) + zero
    y = clean + 0.01 * np.random.default_rng(seed).standard_normal(T.size)
    return record_from_arrays(T, u, y), clean


def test_a_validation_run_with_another_sensor_zero_still_shows_the_delay():
    rec, _ = _run(0, 0.0, 0.0)
    val, clean = _run(1, 0.0, 0.3)  # the sensor reads 0.3 (30 noise sigmas) higher in the other run
    auto = diagnose_effects(NOMINAL, rec, validate=val, options=DiagnoseOptions(candidates=["delay", "lag"], n_null=9))
    assert auto.split["heldout_offset"] == "fit"
    assert auto.verdict["effects"][0] == "delay"
    assert auto.effects[0].parameters["delay"] == pytest.approx(0.05, abs=0.005)
    e = val.y - clean
    assert auto.effects[0].shrinkage == pytest.approx(1.0 - np.var(e) / auto.j_refit, abs=0.03)
    carried = diagnose_effects(NOMINAL, rec, validate=val,
                               options=DiagnoseOptions(candidates=["delay", "lag"], n_null=9, heldout_offset="carry"))
    # the 0.3 offset dominates every model's held-out error: the delay removes a sliver of it
    assert carried.verdict["effects"] == [] or carried.verdict["effects"] == ["parameter_mismatch"]
    assert carried.j_refit - auto.j_refit == pytest.approx(0.3**2, rel=0.1)  # mean(e^2) = var(e) + mean(e)^2


def test_a_split_record_carries_its_offset_unless_told():
    rec, _ = _run(2, 0.0, 0.0)
    dg = diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(candidates=["delay"], n_null=5))
    assert dg.split["heldout_offset"] == "carry"
    with pytest.raises(ModelError, match="heldout_offset"):
        diagnose_effects(NOMINAL, rec, options=DiagnoseOptions(candidates=["delay"], n_null=5, heldout_offset="refit"))


def test_the_cli_passes_the_heldout_offset(run_cli, tmp_path):
    import json

    for name, seed, zero in (("run.csv", 0, 0.0), ("other.csv", 1, 0.3)):
        rec, _ = _run(seed, 0.0, zero)
        np.savetxt(tmp_path / name, np.c_[rec.t, rec.u, rec.y], delimiter=",", header="t,u,y", comments="")
    base = ["diagnose", "--plant", "2/(0.2*s+1)", "--data", str(tmp_path / "run.csv"), "--validate",
            str(tmp_path / "other.csv"), "--candidates", "delay", "--no-report", "--json"]
    res = run_cli(*base, str(tmp_path / "a.json"), "--heldout-offset", "carry")
    assert res.code == 0, res.err
    assert json.loads((tmp_path / "a.json").read_text())["attribution"]["split"]["heldout_offset"] == "carry"
    assert run_cli(*base, str(tmp_path / "b.json"), "--heldout-offset", "mean").code == 2
