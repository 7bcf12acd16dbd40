"""The screen's least squares (Gram matrix, corrected semi-normal equations) against numpy's SVD solver."""

import numpy as np
import pytest

from synth.gap.attribution.tall_lsq import TallLeastSquares


@pytest.mark.parametrize("seed", range(8))
def test_matches_lstsq_on_random_designs_up_to_condition_1e6(seed):
    rng = np.random.default_rng(seed)
    n, k = int(rng.integers(200, 5000)), int(rng.integers(2, 12))
    U, _ = np.linalg.qr(rng.standard_normal((n, k)))
    V, _ = np.linalg.qr(rng.standard_normal((k, k)))
    sv = np.geomspace(1.0, 10.0 ** -rng.uniform(0, 6), k)  # condition up to 1e6
    X = (U * sv) @ V.T * rng.uniform(1e-3, 1e3, k)  # and badly scaled columns
    y = X @ rng.standard_normal(k) + rng.uniform(1e-3, 1.0) * rng.standard_normal(n)
    ls = TallLeastSquares(X, y)
    for cols in (None, sorted(rng.choice(k, size=max(1, k - 2), replace=False).tolist())):
        idx = np.arange(k) if cols is None else np.asarray(cols)
        sol, *_ = np.linalg.lstsq(X[:, idx], y, rcond=None)
        r = y - X[:, idx] @ sol
        coef, ssr = ls.fit(cols)
        assert ssr == pytest.approx(float(r @ r), rel=1e-9)
        assert np.allclose(X @ coef, X[:, idx] @ sol, rtol=0, atol=1e-7 * np.max(np.abs(y)))
        assert np.all(coef[np.setdiff1d(np.arange(k), idx)] == 0.0)


def test_rank_deficient_falls_back_and_non_finite_is_infinite():
    rng = np.random.default_rng(1)
    a = rng.standard_normal(500)
    X = np.column_stack([a, 2.0 * a, rng.standard_normal(500)])  # exactly collinear
    y = X[:, 0] + X[:, 2]
    coef, ssr = TallLeastSquares(X, y).fit()
    assert ssr < 1e-20 * float(y @ y) + 1e-20 and np.allclose(X @ coef, y)
    X[3, 1] = np.inf
    ls = TallLeastSquares(X, y)
    assert not ls.finite and ls.fit()[1] == np.inf
