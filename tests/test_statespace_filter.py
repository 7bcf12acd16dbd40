"""``synth.statespace.lfilter`` and ``ss_to_tf`` replace scipy.signal's (whose import costs 0.5 s) in the plant
simulation of identification and the gap diagnosis: they must agree with scipy's on random filters, stable,
marginal (a pole at 1) and unstable, of orders 0-5."""

import numpy as np
from scipy import signal

from synth.statespace import lfilter, ss_to_tf


def test_lfilter_is_scipys_lfilter():
    rng = np.random.default_rng(5)
    for trial in range(40):
        order = int(rng.integers(0, 6))
        poles = rng.uniform(0.2, 0.99, size=order) * np.exp(1j * rng.uniform(0, np.pi, size=order))
        if trial % 5 == 0 and order:
            poles[0] = 1.0  # an integrator
        a = np.real(np.poly(np.r_[poles[: (order + 1) // 2], np.conj(poles[: order // 2])]))
        a = a * rng.uniform(0.5, 2.0)  # a leading coefficient other than 1
        b = rng.normal(size=int(rng.integers(1, order + 2)))
        x = rng.normal(size=int(rng.integers(1, 3000)))
        y = lfilter(b, a, x)
        ref = signal.lfilter(b, a, x)
        np.testing.assert_allclose(y, ref, rtol=1e-9, atol=1e-10 * max(1.0, float(np.max(np.abs(ref)))))


def test_ss_to_tf_is_scipys_ss2tf():
    rng = np.random.default_rng(6)
    for _ in range(30):
        n = int(rng.integers(1, 6))
        A, B, C, D = rng.normal(size=(n, n)), rng.normal(size=n), rng.normal(size=n), float(rng.normal())
        num, den = ss_to_tf(A, B, C, D)
        ref_num, ref_den = signal.ss2tf(A, B[:, None], C[None, :], np.array([[D]]))
        np.testing.assert_allclose(den, ref_den, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(num, ref_num[0], rtol=1e-9, atol=1e-10)
