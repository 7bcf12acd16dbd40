"""synth.gap.diagnose: the JSON contract, a rate-limited record, the three model sources, bad input."""

import json

import numpy as np
import pytest

from synth.data import record_from_arrays
from synth.errors import DataError, ModelError, SpecError
from synth.gap.diagnose import check_candidates, diagnose, load_model
from synth.ident.simulate import simulate_plant
from synth.plant import Plant, Signal
from synth.sim.blocks import RateLimit

X4 = "23*(s+0.43)/((s+9.6)*(s+0.54))"


def rate_limited_record(rate=400.0, dt=0.01, seconds=8.0, noise=0.2, seed=0):
    t = np.arange(0, seconds, dt)
    u = np.where((t % 2) >= 1, 100.0, 0.0)
    y = simulate_plant(Plant.from_string("20/(s+10)"), t, RateLimit(rate).apply(u, dt))
    return record_from_arrays(t, u, y + noise * np.random.default_rng(seed).normal(size=t.size),
                              input=Signal("pwm", "PWM"), output=Signal("speed", "rad/s"))


@pytest.fixture(scope="module")
def rate_limited():
    return diagnose(Plant.from_string("20/(s+10)"), rate_limited_record(), candidates=["rate_limit", "delay"],
                    n_null=3)


def test_rate_limited_record_gives_rate_limit(rate_limited):
    d = rate_limited.to_dict()
    assert d["verdict"]["effects"] == ["rate_limit"]
    assert d["verdict"]["status"] == "effect"
    best = d["effects"][0]
    assert best["effect"] == "rate_limit" and best["accepted"] is True
    assert best["parameters"]["rate"] == pytest.approx(400.0, rel=0.03)
    assert best["shrinkage"] > 0.95 and best["shrinkage_ci"][0] > 0.9
    # the delay explains part of it, but is not accepted beside the winner
    delay = next(e for e in d["effects"] if e["effect"] == "delay")
    assert delay["accepted"] is False and delay["shrinkage"] < best["shrinkage"]
    # the ramp takes 0.25 s of each 1 s half period: the gap is large and sits in the rise
    assert 0.2 < d["gap"]["nrmse"] < 0.8
    assert "rise" in d["headline"]
    assert "explained by rate limit (rate = " in d["summary"]


def test_json_contract_keys_and_types(rate_limited):
    d = json.loads(json.dumps(rate_limited.to_dict()))
    assert {"gap", "where", "effects", "verdict"} <= set(d)
    assert isinstance(d["gap"]["nrmse"], float)
    assert d["gap"]["fit_percent"] == pytest.approx(100 * (1 - d["gap"]["nrmse"]))
    for key in ("time_windows", "frequency_bands"):
        assert isinstance(d["where"][key], list)
        for row in d["where"][key]:
            assert len(row) == 3 and all(isinstance(x, float) for x in row) and row[0] < row[1] and 0 < row[2] <= 1
    assert d["where"]["time_windows"] and d["where"]["frequency_bands"]
    assert isinstance(d["where"]["regimes"], dict) and "rate" in d["where"]["regimes"]
    for e in d["effects"]:
        assert {"effect", "parameters", "shrinkage", "shrinkage_ci", "accepted"} <= set(e)
        assert isinstance(e["parameters"], dict) and isinstance(e["accepted"], bool)
        assert len(e["shrinkage_ci"]) == 2 and e["shrinkage_ci"][0] <= e["shrinkage"] <= e["shrinkage_ci"][1] + 1e-12
    assert isinstance(d["verdict"]["effects"], list) and isinstance(d["verdict"]["indistinguishable"], list)
    assert d["units"] == {"input": "PWM", "output": "rad/s"}
    assert d["noise_floor"]["std"] == pytest.approx(0.2, rel=0.15)  # the added white noise


def test_no_gap_gives_empty_verdict():
    G = Plant.from_string("20/(s+10)")
    rec = rate_limited_record(rate=1e9)  # the limit never acts: the model is right
    d = diagnose(G, rec, candidates=["rate_limit"], n_null=3).to_dict()
    assert d["verdict"]["effects"] == [] and d["verdict"]["status"] == "none"
    assert d["summary"].startswith("No gap")


def test_model_sources_give_the_same_plant(tmp_path):
    from synth.outputs import write_json

    tf = load_model(X4, delay=0.02)
    ident = write_json(tmp_path / "identify.json", {"tf": tf.to_string(6), "delay": 0.02, "plant": tf.to_dict()})
    tf_only = write_json(tmp_path / "tf_only.json", {"tf": tf.to_string(6), "delay": 0.02})  # tf carries exp(-0.02 s)
    spec = load_model("specs/x4_rotor.yaml", delay=0.02)
    for other in (load_model(str(ident)), load_model(str(tf_only)), spec):
        assert np.allclose(other.num, tf.num) and np.allclose(other.den, tf.den)
        assert other.delay == pytest.approx(0.02)
    assert load_model("specs/x4_rotor.yaml").delay == 0.0
    assert load_model(str(ident), delay=0.0).delay == 0.0  # --delay replaces a file's delay


