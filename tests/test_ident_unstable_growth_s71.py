"""A fitted model whose right-half-plane mode grows past e^14 over the record is a failure, not a result.

Black-box finding (session 71): ``5/((s+1)(s+5)) e^(-0.15 s)`` under a multisine on jittered time stamps, fitted with
``--delay fit``: exit 0 with k = 4.8e-74, a pole at +0.85 rad/s (growing e^170 over the 200 s record) and a 5.33 s
delay, fit 0.05 %, the pole and the delay not even flagged weak; a third-order PRBS record the same way (a pole at
+0.445 rad/s, fit 1.2 %). An open-loop record whose output stays bounded cannot hold such a mode."""

from __future__ import annotations

import numpy as np

from synth.ident.fit_failure import GROWING, fit_failure, roots_beyond_record


def test_a_mode_that_explodes_over_the_record_fails_the_fit_and_a_slow_one_does_not():
    exploding = roots_beyond_record(np.array([4.8e-74]), np.polymul([1.0, 66.3], [1.0, -0.852]), 200.0, 0.01)
    assert GROWING in exploding and "+0.852" in exploding
    why = fit_failure({"k": 4.8e-74, "p1": 66.3, "p2": -0.852}, np.array([1.0, 1.0, 5.0]), "Solve_Succeeded", True,
                      0.05, 5.33, 200.0, 20000, 5, ridge=exploding)
    assert why.startswith("the fitted model is unstable (a pole at +0.852 rad/s") and "explodes" in why
    # a short record of an unstable mode (e^2 over it) and a stable model are not failures on that ground
    assert roots_beyond_record(np.array([1.0]), np.array([1.0, -1.0]), 2.0, 0.01) == ""
    assert roots_beyond_record(np.array([1.0]), np.array([1.0, 0.852]), 200.0, 0.01) == ""
