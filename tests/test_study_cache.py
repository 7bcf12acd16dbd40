"""The design report's spec-only studies kept on disk (synth.report.studies, synth.disk_cache): a second run
of the same spec reuses them, a change to what they read (the simulation block, the reference, the plant) or
to the code is a miss, an edited requirement is not, and SYNTH_RESULT_CACHE=off computes them every time."""

from __future__ import annotations

import pytest

import synth.disk_cache as disk_cache
import synth.gap.x4_case as x4_case
from synth.report.studies import spec_studies
from synth.spec import load_spec


@pytest.fixture
def gap_calls(tmp_path, monkeypatch) -> list[float]:
    """Counts the gap case's runs (each returns the spec's rate limit, so a stale hit would show)."""
    monkeypatch.setenv("SYNTH_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("SYNTH_RESULT_CACHE", raising=False)
    calls: list[float] = []

    def counting(spec, objects=None):
        rate = spec.simulation.actuator[0].rate
        calls.append(rate)
        return {"rate": rate}

    monkeypatch.setattr(x4_case, "x4_gap_case", counting)
    return calls


def _gap_case(spec):
    return dict(spec_studies(spec))["gap_case"]()


def test_a_second_run_reuses_the_study_and_a_changed_input_does_not(gap_calls):
    spec = load_spec("specs/x4_rotor.yaml")
    first = _gap_case(spec)
    assert _gap_case(load_spec("specs/x4_rotor.yaml")) == first == ({"rate": 10000.0}, {})
    assert gap_calls == [10000.0]
    # a requirement edited: the studies do not read requirements
    tighter = spec.model_copy(update={"requirements": spec.requirements[:1]})
    _gap_case(tighter)
    assert len(gap_calls) == 1
    # the rate limit changed: a miss, and the new value
    actuator = [spec.simulation.actuator[0].model_copy(update={"rate": 5000.0}), *spec.simulation.actuator[1:]]
    slower = spec.model_copy(update={"simulation": spec.simulation.model_copy(update={"actuator": actuator})})
    assert _gap_case(slower)[0] == {"rate": 5000.0}
    # the reference's published rise time changed: a miss
    other = spec.model_copy(update={"reference": spec.reference.model_copy(update={"rise_time": 0.04})})
    _gap_case(other)
    assert gap_calls == [10000.0, 5000.0, 10000.0]


def test_a_code_change_is_a_miss_and_the_cache_can_be_turned_off(gap_calls, monkeypatch):
    spec = load_spec("specs/x4_rotor.yaml")
    _gap_case(spec)
    monkeypatch.setattr(disk_cache, "code_fingerprint", lambda: "another version")
    _gap_case(spec)
    assert len(gap_calls) == 2
    monkeypatch.setenv("SYNTH_RESULT_CACHE", "off")
    _gap_case(spec)
    _gap_case(spec)
    assert len(gap_calls) == 4
