"""``synth psd``: bad options refused in one line (exit 2), requirements withheld on weak evidence, uneven stamps.

Black-box findings (session 44): bands past Nyquist, a negative spike threshold, a zero or overflowing
bandwidth factor and a conflicting ``--dt`` were accepted; a one-segment spectrum and pure white noise
got a bandwidth requirement; jittered time stamps lost a third of the record's mean square to linear
interpolation.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.signal import lfilter

from synth.ident.psd import MIN_SEGMENTS, analyze_psd

DT = 0.01          # Nyquist pi / DT = 314.16 rad/s


def _write(path, x, dt=DT, t=None):
    t = np.arange(x.size) * dt if t is None else t
    np.savetxt(path, np.column_stack([t, x]), delimiter=",", header="time,x", comments="", fmt="%.12g")
    return str(path)


@pytest.fixture
def white(tmp_path):
    return _write(tmp_path / "white.csv", np.random.default_rng(0).normal(size=5000))


def _one_line_exit_2(r, *needles):
    assert r.code == 2, (r.out, r.err)
    assert len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err, r.err
    for n in needles:
        assert n in r.err, r.err


# ------------------------------------------------------------------------------------------ 1. bands
@pytest.mark.parametrize(("option", "w1", "w2", "what"), [
    ("--band", "10", "1000", "past the Nyquist frequency 314.15927 rad/s"),
    ("--floor-band", "100", "500", "past the Nyquist frequency 314.15927 rad/s"),
    ("--band", "400", "1000", "wholly above the Nyquist frequency 314.15927 rad/s"),
    ("--floor-band", "400", "1000", "wholly above the Nyquist frequency 314.15927 rad/s"),
    ("--band", "0", "100", "must be > 0 rad/s"),
    ("--band", "-5", "100", "must be > 0 rad/s"),
    ("--band", "100", "50", "increasing"),
    ("--floor-band", "nan", "100", "must be > 0 rad/s"),
])
def test_band_past_nyquist_or_not_positive_increasing_is_refused(run_cli, white, option, w1, w2, what):
    r = run_cli("psd", "--data", white, "--time", "time", "--signal", "x", option, w1, w2)
    _one_line_exit_2(r, option, what)


def test_band_up_to_nyquist_is_accepted(run_cli, white):
    r = run_cli("psd", "--data", white, "--time", "time", "--signal", "x", "--band", "10", "314.159",
                "--floor-band", "150", "314.1593")
    assert r.code == 0, r.err


# ------------------------------------------------------------------------------------------ 2. spike threshold
@pytest.mark.parametrize("value", ["-3", "0", "nan", "inf"])
def test_spike_threshold_must_be_finite_positive_db(run_cli, white, value):
    r = run_cli("psd", "--data", white, "--time", "time", "--signal", "x", "--spike-db", value)
    _one_line_exit_2(r, "--spike-db", "finite number of dB > 0")


# ------------------------------------------------------------------------------------------ 3. factor
@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf"])
def test_factor_validated_even_without_a_share_frequency(run_cli, white, value):
    r = run_cli("psd", "--data", white, "--time", "time", "--signal", "x", "--factor", value)
    _one_line_exit_2(r, "--factor", "finite number > 0")


def _lowpass(seed=3, n=20_000, dt=0.002, wc=20.0, floor_std=0.05):
    rng = np.random.default_rng(seed)
    a = math.exp(-wc * dt)
    return lfilter([1 - a], [1, -a], rng.normal(size=n)) + floor_std * rng.normal(size=n), a


def test_factor_overflowing_the_bandwidth_is_refused(run_cli, tmp_path):
    p = _write(tmp_path / "lp.csv", _lowpass()[0], dt=0.002)
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x", "--factor", "1e308")
    _one_line_exit_2(r, "--factor", "not finite")
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x", "--factor", "2", "--json", "-")
    assert r.code == 0, r.err
    s = json.loads(r.out)["bandwidth_suggestion"]
    assert s["min_bandwidth"] == pytest.approx(2 * s["share_frequency"])


# ------------------------------------------------------------------------------------------ 4. dt
@pytest.mark.parametrize(("value", "what"), [("-0.01", "must be a finite number > 0 s"),
                                             ("0", "must be a finite number > 0 s"),
                                             ("nan", "must be a finite number > 0 s"),
                                             ("0.05", "disagrees with the 0.01 s of the time column")])
def test_dt_bad_or_conflicting_with_the_time_column(run_cli, white, value, what):
    r = run_cli("psd", "--data", white, "--time", "time", "--signal", "x", "--dt", value)
    _one_line_exit_2(r, "--dt", what)


def test_dt_agreeing_with_the_time_column_within_1_percent_is_accepted(run_cli, white):
    r = run_cli("psd", "--data", white, "--time", "time", "--signal", "x", "--dt", "0.01005")
    assert r.code == 0, r.err


def test_bad_dt_without_time_column(run_cli, tmp_path):
    p = tmp_path / "x.csv"
    p.write_text("x\n" + "".join(f"{v:.6g}\n" for v in np.random.default_rng(1).normal(size=400)))
    r = run_cli("psd", "--data", str(p), "--signal", "x", "--dt", "-0.01")
    _one_line_exit_2(r, "--dt", "must be a finite number > 0 s")


# ------------------------------------------------------------------------------------------ 5. few segments
def test_twenty_samples_give_no_confident_requirement(run_cli, tmp_path):
    p = _write(tmp_path / "short.csv", np.random.default_rng(0).normal(size=20))
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x")
    assert r.code == 0, r.err
    assert "suggested requirement" in r.out and f"undetermined: 1 segments averaged, need >= {MIN_SEGMENTS}" in r.out
    assert "'type': 'bandwidth'" not in r.out
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x", "--json", "-")
    s = json.loads(r.out)["bandwidth_suggestion"]
    assert s["status"] == "undetermined" and "min_bandwidth" not in s
    assert s["reason"] == f"undetermined: 1 segments averaged, need >= {MIN_SEGMENTS}"


def test_real_disturbance_with_three_segments_is_still_undetermined(run_cli, tmp_path):
    x, _ = _lowpass(n=2000)
    p = _write(tmp_path / "lp.csv", x, dt=0.002)
    # 1000-sample segments, 50 % overlap: 3 segments; the same record in 500-sample ones: 7
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x", "--segment", "2", "--requirements")
    assert r.code == 0, r.err
    assert "undetermined: 3 segments averaged, need >= 4" in r.out and "'type': 'bandwidth'" not in r.out
    assert "requirements:" not in r.out  # the requirements block is withheld too
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x", "--segment", "1", "--json", "-")
    assert json.loads(r.out)["bandwidth_suggestion"]["status"] == "suggested"


# ------------------------------------------------------------------------------------------ 6. significance
def test_white_noise_gives_no_bandwidth_requirement_over_24_seeds():
    # before: 2 of the first 6 seeds suggested a bandwidth (power above the floor 0.3-0.5 % of the total)
    suggested = []
    for seed in range(24):
        x = np.random.default_rng(seed).normal(size=20_000)
        a = analyze_psd([x], 0.002)
        if a.share_frequency is not None:
            suggested.append((seed, a.share_frequency))
        else:
            assert a.suggestion_withheld and "within the scatter" in a.suggestion_withheld
    # false-alarm rate 0.1 % per record: P(any of 24) = 2.4 %
    assert suggested == []


def test_significance_scatter_matches_white_noise_spread():
    """The stated 1-sigma scatter of the above-floor power is the spread seen over seeds (within 35 %)."""
    ratios = []
    for seed in range(40):
        a = analyze_psd([np.random.default_rng(100 + seed).normal(size=8_000)], 0.002)
        ratios.append(a.disturbance_power / a.disturbance_power_scatter)
    assert 0.6 < float(np.std(ratios)) < 1.35
    assert abs(float(np.mean(ratios))) < 0.6


def test_low_frequency_disturbance_still_gives_the_closed_form_share_frequency():
    x, a = _lowpass()                      # corner 20 rad/s, white floor of std 0.05
    noise = 0.05 * np.random.default_rng(99).normal(size=x.size)
    # closed form: the discrete first-order spectrum 1 / |1 - a e^{-jw dt}|^2 above the floor, integrated to 90 %
    w = np.linspace(0, math.pi / 0.002, 200_001)
    S = 1 / (1 + a * a - 2 * a * np.cos(w * 0.002))
    for analysis, above in ((analyze_psd([x], 0.002, noise=[noise]), S),   # floor from a noise record: 125.6 rad/s
                            # own floor: the upper half's median holds the filter's tail too: 104.9 rad/s
                            (analyze_psd([x], 0.002), S - np.median(S[w > w[-1] / 2]))):
        cum = np.cumsum(above)
        w90 = float(np.interp(0.9 * cum[-1], cum, w))
        assert analysis.suggestion_withheld is None and analysis.share_frequency is not None
        assert analysis.share_frequency == pytest.approx(w90, rel=0.1)
        assert analysis.disturbance_power > 100 * analysis.disturbance_power_scatter


# ------------------------------------------------------------------------------------------ 7. uneven stamps
def _jittered(tmp_path, seed=7, n=20_000, dt=0.002, jitter=0.2):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt + rng.uniform(-jitter, jitter, n) * dt
    x = 0.7 * rng.normal(size=n)
    return _write(tmp_path / "jit.csv", x, t=t), x


@pytest.mark.parametrize("seed, jitter", [(7, 0.2), (8, 0.3), (9, 0.4)])
def test_jittered_stamps_keep_the_mean_square_and_the_floor(run_cli, tmp_path, seed, jitter):
    """Stamps within +-jitter of an interval of their slots. Found by a black-box test: at +-30 % and +-40 % the grid
    through the first and the last stamp (each jittered itself) left stamps 60 % from it, the record was
    interpolated, white noise's floor came out 3.7 dB low and a 140 rad/s bandwidth was suggested."""
    p, x = _jittered(tmp_path, seed, jitter=jitter)
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x", "--json", "-")
    assert r.code == 0, r.err
    d = json.loads(r.out)
    # before: mean square 0.3247 against the raw 0.4929, floor -38.8 dB against sigma^2 dt / pi = -35.06 dB
    assert d["raw_variance"] == pytest.approx(float(np.var(x)), rel=1e-6)
    assert d["total_power"] == pytest.approx(float(np.var(x)), rel=0.03)
    assert d["floor_db"] == pytest.approx(10 * math.log10(0.49 * 0.002 / math.pi), abs=0.5)
    notes = " ".join(d["notes"])
    assert "not interpolated" in notes and "jitter" in notes
    assert d["bandwidth_suggestion"]["status"] == "not significant" and d["share_frequency"] is None
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x")
    assert "mean square" in r.out and f"{np.var(x):.4g}" in r.out


