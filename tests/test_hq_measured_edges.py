"""Bandwidth and phase delay from measured responses at the edges of the data (found by a black-box test, session 44).

The references here are dense grids of the model's own response, written with numpy apart from synth: a crossing
below the lowest measured frequency made the other bandwidth "the lesser" (1.731 rad/s for a true 0.2914), and the
smooth bend of a lightly damped mode was taken for scatter, so the phase delay came from a line (0.474 s for 0.413).
"""

from __future__ import annotations

import numpy as np
import pytest

from synth.ident.hq import hq_from_frd


def _phase_deg(G, w: np.ndarray, start: float) -> np.ndarray:
    """Unwrapped phase of ``G`` on ``w``, anchored at ``start`` degrees at ``w[0]`` (the low-frequency asymptote)."""
    ph = np.degrees(np.unwrap(np.angle(G(w))))
    return ph - 360.0 * np.round((ph[0] - start) / 360.0)


def _first_down(w: np.ndarray, y: np.ndarray, level: float) -> float:
    i = int(np.flatnonzero((y[:-1] > level) & (y[1:] <= level))[0])
    return float(w[i] + (level - y[i]) * (w[i + 1] - w[i]) / (y[i + 1] - y[i]))


def _dense(G, start: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    w = np.logspace(-4, 2, 600_001)
    return w, 20 * np.log10(np.abs(G(w))), _phase_deg(G, w, start)


def _metrics(G, w: np.ndarray, start: float, **kw):
    return hq_from_frd(w, G(w), coherence=np.full(w.size, 0.99), averages=20, **kw)


def G_rate(w: np.ndarray) -> np.ndarray:
    s = 1j * w
    return 10 / (s * (s + 0.3) * (s + 20))


def G_mode(w: np.ndarray) -> np.ndarray:
    s = 1j * w
    return 3 * np.exp(-0.05 * s) / (s * (s**2 + 0.4 * s + 4))


def test_phase_bandwidth_below_the_data_is_not_replaced_by_the_gain_bandwidth() -> None:
    wd, _, ph = _dense(G_rate, -90.0)
    w135 = _first_down(wd, ph, -135.0)
    assert 0.28 < w135 < 0.30  # the reference: far below the 1 rad/s the record starts at
    m = _metrics(G_rate, np.logspace(0, 1, 60), -90.0, response_type="rate")
    assert m.bandwidth is None and m.bandwidth_limit == "below_data" and m.below_data == ("phase",)
    assert m.bandwidth_phase is None and m.bandwidth_gain is not None  # the gain bandwidth alone is not the lesser
    assert m.to_dict()["below_data"] == {"bandwidths": ["phase"], "lowest_frequency": 1.0}
    full = _metrics(G_rate, np.logspace(-2, 1, 240), -90.0, response_type="rate")
    assert full.below_data == () and full.bandwidth_limit == "phase"
    assert full.bandwidth == pytest.approx(w135, rel=2e-3)


def test_gain_bandwidth_below_the_data() -> None:
    wd, mag, ph = _dense(G_mode, -90.0)
    w180 = _first_down(wd, ph, -180.0)
    level = float(np.interp(np.log(w180), np.log(wd), mag)) + 6.0
    below = wd < w180
    wg = _first_down(wd[below], mag[below], level)
    assert 0.19 < wg < 0.21
    m = _metrics(G_mode, np.logspace(np.log10(1.2), 1.3, 80), -90.0, response_type="rate")
    assert m.bandwidth is None and m.below_data == ("gain",) and m.bandwidth_phase is not None
    full = _metrics(G_mode, np.logspace(-2, 1.3, 400), -90.0, response_type="rate")
    assert full.bandwidth_limit == "gain" and full.bandwidth == pytest.approx(wg, rel=1e-2)


def test_smooth_mode_is_not_scatter_but_noise_is() -> None:
    wd, _, ph = _dense(G_mode, -90.0)
    w180 = _first_down(wd, ph, -180.0)
    tau = -(float(np.interp(np.log(2 * w180), np.log(wd), ph)) + 180.0) / (np.degrees(1.0) * 2 * w180)
    assert tau == pytest.approx(0.413, abs=2e-3)
    w = np.logspace(np.log10(1.2), 1.3, 80)
    m = _metrics(G_mode, w, -90.0, response_type="rate")
    assert m.phase_method == "raw"
    assert m.phase_delay == pytest.approx(tau, rel=0.01)
    rng = np.random.default_rng(4)
    H = G_mode(w) * np.exp(1j * np.radians(rng.normal(0.0, 10.0, w.size)))
    noisy = hq_from_frd(w, H, coherence=np.full(w.size, 0.99), averages=20, response_type="rate")
    assert noisy.phase_method == "line"


def test_a_lag_past_its_corner_is_not_called_an_integrator() -> None:
    w = np.logspace(np.log10(1.07 * 2.0), 2, 60)  # 1/(s/2 + 1) from just past its corner: phase about -47 deg
    m = hq_from_frd(w, 1 / (1j * w / 2 + 1), coherence=np.full(w.size, 0.99), averages=20)
    assert "integrator" not in m.response_type_reason
    assert "--response-type" in m.response_type_reason


def test_options_of_the_other_source_and_bad_fit_bands_are_refused(run_cli, tmp_path) -> None:
    w = np.logspace(-1, 1.3, 80)
    frd = tmp_path / "fr.csv"
    np.savetxt(frd, np.column_stack([w, 20 * np.log10(abs(G_mode(w))), _phase_deg(G_mode, w, -90.0)]),
               delimiter=",", header="w,mag_db,phase_deg", comments="")
    for args, flag in ((["--frd", str(frd), "--delay", "0.1"], "--delay"),
                       (["--frd", str(frd), "--phase-fit", "line", "--fit-band", "-1", "5"], "--fit-band"),
                       (["--frd", str(frd), "--fit-band", "5", "2"], "--fit-band"),
                       (["--tf=1/(s+1)", "--averages", "3"], "--averages"),
                       (["--tf=1/(s+1)", "--fit-band", "1", "2"], "--fit-band")):
        r = run_cli("hq", *args)
        assert r.code == 2 and flag in r.err and len(r.err.strip().splitlines()) == 1, (args, r.err)
    with pytest.raises(Exception, match="fit_band"):
        hq_from_frd(w, G_mode(w), fit_band=(-1.0, 5.0))


def test_an_unstable_model_says_so() -> None:
    from synth.ident.hq import hq_from_plant
    from synth.plant import Plant

    m = hq_from_plant(Plant.from_string("1/((s-0.5)*(s+4)*(s+20))"))
    assert any("unstable" in n and "1 pole(s)" in n for n in m.notes)
    assert not any("unstable" in n for n in hq_from_plant(Plant.from_string("1/((s+0.5)*(s+4))")).notes)
