"""The design benchmark's reference (``benchmarks/design_reference.py``) refines a one-parameter search to the
feasibility boundary where the optimum lies there. Until session 75 its candidates had to hold a slack of +0.05 on
the coarse grid, so the refinement started from a point 5 % inside and stopped short: P on 2/(s+1) with bandwidth
<= 6 rad/s, maximize bandwidth, gave kp = 2.362 for 2.507."""

import numpy as np
import pytest

from benchmarks.design_reference import reference


@pytest.mark.parametrize("gain, cap", [(2.0, 6.0), (0.7, 3.0), (5.0, 40.0)])
def test_one_parameter_optimum_on_the_boundary(gain: float, cap: float) -> None:
    # g/(s+1) under kp: T = g kp/(s + 1 + g kp); |T/T(0)| = 10^(-3/20) at w = x (1 + g kp), x from 1 + x^2 = 10^(3/10)
    x = np.sqrt(10 ** 0.3 - 1.0)
    kp_star = (cap / x - 1.0) / gain
    spec = {"controller": {"type": "P", "bounds": {"kp": [0, 4 * kp_star]}},
            "requirements": [{"type": "bandwidth", "max": cap}], "objective": {"maximize": "bandwidth"}}
    r = reference([gain], [1.0, 1.0], 0.0, spec)
    assert r.feasible
    assert r.best.params["kp"] == pytest.approx(kp_star, rel=2e-4)
    assert r.best.objective == pytest.approx(cap, rel=2e-4)
