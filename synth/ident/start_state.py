"""Whether a whole-record fit's record starts at rest.

A whole-record fit assumes the plant at rest at the first fitted sample (:mod:`synth.ident.sim_error_problem`). A
record cut out of a running experiment starts with the plant in some unknown state, whose free response (a sum of
the model's own modes) the fit then bends its parameters to soften: on short records with slow modes by tens of
standard deviations, with nothing in the residuals large enough to see by eye.

The test is the score (Lagrange-multiplier) test of the fit against the same model with its initial state free: the
residual regressed on the parameters' sensitivities together with the model's free responses from the first fitted
sample (one Gauss-Newton step of the larger problem). The drop in the residual's energy, over the noise variance
left by that regression, is a chi-square variable with as many degrees of freedom as the free responses add where the
plant did start at rest. The same regression gives the parameters' shift: a start state *matters* where the drop is
significant at :data:`ALPHA` and the shift of some parameter exceeds :data:`MATERIAL` of its standard deviation, so
that residuals that are merely not white (coloured noise, a small unmodelled lag) do not on their own set it off.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from synth.plant import Plant

__all__ = ["ALPHA", "ANCHORS", "MATERIAL", "StartState", "free_columns", "free_response_basis", "free_start_gram",
           "start_state_test"]

ALPHA = 1e-3
"""False-alarm probability of the drop in residual energy on a record that starts at rest (white residuals)."""

ANCHORS = 8
"""Later samples at which the test's drop is measured where no state starts (:attr:`StartState.inflation`)."""

MATERIAL = 1.0
"""A start state matters where it shifts some parameter (or the delay) by more than this many standard deviations."""

