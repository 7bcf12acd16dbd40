"""Where synth.ident.covariance.fit_covariance calls J^T J singular: round-off, not an ill-conditioned but regular
fit (the Cramer-Rao benchmark's case 4 has an eigenvalue ratio of about 1e-10; at the old threshold of 1e-10,
seven of its 20 noise seeds reported every standard error as infinite)."""

from __future__ import annotations

import numpy as np

from synth.ident.covariance import fit_covariance


def _jacobian(eps: float) -> np.ndarray:
    rng = np.random.default_rng(3)
    a, b, c = rng.standard_normal((3, 4000))
    return np.column_stack([a, a + eps * b, c])  # the second column leans on the first


def _eigen_ratio(J: np.ndarray) -> float:
    JtJ = J.T @ J
    d = np.sqrt(np.diag(JtJ))
    ev = np.linalg.eigvalsh(JtJ / np.outer(d, d))
    return float(ev[0] / ev[-1])


def test_an_ill_conditioned_regular_fit_gets_the_inverse() -> None:
    J = _jacobian(1e-5)
    assert 1e-11 < _eigen_ratio(J) < 1e-10  # below the old threshold, far above round-off
    cov, note = fit_covariance(J.T @ J, 0.25)
    assert note == ""
    expected = 0.25 * np.linalg.inv(J.T @ J)
    assert np.all(np.isfinite(cov))
    assert np.allclose(np.sqrt(np.diag(cov)), np.sqrt(np.diag(expected)), rtol=1e-3)


def test_a_singular_direction_stays_infinite() -> None:
    J = _jacobian(0.0)
    assert _eigen_ratio(J) < 1e-15
    cov, note = fit_covariance(J.T @ J, 0.25)
    assert "not identifiable" in note
    assert np.isinf(cov[0, 0]) and np.isinf(cov[1, 1]) and np.isfinite(cov[2, 2])