@pytest.mark.parametrize("text, error, needle", [
    ("23*(s+0.43)/((s+9.6)*(s+", ModelError, "--plant"),
    ("missing_model.json", DataError, "model file not found"),
    ("missing_spec.yaml", DataError, "model file not found"),
])
def test_bad_models(text, error, needle):
    with pytest.raises(error) as exc:
        load_model(text)
    assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_bad_model_files(tmp_path):
    (tmp_path / "bad.json").write_text("{not json")
    (tmp_path / "empty.json").write_text('{"fit_percent": 99}')
    (tmp_path / "bad.yaml").write_text("name: x\n")
    for name, error in (("bad.json", ModelError), ("empty.json", ModelError), ("bad.yaml", SpecError)):
        with pytest.raises(error) as exc:
            load_model(str(tmp_path / name))
        assert "\n" not in str(exc.value)
    with pytest.raises(ModelError, match="delay"):
        load_model(X4, delay=-1.0)


def test_candidates_validated():
    assert check_candidates(["lag(sensor)", "rate_limit"]) == ["lag(sensor)", "rate_limit"]
    with pytest.raises(ModelError, match="unknown effect 'ratelimit'"):
        check_candidates(["ratelimit"])
    with pytest.raises(ModelError, match="repeated"):
        check_candidates(["delay", "delay"])
    with pytest.raises(ModelError, match="at least one"):
        check_candidates([])


def test_diagnose_takes_arrays_columns_and_records_alike():
    """What users hold: (t, u, y) arrays, a mapping of columns or a Record, for the data and the validation data."""
    t = np.arange(0, 8, 0.01)
    u = np.where((t % 2) >= 1, 1.0, 0.0)
    G = Plant.from_string("2/(0.2*s+1)")
    rng = np.random.default_rng(3)
    y = simulate_plant(G.with_delay(0.05), t, u) + 0.005 * rng.normal(size=t.size)
    y_val = simulate_plant(G.with_delay(0.05), t, u) + 0.005 * rng.normal(size=t.size)
    kw = {"candidates": ["delay", "lag"], "n_null": 3}
    by_record = diagnose(G, record_from_arrays(t, u, y), record_from_arrays(t, u, y_val), **kw)
    by_arrays = diagnose(G, (t, u, y), (t, u, y_val), **kw)
    by_columns = diagnose(G, {"time": t, "input": u, "output": y}, np.column_stack([t, u, y_val]), **kw)
    assert by_record.verdict["effects"] == ["delay"]
    for other in (by_arrays, by_columns):
        assert other.verdict == by_record.verdict
        assert other.attribution.effects[0].parameters == by_record.attribution.effects[0].parameters
    runs = diagnose(G, (t, u, y), [(t, u, y_val), record_from_arrays(t, u, y_val)], **kw)
    assert isinstance(runs.validate, tuple) and len(runs.validate) == 2


def test_diagnose_names_a_form_that_is_not_a_record():
    with pytest.raises(DataError, match="not a record"):
        diagnose(Plant.from_string("2/(0.2*s+1)"), 42, candidates=["delay"])


@pytest.mark.parametrize("seed", [0, 1])
def test_a_symmetric_actuator_saturation_is_named_with_both_limits(seed):
    """Found by a black-box test: ``4/(s^2 + 2.4 s + 4)`` behind an input clipped at +-0.6 (random command levels in
    [-1, 1], noise std 0.01). The saturation's grid tried one limit at a time; its one-sided fit lost to a static
    nonlinearity (a2 = 0.012, a3 = -0.43). The record is simulated here by scipy (the clipped command through the
    linear plant, zero-order hold), not by synth."""
    from scipy import signal

    rng = np.random.default_rng(seed)
    dt, n = 0.01, 20_000
    t = np.arange(n) * dt
    u = np.repeat(rng.uniform(-1.0, 1.0, n // 200), 200)
    num, den, _ = signal.cont2discrete(([4.0], [1.0, 2.4, 4.0]), dt, method="zoh")
    y = signal.lfilter(np.ravel(num), den, np.clip(u, -0.6, 0.6)) + 0.01 * rng.standard_normal(n)
    d = diagnose(Plant.from_string("4/(s^2+2.4*s+4)"), (t, u, y))
    assert d.verdict["effects"][0] == "saturation", d.summary
    p = next(e for e in d.attribution.effects if e.effect == "saturation").parameters
    assert abs(p["lower"] + 0.6) < 0.06 and abs(p["upper"] - 0.6) < 0.06


def test_a_one_sided_saturation_headline_writes_the_absent_limit_as_the_table_does():
    """``min(u, 0.5)`` through ``4/(s^2 + 2.4 s + 4)`` (scipy, zero-order hold): the verdict names saturation with its
    upper limit, and its headline writes the absent lower limit as ``-inf`` (it wrote ``-none``; found by a black-box
    test)."""
    from scipy import signal

    rng = np.random.default_rng(3)
    dt, n = 0.01, 20_000
    t = np.arange(n) * dt
    u = np.repeat(rng.uniform(-1.0, 1.0, n // 200), 200)
    num, den, _ = signal.cont2discrete(([4.0], [1.0, 2.4, 4.0]), dt, method="zoh")
    y = signal.lfilter(np.ravel(num), den, np.minimum(u, 0.5)) + 0.01 * rng.standard_normal(n)
    d = diagnose(Plant.from_string("4/(s^2+2.4*s+4)"), (t, u, y))
    assert d.verdict["effects"][0] == "saturation", d.summary
    p = next(e for e in d.attribution.effects if e.effect == "saturation").parameters
    assert abs(p["upper"] - 0.5) < 0.03 and p["lower"] == -np.inf
    assert "lower = -inf" in d.summary and "none" not in d.summary
