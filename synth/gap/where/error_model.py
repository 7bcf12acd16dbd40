"""A model-error model: the part of the residual that the input explains, with its confidence region.

An ARX model from the input to the residual is fitted by least squares,

``e_k + a_1 e_{k-1} + ... + a_na e_{k-na} = b_0 u_k + ... + b_{nb-1} u_{k-nb+1} + c + v_k``,

(the constant ``c`` absorbs any offset; the ``A`` polynomial both shapes the
error dynamics and whitens coloured noise, which keeps the least-squares
covariance honest). The parameter covariance is ``P = s^2 (Phi^T Phi)^-1``
(normal equations on unit-norm columns)
with ``s^2`` the residual variance. The error model's frequency response
``E(e^{jw dt}) = B/A`` gets its covariance by the Gauss approximation
formula: with ``J = dE/dtheta`` (``z^-j/A`` for ``b_j``, ``-E z^-i/A`` for
``a_i``), the covariance of ``[Re E, Im E]`` is ``[Re J; Im J] P [Re J; Im J]^T``.
At each frequency the 2-D confidence ellipse excludes 0 when
``g^T C^-1 g > chi2_2(level)`` (near 0 and Nyquist, where ``E`` is real and
``C`` singular, only the direction with variance is tested, with one degree
of freedom; ``stat`` is reported on the ``chi2_2`` scale). To keep the chance of any false band near
``1 - level`` over the whole grid, bands are only reported when the error
model as a whole is significant first: a Wald test of ``b = 0``,
``b^T P_bb^-1 b > chi2_nb(level)`` (a gatekeeping procedure). When the
regressors are collinear (a noise-free residual that a lower-order ARX fits
exactly) ``na`` is lowered until they are not.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.distributions import chi2_isf, chi2_ppf, chi2_sf
from synth.errors import DataError

__all__ = ["ErrorModel", "fit_error_model"]


@dataclass(frozen=True)
class ErrorModel:
    """ARX model-error model and its frequency response with confidence.

    Attributes
    ----------
    a, b : numpy.ndarray
        ``A = [1, a_1, ...]`` and ``B = [b_0, ...]`` (powers of ``q^-1``).
    cov : numpy.ndarray
        Covariance of ``[a_1..a_na, b_0..b_nb-1]``.
    dt : float
        Sample interval [s].
    w : numpy.ndarray
        Frequency grid [rad/s].
    response : numpy.ndarray
        ``E(e^{jw dt})`` (output units per input unit).
    stat : numpy.ndarray
        ``g^T C^-1 g`` at each frequency.
    mag_lo, mag_hi : numpy.ndarray
        Outer bounds of ``|E|`` over the confidence ellipse (``|E| -+ sqrt(chi2_2 lambda_max(C))``).
    wald, wald_p : float
        Wald statistic of ``b = 0`` and its p-value.
    level : float

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> u = rng.normal(size=3000)
    >>> m = fit_error_model(u, 0.2 * np.r_[0.0, u[:-1]] + 0.1 * rng.normal(size=3000), 0.01, na=1, nb=3)
    >>> m.significant_overall, round(float(m.b[1]), 2), bool(m.significant.all())
    (True, 0.2, True)
    """

    a: np.ndarray
    b: np.ndarray
    cov: np.ndarray = field(repr=False)
    dt: float
    w: np.ndarray = field(repr=False)
    response: np.ndarray = field(repr=False)
    stat: np.ndarray = field(repr=False)
    mag_lo: np.ndarray = field(repr=False)
    mag_hi: np.ndarray = field(repr=False)
    wald: float
    wald_p: float
    level: float
    nb_asked: int | None = None
    """The taps asked for, where the input pinned down fewer (``b`` holds those kept)."""

    @property
    def significant_overall(self) -> bool:
        """Whether the Wald test rejects ``b = 0`` at ``level``."""
        return self.wald_p < 1.0 - self.level

    @property
    def significant(self) -> np.ndarray:
        """Frequencies where the confidence region excludes 0 (all False unless significant overall)."""
        if not self.significant_overall:
            return np.zeros(self.w.size, bool)
        return self.stat > chi2_ppf(self.level, 2)

    def to_dict(self) -> dict[str, Any]:
        """Plain dict for JSON."""
        mag = np.abs(self.response)
        fewer = self.nb_asked is not None and self.nb_asked > self.b.size
        note = {"nb_asked": self.nb_asked,
                "note": f"the input excites too few frequencies for {self.nb_asked} input taps: {self.b.size} kept; "
                        "between the frequencies it excites, the response is the low-order model's "
                        "interpolation"} if fewer else {}
        return {"structure": "ARX", "na": int(self.a.size - 1), "nb": int(self.b.size), **note, "level": self.level,
                "wald": self.wald, "wald_p": self.wald_p, "significant": self.significant_overall,
                "peak_magnitude": float(mag.max()), "w_peak": float(self.w[np.argmax(mag)]),
                "method": "least-squares ARX input->residual; Gauss approximation of the response covariance; "
                          "pointwise chi2(2) ellipse test, gated by a Wald test of B = 0"}


COLLINEAR = 1e-14
"""Regressors whose scaled Gram matrix has a smallest eigenvalue below this fraction of its largest are collinear."""


def _pinned_taps(lags: list[np.ndarray]) -> int:
    """How many of the leading input ``lags`` (with a constant) are linearly independent to :data:`COLLINEAR`, at
    least 1: one scaled Gram matrix, its leading blocks tested from the largest down."""
    X = np.column_stack([*lags, np.ones(lags[0].size)])
    norms = np.linalg.norm(X, axis=0)
    X = X / np.where(norms == 0.0, 1.0, norms)
    gram = np.einsum("ki,kj->ij", X, X)
    for nb in range(len(lags), 1, -1):
        keep = [*range(nb), len(lags)]
        eig = np.linalg.eigvalsh(gram[np.ix_(keep, keep)])
        if eig[0] >= COLLINEAR * eig[-1]:
            return nb
    return 1


def _response(a: np.ndarray, b: np.ndarray, w: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    zinv = np.exp(-1j * w * dt)
    A = np.polyval(a[::-1], zinv)
    B = np.polyval(b[::-1], zinv)
    E = B / A
    na, nb = a.size - 1, b.size
    J = np.empty((w.size, na + nb), complex)
    for i in range(1, na + 1):
        J[:, i - 1] = -E * zinv**i / A
    for j in range(nb):
        J[:, na + j] = zinv**j / A
    return E, J


def fit_error_model(u: np.ndarray, e: np.ndarray, dt: float, na: int = 4, nb: int = 10, level: float = 0.95,
                    w: np.ndarray | None = None) -> ErrorModel:
    """Fit an ARX error model from input ``u`` to residual ``e`` and evaluate it with confidence.

    Parameters
    ----------
    u, e : numpy.ndarray
        Input and residual.
    dt : float
        Sample interval [s].
    na, nb : int
        Orders of ``A`` (>= 0) and ``B`` (>= 1; taps from lag 0).
    level : float
        Confidence level.
    w : numpy.ndarray, optional
        Frequencies [rad/s]; default 200 log-spaced from ``2 pi/T`` to 0.99 of Nyquist.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(1)
    >>> u = rng.normal(size=3000)
    >>> fit_error_model(u, rng.normal(size=3000), 0.01).significant_overall
    False
    """
    u = np.asarray(u, float)
    e = np.asarray(e, float)
    if u.shape != e.shape:
        raise DataError("input and residual must have the same length", where="residual")
    na, nb = int(na), int(nb)
    if na < 0 or nb < 1:
        raise DataError(f"need na >= 0 and nb >= 1, got na={na}, nb={nb}", where="error model orders")
    if not 0.0 < level < 1.0:
        raise DataError(f"must be in (0, 1), got {level!r}", where="level")
    k0 = max(na, nb - 1)
    n = u.size - k0
    n_par = na + nb + 1
    if n < 3 * n_par:
        raise DataError(f"record too short for an error model of {n_par} parameters ({u.size} samples)",
                        where="residual")
    uc = u - u.mean()
    target = e[k0:]
    nb_asked = nb
    # an input of few frequencies (a sum of sines) pins down as many taps as it has sines times two
    nb = _pinned_taps([uc[k0 - j: u.size - j] for j in range(nb)])
    while True:
        Phi = np.column_stack([-e[k0 - i: u.size - i] for i in range(1, na + 1)]
                              + [uc[k0 - j: u.size - j] for j in range(nb)] + [np.ones(n)])
        scale = np.linalg.norm(Phi, axis=0)
        scale[scale == 0.0] = 1.0
        Phis = Phi / scale
        gram = np.einsum("ki,kj->ij", Phis, Phis)  # small normal equations (no threaded BLAS on a busy machine)
        eig = np.linalg.eigvalsh(gram)
        if eig[0] >= COLLINEAR * eig[-1]:
            break
        if na == 0:
            raise DataError("the input is constant: it does not excite an error model from the input to the residual",
                            where="residual")
        na -= 1  # a noise-free residual that a lower-order ARX fits exactly
    ginv = np.linalg.inv(gram)
    theta = ginv @ np.einsum("ki,k->i", Phis, target) / scale
    resid = target - np.einsum("ki,i->k", Phi, theta)
    n_par = na + nb + 1
    s2 = max(float(np.dot(resid, resid)) / (n - n_par), 1e-300)
    cov = s2 * ginv / np.outer(scale, scale)
    a = np.r_[1.0, theta[:na]]
    b = theta[na: na + nb]
    P = cov[: na + nb, : na + nb]
    Pbb = P[na:, na:]
    wald = float(b @ np.linalg.solve(Pbb, b))
    wald_p = float(chi2_sf(wald, nb))
    if w is None:
        w_lo = 2.0 * np.pi / (u.size * dt)
        w = np.logspace(np.log10(w_lo), np.log10(0.99 * np.pi / dt), 200)
    w = np.asarray(w, float)
    E, J = _response(a, b, w, dt)
    G = np.stack([J.real, J.imag], axis=1)  # (nw, 2, npar)
    C = np.einsum("wip,pq,wjq->wij", G, P, G)
    g = np.stack([E.real, E.imag], axis=1)
    lam, vec = np.linalg.eigh(C)
    proj = np.einsum("wij,wi->wj", vec, g)
    keep = lam > 1e-6 * lam[:, -1:]  # near 0 and Nyquist E is real: Im has no variance, test one dimension
    stat = np.sum(np.where(keep, proj**2 / np.where(keep, lam, 1.0), 0.0), axis=1)
    dof = keep.sum(axis=1)
    stat = chi2_isf(np.maximum(chi2_sf(stat, dof), 1e-300), 2)  # on the chi2(2) scale: one threshold for all w
    radius = np.sqrt(chi2_ppf(level, 2) * lam[:, -1])
    mag = np.abs(E)
    return ErrorModel(a, b, P, float(dt), w, E, stat, np.maximum(mag - radius, 0.0), mag + radius,
                      wald, wald_p, float(level), nb_asked)
