"""A lead-lag on an unstable plant with a right-half-plane zero, whose stabilizing set random starts missed.

Problem 181 of the design benchmark's seed 13: ``21.6258 (1 - s/4.2526) / ((s - 0.4865)(s + 1.7019)(s + 0.2362))``,
lead-lag bounds k in [0, 7.66], z in [0.139, 55.8], p in [0.139, 139], a static sensitivity of at most
-11.18 dB, maximize bandwidth. 600 random controllers stabilized none, and design answered "undetermined",
while the benchmark's reference found k = 7.66, z = 0.188, p = 34.2. The start search now also takes the exact
stabilizing set of k for zeros drawn in the bounds (``synth.synthesis.axis_starts.leadlag_slices``). The checks
here are numpy's roots of the closed-loop polynomial and the static sensitivity by hand, not synth's code."""

import numpy as np

from synth import design, parse_spec

NUM = [-21.6258 / 4.2526, 21.6258]
DEN = np.poly([0.486492, -1.70187, -0.236173])
SPEC = {"name": "leadlag_181",
        "plant": {"tf": "21.6258*(1-s/4.2526)/((s-0.486492)*(s+1.70187)*(s+0.236173))"},
        "controller": {"type": "leadlag", "bounds": {"k": [0.0, 7.65653], "z": [0.139386, 55.7542],
                                                       "p": [0.139386, 139.386]}},
        "requirements": [{"type": "sensitivity_static", "max_db": -11.1844}],
        "objective": {"maximize": "bandwidth"}}


def test_the_lead_lag_is_designed_inside_the_stabilizing_set():
    result = design(parse_spec(SPEC))
    assert result.feasible, result.verdict
    k, z, p = (result.controller.parameters[n] for n in ("k", "z", "p"))
    closed = np.polyadd(np.polymul([1.0, p], DEN), np.polymul(k * np.array([1.0, z]), NUM))
    assert np.max(np.roots(closed).real) < 0
    loop_gain_at_0 = k * z / p * NUM[-1] / DEN[-1]
    assert 20 * np.log10(abs(1.0 / (1.0 + loop_gain_at_0))) <= -11.1844 + 1e-6
    assert result.objective["value"] > 0.9 * 3.2228  # the reference's best bandwidth (rad/s); synth: 3.094
