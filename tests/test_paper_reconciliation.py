"""The X-4 paper's numbers beside synth's computed values: every non-reconciliation asserted with its numbers."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.controllers import Controller
from synth.loop import Loop
from synth.paper_checks import EQ15, PLANT, PaperTable, onset_delay, x4_paper_checks
from synth.paper_row import AGREES, APPROXIMATE, DISAGREES
from synth.plant import Plant


@pytest.fixture(scope="module")
def table() -> PaperTable:
    return x4_paper_checks()


def test_eq15_slow_pole_pair(table):
    pole, zero = table.row("eq. 15 slow pole (measured)"), table.row("eq. 15 zero (measured)")
    assert (pole.paper, zero.paper) == ("0.0042", "0.0046")
    assert pole.synth == pytest.approx(0.4429, abs=1e-4) and zero.synth == pytest.approx(0.43)
    assert pole.status == zero.status == DISAGREES
    assert pole.source == "eq. 15"


def test_fast_pole_measured_vs_model(table):
    r = table.row("eq. 15 fast pole (measured)")
    assert r.paper == "99" and r.synth == pytest.approx(78.70, abs=0.01) and r.status == DISAGREES
    # the model's value is the one synth.Loop computes, not a typed-in number
    poles = Loop(Plant.from_string(PLANT), Controller("P", {"kp": 3.0})).closed_loop_poles()
    assert r.synth == pytest.approx(float(max(-poles.real)))


def test_eq14_against_the_model(table):
    assert table.row("eq. 14 fast pole").synth == pytest.approx(78.70, abs=0.01)
    assert table.row("eq. 14 fast pole").status == DISAGREES
    assert "78.55" in table.row("eq. 14 fast pole").reconcile  # eq. 14 is eq. 5 at K = 68.85/23
    assert table.row("eq. 14 gain").synth == pytest.approx(69.0)


def test_slew_rate_units(table):
    cross = table.row("slew-rate crossing of P(3)")
    ratio = table.row("B/De stated (paper) / needed for a 5 rad/s crossing (synth)")
    assert cross.paper == "5" and cross.synth == pytest.approx(1e4 / (5 * 3), rel=1e-3) and cross.status == DISAGREES
    assert ratio.paper == "2000" and ratio.synth == pytest.approx(15.0, rel=1e-6) and ratio.status == DISAGREES
    rate = table.row("rate limit as 8 % of full throttle per 1 ms sample")
    assert rate.synth == pytest.approx(20.4) and rate.status == DISAGREES


def test_requirement_rows(table):
    assert table.row("low-frequency plant gain").synth == pytest.approx(23 * 0.43 / (9.6 * 0.54))
    assert table.row("minimum gain for -15 dB").status == AGREES
    assert table.row("minimum gain for -15 dB").synth == pytest.approx((10 ** 0.75 - 1) / 1.8)
    assert table.row("static sensitivity at K = 3").status == AGREES
    band = table.row("band below which -15 dB is required (paper) / held by P(3) (synth)")
    assert band.synth == pytest.approx(10.33, abs=0.05) and band.status == DISAGREES
    onset = table.row("limit-cycle onset gain")
    assert onset.synth == pytest.approx(3.69, abs=0.01) and onset.status == DISAGREES


def test_onset_delay_is_where_the_gain_turns_critical():
    plant = Plant.from_string(PLANT)
    d = onset_delay(plant, 5.0)
    assert 0.013 < d < 0.016
    from synth.synthesis.gainset import critical_gains

    assert critical_gains(plant, [d])[0]["critical_gain"] == pytest.approx(5.0, rel=1e-3)
    assert onset_delay(plant, 1e-3, hi=0.01) is None  # a tiny gain stays stable


def test_closed_loop_measurements(table):
    bw = table.row("closed-loop bandwidth (measured)")
    assert bw.paper == "70" and bw.synth == pytest.approx(83.2, abs=0.1) and bw.status == DISAGREES
    rise = table.row("closed-loop rise time (measured)")
    assert rise.synth == pytest.approx(0.025, abs=0.001) and rise.status == DISAGREES
    ol = table.row("open-loop rise time")
    assert ol.synth == pytest.approx(0.125, abs=0.002) and "0.223" in ol.reconcile
    dc = table.row("closed-loop DC gain (eq. 15)")
    assert float(dc.paper) == pytest.approx(83 * 0.0046 / (99 * 0.0042), abs=1e-3)
    assert Plant.from_string(EQ15).dc_gain() == pytest.approx(float(dc.paper), abs=1e-3)


def test_identification_rows(table):
    snr = table.row("SNR after averaging the steps")
    assert snr.synth == pytest.approx(38 + 10 * np.log10(70)) and snr.status == APPROXIMATE


def test_the_sizing_rows_are_in_the_one_table(table):
    assert table.row("shaft power 131 W / 0.1749 N m: speed").status == DISAGREES
    assert table.row("current limit").status == DISAGREES
    assert table.row("induced power for 12.7 N").status == DISAGREES


def test_table_forms(table):
    d = json.loads(json.dumps(table.to_dict()))
    assert d["disagreements"] == len(table.disagreements()) >= 20
    assert all(r["unit"] and r["source"] and r["reconcile"] for r in d["rows"])
    md = table.to_markdown()
    assert md.count("\n") == len(table.rows) + 1
    with pytest.raises(KeyError, match="no row 'nothing'"):
        table.row("nothing")