@dataclass(frozen=True)
class StartState:
    """The start-state test of one fit.

    Attributes
    ----------
    statistic : float
        The drop in residual energy when the free responses join the regression, over the noise variance left.
    threshold : float
        The chi-square quantile at :data:`ALPHA` with ``dof`` degrees of freedom, times ``inflation``.
    dof : int
        Directions the free responses add to the parameters' sensitivities.
    inflation : float
        The median of the same drop at ``anchors`` later samples over its chi-square median (at least 1; 1 with
        fewer than 4 anchors): how much residuals that are not white raise it where no state starts.
    anchors : int
        Later samples the inflation rests on.
    shift : float
        The largest parameter shift the start state accounts for, in the parameter's standard deviations.
    shifted : str
        The parameter of ``shift``.
    window : float
        Where the estimated free response has less energy left than one noise variance, plus the delay [s].
    first : float
        Time of the first fitted sample from the record's start [s].
    left_std : float
        The residuals' standard deviation with the free responses in the regression: where a start state is what the
        fit missed, about the record's noise; a structure that cannot explain the record leaves far more
        (:mod:`synth.ident.misfit`).
    """

    statistic: float
    threshold: float
    dof: int
    inflation: float
    anchors: int
    shift: float
    shifted: str
    window: float
    first: float
    left_std: float = 0.0

    @property
    def matters(self) -> bool:
        """The start state is not at rest (beyond :data:`ALPHA`) and biases a parameter (beyond :data:`MATERIAL`)."""
        return self.statistic > self.threshold and self.shift > MATERIAL

    @property
    def masked(self) -> bool:
        """It would matter but for the inflation: significant against the chi-square quantile alone, shifting a
        parameter beyond :data:`MATERIAL`, yet below the inflated threshold. A fit that a start state bent into
        another basin leaves residuals far from white everywhere, which inflate the threshold: such a start is
        judged by a refit without it (:mod:`synth.ident.unknown_start`)."""
        return not self.matters and self.statistic * self.inflation > self.threshold and self.shift > MATERIAL

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields and the verdicts."""
        return {**asdict(self), "matters": self.matters, "masked": self.masked}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> StartState:
        """The inverse of :meth:`to_dict`."""
        return cls(**{k: v for k, v in data.items() if k not in ("matters", "masked")})


def free_response_basis(plant: Plant, dt: float, length: int) -> np.ndarray:
    """Orthonormal columns spanning every free response of ``plant`` (delay left out) sampled every ``dt`` over
    ``length`` samples: the homogeneous solutions of the sampled denominator, whose roots are ``exp(p dt)``.

    Examples
    --------
    >>> Q = free_response_basis(Plant.from_string("1/((s+1)*(s+10))"), 0.01, 500)
    >>> Q.shape, bool(np.allclose(Q.T @ Q, np.eye(2)))
    ((500, 2), True)
    >>> x = np.exp(-np.arange(500) * 0.01)  # the slow mode lies in the space
    >>> round(float(np.linalg.norm(Q @ (Q.T @ x) - x)), 9)
    0.0
    """
    den = np.trim_zeros(np.asarray(plant.den, float), "f")
    order = den.size - 1
    if order < 1 or length < 1:
        return np.zeros((max(length, 0), 0))
    from scipy.signal import lfilter  # here, not at the top: 0.34 s that the design report's import path would pay

    a = np.real(np.poly(np.exp(np.roots(den) * dt)))
    with np.errstate(over="ignore", invalid="ignore"):
        columns = np.column_stack([lfilter([1.0], a, np.zeros(length), zi=np.eye(order)[i])[0] for i in range(order)])
    if not np.all(np.isfinite(columns)):  # a model growing past every bound over the record (an unstable fit on its
        return np.zeros((length, 0))      # way to failing): no free response to test it against, not an SVD error
    u, s, _ = np.linalg.svd(columns, full_matrices=False)
    keep = s > 1e-9 * s[0] if s.size and s[0] > 0 else np.zeros(s.size, dtype=bool)
    return u[:, keep]


def free_columns(den: np.ndarray, dt: float, rows: np.ndarray, n: int) -> tuple[np.ndarray, int, np.ndarray]:
    """The free responses of a model with denominator ``den`` from the first of the fitted samples ``rows`` (among
    ``n``): their basis over the samples until they have decayed to 1e-9 of their start, how many fitted samples they
    reach, and their values there (zero beyond). What :func:`free_start_gram` and :func:`start_state_test` share.

    Examples
    --------
    >>> Q, head, phi = free_columns(np.array([1.0, 1.0]), 0.01, np.arange(50, 5000), 5000)   # 1/(s+1) from 0.5 s
    >>> Q.shape[1], head, phi.shape                                            # 20.7 s to decay, 2072 samples
    (1, 2073, (2073, 1))
    """
    model = Plant([1.0], den)
    k0 = int(rows[0])
    Q = free_response_basis(model, dt, _support(model, dt, n - k0))
    head = int(np.searchsorted(rows - k0, Q.shape[0]))
    return Q, head, Q[rows[:head] - k0]


def free_start_gram(jacobian: np.ndarray, jtj: np.ndarray, columns: tuple[np.ndarray, int, np.ndarray]) -> np.ndarray:
    """``J^T J`` with the free responses from the first fitted sample (:func:`free_columns`) joined as nuisance
    columns (after ``J``'s): the Gauss-Newton information of a fit whose start state is unknown. Its inverse's leading
    block is the parameters' covariance with that state free (never smaller than ``J^T J``'s inverse).

    Examples
    --------
    >>> t = np.arange(400) * 0.01
    >>> J = np.column_stack([1 - np.exp(-t), np.ones(t.size)])   # a gain's and an offset's sensitivities
    >>> gram = free_start_gram(J, J.T @ J, free_columns(np.array([1.0, 1.0]), 0.01, np.arange(t.size), t.size))
    >>> gram.shape, bool(np.linalg.inv(gram)[0, 0] > np.linalg.inv(J.T @ J)[0, 0])
    ((3, 3), True)
    """
    _, head, phi = columns
    cross = jacobian[:head].T @ phi
    return np.block([[jtj, cross], [cross.T, phi.T @ phi]])


def _support(model: Plant, dt: float, available: int) -> int:
    """Samples until the slowest mode's free response has decayed to 1e-9 of its start (``available`` for a mode
    that does not decay)."""
    den = np.trim_zeros(np.asarray(model.den, float), "f")
    roots = np.roots(den) if den.size > 1 else np.array([])
    slowest = float(np.max(roots.real)) if roots.size else -np.inf
    if slowest >= 0.0:
        return available
    return int(min(available, max(2, np.ceil(np.log(1e9) / -slowest / dt))))


def _least_squares(gram: np.ndarray, moment: np.ndarray, energy: float) -> tuple[np.ndarray, int, float]:
    """Least squares from its normal equations (columns scaled to unit norm, directions below 1e-12 of the largest
    eigenvalue left out): the coefficients, the rank and the residual's energy."""
    diag = np.sqrt(np.clip(np.diag(gram), 0.0, None))
    d = np.where(diag > 0, 1.0 / np.where(diag > 0, diag, 1.0), 0.0)
    values, vectors = np.linalg.eigh(gram * d[:, None] * d[None, :])
    keep = values > 1e-12 * max(float(values[-1]), 0.0) if values.size else values > 0
    coef = d * (vectors[:, keep] @ ((vectors[:, keep].T @ (d * moment)) / values[keep]))
    return coef, int(np.count_nonzero(keep)), max(0.0, energy - float(moment @ coef))