def test_irregular_stamps_interpolated_with_a_quantitative_note(run_cli, tmp_path):
    rng = np.random.default_rng(8)
    n, dt = 20_000, 0.002
    keep = np.sort(rng.choice(n, size=int(0.8 * n), replace=False))  # a fifth of the samples lost: gaps
    x = 0.7 * rng.normal(size=keep.size)
    p = _write(tmp_path / "gaps.csv", x, t=keep * dt)
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x", "--json", "-")
    assert r.code == 0, r.err
    d = json.loads(r.out)
    assert d["raw_variance"] == pytest.approx(float(np.var(x)), rel=1e-6)
    notes = " ".join(d["notes"])
    assert "linear interpolation attenuates the spectrum" in notes and "dB at half the Nyquist" in notes
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x")
    assert f"{np.var(x):.4g}" in r.out and "raw samples" in r.out


def test_white_noise_cli_says_not_significant(run_cli, tmp_path):
    # seed 2, 500 Hz: before, "suggested requirement {'type': 'bandwidth', 'min': 706.0}" from 0.76 % of the power
    p = _write(tmp_path / "w2.csv", np.random.default_rng(2).normal(size=20_000), dt=0.002)
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x", "--json", "-")
    assert r.code == 0, r.err
    d = json.loads(r.out)
    assert d["bandwidth_suggestion"]["status"] == "not significant" and d["share_frequency"] is None
    assert d["disturbance_power"] < 3.09 * d["disturbance_power_scatter"]
    r = run_cli("psd", "--data", p, "--time", "time", "--signal", "x")
    assert "not significant: the power above the floor" in r.out and "'type': 'bandwidth'" not in r.out


