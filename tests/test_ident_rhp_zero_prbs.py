"""A right-half-plane zero under a fast PRBS: the whole-record refit takes the better of its two starts.

Found by a black-box test: 3(1 - 0.5 s)/((s + 1)(0.25 s + 1)) under a +-1 PRBS held 0.2 s (100 Hz, 60 s, 5 % noise).
The 0.2 s edge windows hold the zero's undershoot (the average's step came out -1.2), the model settles in 1.7 s, so
the whole record was refitted from the edge fit; that refit crawled onto the ridge K -> 0, a -> inf of K(1 - a s), at
its iteration limit with little left to gain along its way (accepted as converged), and `synth identify` printed K =
5e-6, a = 1.8e5 (fit 36 %), exit 0, on 6 of 12 noise seeds. Started from the whole record's own deterministic start,
the same record fits at 95 %. The reference is an output-error least-squares fit written here with scipy
(`least_squares` on the same structure's zero-order-hold response), started from a naive guess."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.signal import cont2discrete, lfilter

from synth.data import record_from_arrays
from synth.ident.identification import identify

STRUCTURE = "K*(1-a*s)/((T1*s+1)*(T2*s+1))"


def _response(theta: np.ndarray, t: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The structure's output to ``u`` held between samples (exact zero-order-hold discretization), in steady
    state at ``u[0]`` before the record."""
    k, a, t1, t2 = theta
    b, den, _ = cont2discrete(([-k * a, k], np.polymul([t1, 1.0], [t2, 1.0])), t[1] - t[0], method="zoh")
    return k * u[0] + lfilter(np.ravel(b), den, u - u[0])


def _record(seed: int, truth: np.ndarray, hold: int, dt: float, n: int):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    u = np.repeat(rng.integers(0, 2, n // hold + 1) * 2.0 - 1.0, hold)[:n]
    y = _response(truth, t, u)
    return t, u, y + 0.05 * np.std(y) * rng.normal(size=n)


@pytest.mark.parametrize("seed, truth, hold, dt, n", [
    (1, (3.0, 0.5, 1.0, 0.25), 20, 0.01, 6000),
    (2, (3.0, 0.5, 1.0, 0.25), 20, 0.01, 6000),
    (3, (1.0, 0.2, 2.0, 0.1), 10, 0.02, 6000),
])
def test_identify_matches_an_output_error_fit(seed, truth, hold, dt, n):
    t, u, y = _record(seed, np.array(truth), hold, dt, n)
    result = identify(record_from_arrays(t, u, y), STRUCTURE)
    fit = result.fit
    reference = least_squares(lambda th: _response(th[:4], t, u) + th[4] - y, [1.0, 0.1, 0.5, 2.0, 0.0],
                              method="lm").x
    k, a = fit.parameters["K"], fit.parameters["a"]
    slow, fast = sorted([fit.parameters["T1"], fit.parameters["T2"]], reverse=True)
    ref_slow, ref_fast = sorted(reference[2:4], reverse=True)
    assert fit.fit_percent > 85.0
    for got, want, name in ((k, reference[0], "K"), (a, reference[1], "a"), (slow, ref_slow, "T1"),
                            (fast, ref_fast, "T2")):
        assert got == pytest.approx(want, rel=0.02), name
    true_slow = max(truth[2:4])
    assert abs(k - truth[0]) < 5 * fit.std["K"] + 1e-3 and abs(slow - true_slow) < 5 * max(fit.std["T1"], fit.std["T2"])


@pytest.mark.parametrize("seed", [3])  # seed 1 ends at the iteration limit on the ridge: fit_failure's example
def test_a_fit_on_the_ridge_of_its_structure_is_a_failure_not_a_result(seed):
    """The same plant entered from rest at u = 0 with the PRBS at +-1 from the first sample (a record that begins
    with a step it does not show): the deterministic start lands at K = 0, a = 5e6 and the fit ends there, 'Solve_
    Succeeded' (seed 3) or at its iteration limit (seed 1), with fit 33-35 %, where the record's optimum fits 95 %.
    It was returned as a result; its zero at 2e-7 rad/s, far below anything 60 s resolve, now makes it a failure."""
    from scipy.signal import lsim

    from synth.errors import FitError

    rng = np.random.default_rng(seed)
    t = np.arange(6000) * 0.01
    u = np.repeat(rng.integers(0, 2, 6000 // 20 + 1) * 2.0 - 1.0, 20)[:6000]
    y = lsim(([-1.5, 3.0], np.polymul([1.0, 1.0], [0.25, 1.0])), u, t)[1]
    y = y + 0.05 * np.std(y) * rng.normal(size=t.size)
    with pytest.raises(FitError, match=r"on a ridge .*far below what 60 s resolve") as info:
        identify(record_from_arrays(t, u, y), STRUCTURE, average="none")
    assert "\n" not in str(info.value) and "try another structure" in str(info.value)