def start_state_test(jacobian: np.ndarray, jtj: np.ndarray, residual: np.ndarray, rows: np.ndarray,
                     columns: tuple[np.ndarray, int, np.ndarray], dt: float, delay: float, std: np.ndarray,
                     values: np.ndarray, names: list[str]) -> StartState:
    """Test a whole-record fit (not periodic) for a start state that is not at rest.

    Parameters
    ----------
    jacobian, jtj : numpy.ndarray
        The model output's sensitivities to ``names`` on the fitted samples (rows), in the parameters' units, and
        ``J^T J``.
    residual : numpy.ndarray
        Measured minus model output on the fitted samples.
    rows : numpy.ndarray
        Indices of the fitted samples among the record's (increasing; the first is where the state is free).
    columns : tuple
        The fitted model's free responses from there (:func:`free_columns`, the sensor's poles included).
    dt, delay : float
        Sample time and the fitted delay [s].
    std, values : numpy.ndarray
        The parameters' standard deviations and values, in the order of ``names`` (the last, the output offset, is
        not judged). A shift counts in standard deviations of at least 1e-9 of the value: a noise-free record's are
        at the precision of the arithmetic, and so is what it shifts.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.timefit import fit_structure
    >>> from scipy import signal
    >>> t = np.arange(0.0, 30.0, 0.01); rng = np.random.default_rng(1)
    >>> u = np.repeat(rng.normal(size=300), 10)             # a random staircase
    >>> sys = signal.StateSpace([[-0.5]], [[1.0]], [[1.0]], [[0.0]])
    >>> y = signal.lsim(sys, u, t, X0=[4.0], interp=False)[1] + 0.01 * rng.normal(size=t.size)  # from x = 4, not from rest
    >>> test = StartState.from_dict(fit_structure(record_from_arrays(t, u, y), "k/(s+p)").solver["start_state"])
    >>> test.matters, bool(test.statistic > 10 * test.threshold), test.shifted, round(test.shift)
    (True, True, 'p', 32)
    """
    from scipy.stats import chi2  # here, not at the top: the design report imports this module, never calls it

    k0 = int(rows[0])
    Q, head, phi = columns  # zero beyond Q's samples (to 1e-9 of their start)
    quiet = StartState(0.0, float("inf"), 0, 1.0, 0, 0.0, "", 0.0, k0 * dt)
    if Q.shape[1] == 0 or not (np.all(np.isfinite(jacobian)) and np.all(np.isfinite(residual))):
        return quiet
    q = jacobian.shape[1]
    jtr, energy = jacobian.T @ residual, float(residual @ residual)
    alone, rank_alone, ssr_alone = _least_squares(jtj, jtr, energy)
    beta, dof, noise, statistic = _score(jacobian, residual, jtj, jtr, energy, phi, 0, rank_alone, ssr_alone)
    if dof < 1 or not noise > 0:
        return quiet
    # the same drop where nothing starts: residuals that are not white (a model error, coloured noise) raise it
    # there as much as at the start, a start state at the start only. Measured on the residual with the start's
    # estimated free response taken out: a slowly decaying one would reach the later samples and raise it there too
    rest = residual - jacobian @ beta[:q]
    rest[:head] -= phi @ beta[q:]
    rest_jtr, rest_energy = jacobian.T @ rest, float(rest @ rest)
    _, _, rest_ssr = _least_squares(jtj, rest_jtr, rest_energy)
    span = min(Q.shape[0], residual.size // 8)
    first_spot = max(span, residual.size // 4)
    spots = np.unique(np.linspace(first_spot, residual.size - span, ANCHORS).astype(int)) \
        if residual.size - span > first_spot else np.array([], dtype=int)
    later = [_score(jacobian, rest, jtj, rest_jtr, rest_energy, Q[:span], int(at), rank_alone, rest_ssr)
             for at in spots]
    later = [(d, stat) for _, d, _, stat in later if d >= 1]
    inflation = max(1.0, float(np.median([stat / chi2.median(d) for d, stat in later]))) if len(later) >= 4 else 1.0
    judged = np.maximum(np.asarray(std[:-1], float), 1e-9 * np.abs(np.asarray(values[:-1], float)))
    moved = np.abs(beta[:q - 1] - alone[:q - 1])
    with np.errstate(divide="ignore", invalid="ignore"):  # a parameter without a finite std: any move is material
        shifts = np.where(np.isfinite(judged), np.where(judged > 0, moved / judged, 0.0),
                          np.where(moved > 0, np.inf, 0.0))
    worst = int(np.argmax(shifts)) if shifts.size else 0
    free = Q @ beta[q:]
    tail = np.cumsum((free**2)[::-1])[::-1]  # the free response's energy from each sample on
    above = np.flatnonzero(tail > noise)
    window = (float(above[-1] + 1) * dt if above.size else 0.0) + delay
    return StartState(statistic, float(chi2.isf(ALPHA, dof)) * inflation, dof, inflation, len(later),
                      float(shifts[worst]) if shifts.size else 0.0, names[worst] if shifts.size else "", window, k0 * dt,
                      float(np.sqrt(noise)))


def _score(jacobian: np.ndarray, residual: np.ndarray, jtj: np.ndarray, jtr: np.ndarray, energy: float,
           basis: np.ndarray, at: int, rank_alone: int, ssr_alone: float) -> tuple[np.ndarray, int, float, float]:
    """The regression of ``residual`` on the sensitivities with ``basis`` joining from row ``at``: the coefficients,
    the directions it adds, the noise variance left and the drop in residual energy over it."""
    basis = basis[:residual.size - at]
    rows = slice(at, at + basis.shape[0])
    cross = jacobian[rows].T @ basis
    gram = np.block([[jtj, cross], [cross.T, basis.T @ basis]])
    beta, rank_both, ssr_both = _least_squares(gram, np.r_[jtr, basis.T @ residual[rows]], energy)
    noise = ssr_both / max(1, residual.size - rank_both)
    return beta, rank_both - rank_alone, noise, (ssr_alone - ssr_both) / noise if noise > 0 else 0.0
