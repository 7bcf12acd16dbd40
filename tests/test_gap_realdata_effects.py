"""The new effects on the real records of ../shared/data, each against what its README documents.

- silverbox_duffing: a hardening cubic spring (the resonance rises with amplitude): ``duffing`` is named
  and its cubic coefficient is positive and near the README's own ARX check (68.2 -> 70.6 Hz as the
  output std grows 11.5 -> 81.9 mV: ``((70.6/68.2)^2 - 1) / (3 (0.0819^2 - 0.0115^2)) = 3.6 V^-2``).
- hsm150_two_motor_steps: up (positive) and down (negative) torque steps differ; incremental gain down/up
  between 40/97 and 46/71 (README): ``direction`` is named and ``1 + gain_down`` lies there.
- esc_thrust_stand_1s: the measured battery voltage given as an aux channel drives effects, and the verdict
  says how much it explained (the issue: it was only used to bin the residual).
"""

import numpy as np
import pytest

from synth.data import load_record
from synth.gap.diagnose import diagnose
from synth.plant import Plant
from tests.conftest import shared_path

README_CUBIC = ((70.6 / 68.2) ** 2 - 1) / (3 * (0.0819**2 - 0.0115**2))  # V^-2, from the README's ARX check


def test_silverbox_hardening_spring_is_named_with_the_readme_cubic():
    path = shared_path("data", "silverbox_duffing", "SNLS80mV.csv")
    d = np.genfromtxt(path, delimiter=",", names=True)
    a, b = 24000, 32000  # the arrow's growing-amplitude part: trained on the first half, held out on the larger second
    u, y = d["V1"][a:b] - np.mean(d["V1"][a:b]), d["V2"][a:b] - np.mean(d["V2"][a:b])
    t = np.arange(b - a) / 610.3515625
    G = Plant.from_string("1.9035e5/(s^2+40.684*s+1.9055e5)")  # identified on samples 2000-6000 (small amplitude)
    dg = diagnose(G, (t, u, y), candidates=["duffing", "static_nonlinearity"], max_effects=1)
    assert dg.verdict["effects"] == ["duffing"]
    best = next(e for e in dg.attribution.effects if e.effect == "duffing")
    assert best.accepted and best.shrinkage_ci[0] > 0.05  # measured 0.29 [0.10, 0.42]
    assert 0.5 * README_CUBIC < best.parameters["cubic"] < 2.0 * README_CUBIC  # measured 3.86 (README 3.6)


def hsm150_record(k: int):
    """Run ``k`` of the +0.050 -> +0.065 N m (up) and -0.030 -> -0.045 N m (down) steps, joined, 100 Hz, from 5 s."""
    import scipy.io

    parts = []
    for name in (f"idf_pos_0.065_{k}.mat", f"idf_neg_0.045_{k}.mat"):
        data = scipy.io.loadmat(shared_path("data", "hsm150_two_motor_steps", name), squeeze_me=True)["data"]
        parts.append((data[500::10, 4], data[500::10, 3]))  # torque command [N m], velocity [rad/s]
    u = np.r_[parts[0][0], parts[1][0]]
    y = np.r_[parts[0][1], parts[1][1]]
    return np.arange(u.size) * 0.01, u, y


def test_hsm150_up_and_down_steps_differ_by_direction():
    G = Plant.from_string("7112/(s+0.6592)")  # identified on the up-steps of run 1 (first 15 s)
    dg = diagnose(G, hsm150_record(1), [hsm150_record(2), hsm150_record(3)],
                  candidates=["direction", "lag", "delay"], max_effects=1)
    assert dg.verdict["effects"] == ["direction"]
    best = next(e for e in dg.attribution.effects if e.effect == "direction")
    assert best.shrinkage_ci[0] > 0.1  # measured 0.49 [0.27, 0.66]
    ratio = 1.0 + best.parameters["gain_down"]  # measured 0.49
    assert 40 / 97 < ratio < 46 / 71


def test_esc_measured_voltage_drives_effects_and_the_verdict_says_how_much():
    path = shared_path("data", "esc_thrust_stand_1s", "StepsTest20230615_2023-06-15_174003.csv")
    cols = ("Time (s)", "ESC signal (µs)", "Thrust (gf)")
    with_v = load_record(path, *cols, aux=["Voltage (V)"])
    without = load_record(path, *cols)
    G = Plant.from_string("0.0257/(0.1*s+1)")  # 25.7 gf over the 1000 us range, 0.1 s
    names = ["measured_sag(Voltage (V))", "aux_input(Voltage (V))", "supply_sag"]
    dg = diagnose(G, with_v, candidates=names, max_effects=1, split="interleaved")
    rows = {a["effect"]: a for a in dg.verdict["aux"]}
    assert [a["channel"] for a in dg.verdict["aux"]] == ["Voltage (V)"]
    assert "Voltage (V)" in dg.summary
    sag = next(e for e in dg.attribution.effects if e.effect == "measured_sag(Voltage (V))")
    assert 0.0 < sag.parameters["sag"] < 1.5  # thrust falls with the supply (measured 0.76; 1 = proportional)
    best = max(dg.attribution.effects, key=lambda e: e.shrinkage)
    assert rows[best.effect]["shrinkage"] == pytest.approx(best.shrinkage)
    # without the voltage the record has no aux channel: no aux-driven default candidate, no aux verdict
    plain = diagnose(G, without, candidates=["supply_sag"], max_effects=1, split="interleaved")
    assert "aux" not in plain.verdict
    from synth.gap.effects.registry import aux_candidates

    assert aux_candidates(sorted(with_v.aux)) == ("measured_sag(Voltage (V))", "aux_input(Voltage (V))")
    assert aux_candidates(sorted(without.aux)) == ()
