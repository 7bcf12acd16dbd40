"""The identification kept on disk between runs (synth.ident.result_cache): a hit gives the same result
without fitting, and any change to what determines the result (the record's bytes, the settings) is a miss."""

from __future__ import annotations

import numpy as np
import pytest

import synth.ident.identification as identification
from synth.ident import from_spec
from synth.ident.from_spec import IdentifySettings, identify_plant
from synth.ident.simulate import simulate_plant
from synth.plant import Plant, Signal

TRUE = Plant.from_string("3/(s+2)", delay=0.02)


@pytest.fixture
def record(tmp_path, monkeypatch):
    monkeypatch.setenv("SYNTH_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("SYNTH_IDENTIFY_CACHE", raising=False)
    t = np.arange(0, 12, 0.005)
    u = np.where((t % 4.0) >= 2.0, 1.0, 0.0)
    y = simulate_plant(TRUE, t, u) + 0.003 * np.random.default_rng(3).standard_normal(t.size)
    path = tmp_path / "run.csv"
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="t,u,y", comments="")
    return path


def _settings(path, structure="k/(s+p)") -> IdentifySettings:
    return IdentifySettings(str(path), "t", "u", "y", structure, "fit", None, "auto", 0.95, True)


def _fits(monkeypatch) -> list[int]:
    """Counts the fits run (the process-level cache is cleared so that only the disk cache can answer)."""
    calls: list[int] = []
    real = identification.identify

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(identification, "identify", counting)
    return calls


def _identify(settings):
    from_spec._identify_cached.cache_clear()
    return identify_plant(settings, None, Signal("u", "V"), Signal("y", "rad/s"))


def test_a_second_run_reuses_the_result_and_a_changed_record_or_block_does_not(record, monkeypatch):
    calls = _fits(monkeypatch)
    first = _identify(_settings(record))
    again = _identify(_settings(record))
    assert len(calls) == 1
    assert again.plant.to_string(12) == first.plant.to_string(12)
    assert np.array_equal(np.asarray(again.fit.covariance), np.asarray(first.fit.covariance))
    assert abs(first.fit.parameters["p"] - 2.0) < 0.05  # a real fit, not a stub

    _identify(_settings(record, "k/(T*s+1)"))  # another structure: a miss
    assert len(calls) == 2
    record.write_text(record.read_text() + "12,1,0\n")  # one more sample: other bytes, a miss
    _identify(_settings(record))
    assert len(calls) == 3


def test_an_unreadable_entry_is_recomputed_and_the_cache_can_be_turned_off(record, monkeypatch, tmp_path):
    calls = _fits(monkeypatch)
    first = _identify(_settings(record))
    entries = list((tmp_path / "cache" / "identify").glob("*.pickle"))
    assert len(entries) == 1
    entries[0].write_bytes(b"not a pickle")
    again = _identify(_settings(record))
    assert len(calls) == 2 and again.plant.to_string(12) == first.plant.to_string(12)

    monkeypatch.setenv("SYNTH_IDENTIFY_CACHE", "off")
    for entry in entries:
        entry.unlink()
    _identify(_settings(record))
    _identify(_settings(record))
    assert len(calls) == 4
    assert not list((tmp_path / "cache" / "identify").glob("*.pickle"))
