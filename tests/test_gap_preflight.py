"""Check the model first: an unstable model, a delay longer than the record, a record too short: one line, exit 2."""

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.errors import DataError, ModelError
from synth.gap.diagnose import diagnose
from synth.gap.effects import make_effect
from synth.gap.preflight import check_model
from synth.ident.simulate import simulate_plant
from synth.plant import Plant


@pytest.fixture(scope="module")
def csv(tmp_path_factory):
    t = np.arange(0, 40.01, 0.01)  # the 40 s record
    u = np.where((t % 4) >= 2, 1.0, 0.0)
    y = simulate_plant(Plant.from_string("2/(s+1)"), t, u) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    path = tmp_path_factory.mktemp("pre") / "run.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,u,y", comments="")
    return path


@pytest.mark.parametrize(("plant", "extra", "words"), [
    ("2/(s-1)", [], "unstable model: pole at +1"),
    ("2/(s+1)", ["--delay", "50"], "delay 50 s is not shorter than the record"),
    ("2/(s+0.001)", [], "too short for delay: it needs one time constant of the model's slowest mode, 1000 s"),
])
def test_cli_refuses_before_fitting(run_cli, csv, tmp_path, plant, extra, words):
    r = run_cli("diagnose", "--plant", plant, "--data", str(csv), *extra, "--candidates", "delay",
                "--out", str(tmp_path / "rep"), "--json", str(tmp_path / "gap.json"))
    assert r.code == 2, r.out + r.err
    lines = [ln for ln in r.err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and words in lines[0], r.err
    assert "Traceback" not in r.err and not (tmp_path / "gap.json").exists()


def test_library_raises_before_any_fit():
    t = np.arange(0, 2.0, 0.01)
    u = (t >= 0.5).astype(float)
    rec = record_from_arrays(t, u, simulate_plant(Plant.from_string("2/(0.1*s+1)"), t, u))
    with pytest.raises(ModelError, match="unstable model"):
        diagnose(Plant.from_string("2/(s^2-0.5*s+4)"), rec, candidates=["delay"])
    with pytest.raises(ModelError, match="not shorter than the record"):
        diagnose(Plant.from_string("2/(0.1*s+1)", delay=3.0), rec, candidates=["delay"])
    short = record_from_arrays(t[:100], (t[:100] >= 0.2).astype(float), u[:100])
    with pytest.raises(DataError, match=r"too short for direction: the fits get 50 samples, and 180 are needed"):
        check_model(Plant.from_string("2/(0.1*s+1)"), short, [make_effect("direction")])
    check_model(Plant.from_string("2/(0.1*s+1)"), short, [make_effect("delay")])  # 50 >= 10 x (2 + 1 + 1)
    check_model(Plant.from_string("1/(s*(0.1*s+1))"), rec, [make_effect("delay")])  # an integrator is fine
