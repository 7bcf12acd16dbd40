"""Issue 16, frequency response: the default top (a fifth of Nyquist) no longer hides a resonance above it.

The default range is kept, but when the coherent band reaches the default top and the data stay coherent and
excited above it, the result's notes (printed as ``note:``) say how far, where ``|H|`` peaks there, and which
``--wmax`` shows it. Before the change the Silverbox's resonance near 440 rad/s lay above the default top of
383.5 rad/s and nothing said so.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.signal import lsim

from synth.data import record_from_arrays
from synth.ident.spectra import frequency_response
from tests.conftest import shared_path

FS = 100.0                  # Nyquist 314.2 rad/s, default top 62.83 rad/s
WN, ZETA = 100.0, 0.02      # a lightly damped mode above the default top: peak 1 / (2 zeta) = +28 dB


def _record(keep=lambda w: w > 0, n: int = 12000, seed: int = 5):
    """Noise input (flat where ``keep(w)`` [rad/s]), through the mode by lsim, with a little output noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    w = 2 * np.pi * np.fft.rfftfreq(n, 1 / FS)
    U = np.fft.rfft(rng.standard_normal(n))
    U[~keep(w)] = 0.0
    u = np.fft.irfft(U, n)
    u /= np.std(u)
    _, y, _ = lsim(([WN ** 2], [1.0, 2 * ZETA * WN, WN ** 2]), u, t)
    return record_from_arrays(t, u, y + 0.01 * np.std(y) * rng.standard_normal(n), source="mode")


def test_a_mode_above_the_default_top_is_reported_with_its_peak():
    resp = frequency_response(_record())
    above = resp.above_default_top
    assert resp.w[-1] == pytest.approx(0.2 * np.pi * FS) and resp.band.w_max == resp.w[-1]
    assert above is not None, "the mode at 100 rad/s lies above the default top: the result must say so"
    assert above["peak_w"] == pytest.approx(WN, rel=0.03)
    # |H| at the peak over |H| at 62.83 rad/s: 1/(2 zeta) against 1/|1 - 0.6283^2| = 28.0 - 4.4 dB
    true_rise = 20 * np.log10(1 / (2 * ZETA)) - 20 * np.log10(1 / (1 - (0.2 * np.pi * FS / WN) ** 2))
    assert above["peak_db"] == pytest.approx(true_rise, abs=3.0)
    assert above["coherent_to"] > 1.5 * WN and above["excited_to"] > 1.5 * WN
    top = _top_notes(resp.notes)
    assert len(top) == 1 and f"pass --wmax {above['coherent_to']:.4g}" in top[0]
    # the suggested --wmax shows the mode
    wide = frequency_response(_record(), w_max=above["coherent_to"])
    k = int(np.argmax(np.abs(wide.H)))
    assert wide.w[k] == pytest.approx(WN, rel=0.03) and not _top_notes(wide.notes) and wide.above_default_top is None



def _top_notes(notes) -> list:
    """The notes about the band above the default top (a record not at rest also gets one about its low end)."""
    return [n for n in notes if "default upper limit" in n]

def test_no_note_when_the_input_stops_at_the_default_top_or_wmax_is_given():
    # the input excites up to 55 rad/s only: above the default top the output is leakage and noise
    resp = frequency_response(_record(lambda w: (w > 0) & (w < 55.0)))
    assert resp.above_default_top is None and not _top_notes(resp.notes)
    given = frequency_response(_record(), w_max=0.2 * np.pi * FS)
    assert given.above_default_top is None and not _top_notes(given.notes)


def test_cli_prints_the_note_and_writes_it_to_json(run_cli, tmp_path):
    r = _record()
    path = tmp_path / "mode.csv"
    np.savetxt(path, np.c_[r.t, r.u, r.y], delimiter=",", header="t,u,y", comments="")
    res = run_cli("freqresp", "--data", str(path))
    assert res.code == 0, res.err
    note = next(x for x in res.out.splitlines() if x.startswith("note: the coherent band reaches the default"))
    assert "upper limit 62.83 rad/s" in note and "|H| peaks there at" in note and "pass --wmax" in note
    peak = float(note.split("|H| peaks there at ")[1].split(" rad/s")[0])
    assert peak == pytest.approx(WN, rel=0.03)
    js = json.loads(run_cli("freqresp", "--data", str(path), "--json", "-").out)
    assert js["above_default_top"]["peak_w"] == pytest.approx(peak, rel=1e-3) and len(_top_notes(js["notes"])) == 1


def test_the_silverbox_resonance_above_the_default_top_is_not_missed(run_cli):
    path = shared_path("data", "silverbox_duffing", "Schroeder80mV.csv")
    args = ("freqresp", "--data", str(path), "--dt", "0.0016384", "--input", "V1", "--output", "V2")
    res = run_cli(*args, "--json", "-")
    assert res.code == 0, res.err
    js = json.loads(res.out)
    above = js["above_default_top"]
    assert js["w"][-1] == pytest.approx(383.5, abs=0.1)       # the default top, below the resonance
    assert above is not None and 430 <= above["peak_w"] <= 450 and above["peak_db"] > 5
    assert above["coherent_to"] > 1000 and above["excited_to"] > 1000   # the multisine reaches ~1280 rad/s
    text = run_cli(*args)
    assert any(x.startswith("note: the coherent band reaches the default upper limit 383.5 rad/s")
               for x in text.out.splitlines()), text.out
    # (a denser grid than the default 40 per decade: fewer FFT bins per cell up there, a faster estimate)
    wide = json.loads(run_cli(*args, "--wmax", f"{above['coherent_to']:.4g}", "--points-per-decade", "160",
                              "--json", "-").out)
    w, mag = np.array(wide["w"]), np.array(wide["magnitude_db"])
    assert 430 <= w[np.argmax(mag)] <= 455 and wide["coherent_band"]["w_max"] > 440
