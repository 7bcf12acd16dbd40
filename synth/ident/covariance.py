"""The covariance of a time-domain fit's parameters, including the case a sampled record leaves singular.

The usual estimate is ``s^2 (J^T J)^-1`` with ``J`` the model output's Jacobian in the parameters. A model
with direct feedthrough (biproper) and a fitted delay breaks it: on sampled data the feedthrough's jump is
piecewise constant in the delay (the input is held), so the delay enters the Jacobian only through the
strictly proper part, whose step response after the jump is spanned by the same functions as the gain's and
the zero's columns. ``J^T J`` is then singular (an eigenvalue 1e-16 of its largest) and its inverse is noise:
the reported standard deviations came out as exactly 0 or as 10^4 on fits whose estimates scattered 1 %.

What the record does pin is the delay to the sample its jump falls in; within the sample the fit can move
along the null direction freely. :func:`fit_covariance` then gives the delay the spread of a uniform
position within one sample (``dt / sqrt(12)``), the other parameters their covariance with the delay fixed
plus the delay's spread carried along the null direction.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SINGULAR", "fit_covariance"]

SINGULAR = 1e-13
"""Smallest eigenvalue of the column-scaled ``J^T J`` (relative to its largest) still inverted as it is. A truly
singular direction (the biproper delay within a sample) shows as round-off, 1e-18 to 3e-16 (8 noise seeds of
tests/test_ident_biproper_delay.py); an ill-conditioned but regular fit lies well above: two zeros and three poles
behind a sensor at 0.03 % noise (the Cramer-Rao benchmark's case 4) gives 8e-11 to 1.1e-10, and at the earlier
threshold of 1e-10 seven of its 20 seeds reported every standard error as infinite, the estimates within 1.5
bounds of the truth. Inverted at 1e-10, ``J^T J`` keeps about six significant digits."""


def fit_covariance(JtJ: np.ndarray, s2: float, delay_column: int | None = None,
                   dt: float = 0.0) -> tuple[np.ndarray, str]:
    """``(covariance, note)`` of least-squares estimates with ``J^T J`` of the output Jacobian ``J`` (samples x
    parameters) and residual variance ``s2``. ``delay_column``: the column of a fitted delay, ``dt`` the sampling interval:
    when ``J^T J`` is singular along a direction the delay is part of, the delay's variance is ``dt^2 / 12`` and
    the note says why (see the module's text); a singular direction without the delay keeps infinite variances
    along it. ``note`` is empty when the usual inverse applies.

    Examples
    --------
    An offset and a delay that move the output alike: the delay's spread is a sample's, and the offset trades
    off with it one for one (no noise here, so nothing else):

    >>> J = np.ones((10, 2))
    >>> cov, note = fit_covariance(J.T @ J, 0.0, delay_column=1, dt=0.01)
    >>> (cov / (0.01**2 / 12)).round(6).tolist(), note[:27]
    ([[1.0, -1.0], [-1.0, 1.0]], 'the delay within one sample')
    """
    JtJ = np.asarray(JtJ, float)
    with np.errstate(all="ignore"):
        scale = np.sqrt(np.diag(JtJ))
        scale = np.where(scale > 0, scale, 1.0)
        scaled = JtJ / np.outer(scale, scale)
        if not np.all(np.isfinite(scaled)):
            return np.full(JtJ.shape, np.nan), "the Jacobian is not finite"
        eigenvalues, vectors = np.linalg.eigh(scaled)
    top = float(eigenvalues[-1])
    null = eigenvalues <= SINGULAR * top
    if not np.any(null):
        return s2 * np.linalg.inv(scaled) / np.outer(scale, scale), ""
    d = delay_column
    if d is not None and dt > 0 and np.sum(null) == 1:
        v = vectors[:, 0] / scale  # the null direction in the parameters' own units
        if abs(v[d]) * scale[d] > 0.1:  # the delay takes part in it
            keep = [i for i in range(JtJ.shape[0]) if i != d]
            fixed, note = fit_covariance(JtJ[np.ix_(keep, keep)], s2)
            if not note:
                slope = np.delete(v, d) / v[d]  # the other parameters per unit of delay along the null direction
                var = dt**2 / 12.0
                cov = np.empty(JtJ.shape)
                cov[np.ix_(keep, keep)] = fixed + np.outer(slope, slope) * var
                cov[keep, d] = cov[d, keep] = slope * var
                cov[d, d] = var
                return cov, ("the delay within one sample is not identifiable from this record (the model's "
                             "direct feedthrough jumps with the held input): its spread is a uniform position "
                             "within the sample, carried to the parameters it trades off with")
    cov = s2 * np.linalg.pinv(scaled) / np.outer(scale, scale)
    inf = np.any(np.abs(vectors[:, null]) > 1e-6, axis=1)
    cov[inf, :] = cov[:, inf] = np.inf
    return cov, "the parameters marked by infinite variances are not identifiable from this record (J^T J singular)"
