"""Peaks of |S|, |T| and |KS| narrower than the check's grid (a closed-loop pole next to an open-loop one), against a
brute-force evaluation written here: the loop's response on 400,000 evenly spaced frequencies around the pole."""

from __future__ import annotations

import numpy as np

from synth.check import check
from synth.controllers import Controller
from synth.loop import Loop
from synth.plant import Plant
from synth.spec import parse_spec

SEED8_88 = {  # the design benchmark's seed 8 #88, with the controller a rescaled design reached
    "name": "rand_8_88",
    "plant": {"tf": "0.705268*1/((s+0.173261)*(s+0.627048))", "delay": 0.101715},
    "controller": {"type": "rational", "order": [2, 3]},
    "requirements": [{"type": "peak_sensitivity", "max_db": 3.0668}, {"type": "bandwidth", "min": 0.12671}],
}
CONTROLLER = {"b0": 1.9268810468471189e-07, "b1": -14.636, "b2": 20.3619, "a0": 501.357, "a1": 697.497,
              "a2": 0.702755046634686}


def _responses(num_c, den_c, num_p, den_p, delay, w):
    s = 1j * w
    C = np.polyval(num_c, s) / np.polyval(den_c, s)
    G = np.polyval(num_p, s) / np.polyval(den_p, s) * np.exp(-delay * s)
    L = C * G
    return {"S": 1 / (1 + L), "T": L / (1 + L), "KS": C / (1 + L)}


def test_a_hidden_sensitivity_peak_fails_the_check():
    spec = parse_spec(SEED8_88)
    w = np.linspace(26.3, 26.5, 400_001)
    num_c = [CONTROLLER["b2"], CONTROLLER["b1"], CONTROLLER["b0"]]
    den_c = [1.0, CONTROLLER["a2"], CONTROLLER["a1"], CONTROLLER["a0"]]
    brute = 20 * np.log10(np.abs(_responses(num_c, den_c, [0.705268], np.poly([-0.173261, -0.627048]),
                                            0.101715, w)["S"]).max())
    assert brute > 21.0  # the peak is there: 21.45 dB within 0.002 rad/s of 26.405 rad/s
    for per_decade in (80, 1600):
        result = check(spec, Controller("rational", CONTROLLER), per_decade)
        peak = result.requirements[1]  # [0] is closed-loop stability
        assert not peak.met
        assert abs(peak.value - brute) < 0.01


def test_random_near_cancellations_are_seen():
    """A controller with a lightly damped pole pair (damping 1e-5 to 1e-3, either side of the axis) and a gain over
    three decades around random stable plants with delays: each peak the check reports (80 points per decade) is
    within 0.05 dB of the brute force's, never below. (Before the narrow-peak points the check missed 7 of these
    165 peaks, all of |T|, by 9-42 dB.)"""
    from synth.requirements.control_sensitivity import PeakControlSensitivity
    from synth.requirements.sensitivity import PeakComplementary, PeakSensitivity

    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(120):
        poles = -(10 ** rng.uniform(-1, 1, 2))
        num_p, den_p = [float(10 ** rng.uniform(-0.5, 1))], np.poly(poles)
        delay = float(10 ** rng.uniform(-2, -0.5))
        wn = float(10 ** rng.uniform(0, 1.5))
        zeta = float(rng.choice([-1, 1]) * 10 ** rng.uniform(-5, -3))
        den_c = np.polymul([1.0, 2 * zeta * wn, wn * wn], [1.0, float(10 ** rng.uniform(0, 1))])
        num_c = (np.array([float(rng.normal()) * 0.05 * wn, 0.0, float(rng.uniform(0.1, 1.0))]) * den_c[-1]
                 * float(10 ** rng.uniform(-3, 0)))
        params = {"b0": num_c[2], "b1": num_c[1], "b2": num_c[0], "a0": den_c[3], "a1": den_c[2], "a2": den_c[1]}
        loop = Loop(Plant(np.array(num_p), den_p, delay=delay), Controller("rational", params))
        if not loop.stability().stable:
            continue
        w = np.linspace(wn * 0.97, wn * 1.03, 400_001)
        brute = _responses(num_c, den_c, num_p, den_p, delay, w)
        for req, key in ((PeakSensitivity(type="peak_sensitivity", max_db=0.0), "S"),
                         (PeakComplementary(type="peak_complementary", max_db=0.0), "T"),
                         (PeakControlSensitivity(type="peak_control_sensitivity", max_db=0.0), "KS")):
            local = 20 * np.log10(np.abs(brute[key]).max())
            reported = req.evaluate(loop, 80).value
            assert reported >= local - 0.05, (key, params, delay, reported, local)
            checked += 1
    assert checked >= 150