def test_white_noise_has_no_trend() -> None:
    """A black-box test saw white noise reported with 'trend +5.7 dB/decade', a line through its 3 lowest bins."""
    from synth.ident.psd import analyze_psd

    for seed in range(6):
        x = np.random.default_rng(300 + seed).normal(0.0, 0.7, 30_000)
        a = analyze_psd([x], 0.002)
        assert a.trend is None and any("spectrum is at its floor" in n for n in a.notes)
    t = np.arange(60_000) * 0.002  # a first-order disturbance (corner 20 rad/s) above a floor keeps its trend
    rng = np.random.default_rng(9)
    y = np.zeros(t.size)
    e = rng.normal(0.0, 1.0, t.size)
    for k in range(1, t.size):
        y[k] = y[k - 1] * np.exp(-20 * 0.002) + e[k] * 0.3
    a = analyze_psd([y + rng.normal(0.0, 0.01, t.size)], 0.002)
    assert a.trend is not None and a.trend.slope_db_per_decade < -6.0


def test_the_headers_unit_labels_the_text_and_the_variance_is_called_so(run_cli, tmp_path) -> None:
    """The ESC thrust log's header says 'Thrust (gf)': the text said '[unit]' and called the variance 'mean square'."""
    x = 5.0 + np.random.default_rng(3).normal(0.0, 0.7, 20_000)  # mean 5: variance 0.49, mean square about 25.5
    path = tmp_path / "thrust.csv"
    np.savetxt(path, np.column_stack([np.arange(x.size) * 0.002, x]), delimiter=",", header="Time (s),Thrust (gf)",
               comments="")
    r = run_cli("psd", "--data", str(path), "--time", "Time (s)", "--signal", "Thrust")
    assert r.code == 0, r.err
    assert "Thrust [gf]" in r.out and "[unit]" not in r.out
    line = next(ln for ln in r.out.splitlines() if ln.strip().startswith("variance"))
    assert float(line.split()[1]) == pytest.approx(float(np.var(x)), rel=1e-3) and "gf^2" in line


def test_a_top_a_hair_above_nyquist_is_told_with_digits_that_differ(tmp_path):
    """157.08 against a Nyquist frequency of 157.0796 rad/s (50 Hz) was shown as '157.08 ... above 157.1'."""
    from synth.data import record_from_arrays
    from synth.errors import DataError
    from synth.ident.spectra import frequency_response

    t = np.arange(3000) * 0.02
    u = np.random.default_rng(0).normal(size=t.size)
    with pytest.raises(DataError, match=r"w_max = 157.08 rad/s is above the Nyquist frequency 157.07963 rad/s"):
        frequency_response([record_from_arrays(t, u, u)], w_min=1.0, w_max=157.08)
