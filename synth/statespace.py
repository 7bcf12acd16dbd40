"""Continuous state space of a transfer function and its exact or approximate discretizations: the few
pieces of :mod:`scipy.signal` that simulations and step responses need, on :mod:`scipy.linalg` alone
(importing :mod:`scipy.signal` costs about 0.4 s, paid by every command that simulates).

The forms follow the usual conventions (as ``scipy.signal.tf2ss`` and ``cont2discrete``): the controllable
canonical form, the zero-order hold from one matrix exponential of ``[[A, B], [0, 0]] h``, and the
generalized bilinear transform (``alpha`` 0: forward Euler, 1/2: Tustin, 1: backward Euler).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm
from scipy.linalg.lapack import dtbtrs

__all__ = ["POWERS_UP_TO", "STEP_BLOCK", "generalized_bilinear", "lfilter", "ss_to_tf", "step_from_rest", "tf_to_ss", "zoh"]


STEP_BLOCK = 64
"""Fewest samples of :func:`step_from_rest` computed by one matrix product from the state at the block's start
(a longer response takes longer blocks: about the square root of its length)."""

POWERS_UP_TO = 8
"""Most states for which :func:`step_from_rest` forms the powers of its block step (``n^3`` work per block, cheaper
than a Python step per block for a controller and plant of a few states; a delay line of a hundred states is
stepped block by block)."""


def step_from_rest(F: np.ndarray, g: np.ndarray, h: np.ndarray, d: float | np.ndarray, size: int,
                   z0: np.ndarray | None = None) -> np.ndarray:
    """Output ``y[k] = h z[k] + d`` of ``z[k+1] = F z[k] + g`` from ``z[0] = 0``, for ``k < size`` (a discrete
    system's response to a held unit step); from ``z[0] = z0`` when given (the step held on from that state).
    Stacked systems (``F`` of shape ``(b, n, n)``, ``g``, ``h`` and ``z0`` ``(b, n)``, ``d`` ``(b,)``) give
    ``(b, size)``, all at once.

    The samples come a block of ``m`` at a time: ``z[b + j] = F^j z[b] + (F^0 + ... + F^(j-1)) g``, so
    ``y[b + j] = (h F^j) z[b] + h (F^0 + ... + F^(j-1)) g + d``. The rows ``h F^j`` and the sums come by
    doubling (``log2 m`` matrix products), the block starts by one step of ``F^m`` each (up to
    :data:`POWERS_UP_TO` states, from the powers of ``F^m``, doubling again, and a cumulative sum: no Python step
    at all), and every sample by one matrix product of the block starts and the rows: about ``2 sqrt(size)``
    small products instead of a Python step per sample (the same values as the recursion to rounding). ``m`` is
    the power of two of at least :data:`STEP_BLOCK` nearest above ``sqrt(size)``.

    Examples
    --------
    >>> step_from_rest(np.array([[0.5]]), np.array([1.0]), np.array([1.0]), 0.0, 4).tolist()  # 0, 1, 1.5, 1.75
    [0.0, 1.0, 1.5, 1.75]
    >>> step_from_rest(np.array([[0.5]]), np.array([1.0]), np.array([1.0]), 0.0, 3, z0=np.array([1.5])).tolist()
    [1.5, 1.75, 1.875]
    >>> step_from_rest(np.array([[[0.5]], [[0.0]]]), np.ones((2, 1)), np.ones((2, 1)), np.zeros(2), 3).tolist()
    [[0.0, 1.0, 1.5], [0.0, 1.0, 1.0]]
    """
    single = np.ndim(F) == 2
    F = np.asarray(F, float).reshape(-1, *np.shape(F)[-2:])
    b, n = F.shape[0], F.shape[-1]
    m = max(STEP_BLOCK, 1 << int(np.ceil(np.log2(max(np.sqrt(size), 1.0)))))
    g = np.reshape(np.asarray(g, float), (b, n, 1))
    rows = np.reshape(np.asarray(h, float), (b, 1, n))  # h F^j, j < rows.shape[1]
    power, forced = F, g  # F^j and (F^0 + ... + F^(j-1)) g for j = rows.shape[1]
    while rows.shape[1] < m:
        rows = np.concatenate([rows, rows @ power], axis=1)
        forced = forced + power @ forced
        power = power @ power
    # h (F^0 + ... + F^(j-1)) g + d
    offsets = np.reshape(d, (b, 1)) + np.concatenate([np.zeros((b, 1)), np.cumsum((rows[:, :-1] @ g)[..., 0], axis=1)],
                                                     axis=1)
    blocks = -(-size // m)
    starts = np.zeros((b, blocks, n))  # z at each block's start
    start = None if z0 is None else np.reshape(np.asarray(z0, float), (b, n))
    if n <= POWERS_UP_TO:  # P^k z0 + (P^0 + ... + P^(k-1)) forced with P = F^m, the powers P^k by doubling
        powers, step = np.broadcast_to(np.eye(n), (b, 1, n, n)), power
        while powers.shape[1] < blocks:
            powers = np.concatenate([powers, powers @ step[:, None]], axis=1)
            step = step @ step
        powers = powers[:, :blocks]
        starts[:, 1:] = np.cumsum((powers[:, :-1] @ forced[:, None])[..., 0], axis=1)
        if start is not None:
            starts += (powers @ start[:, None, :, None])[..., 0]
    else:
        if start is not None:
            starts[:, 0] = start
        for k in range(1, blocks):
            starts[:, k] = (power @ starts[:, k - 1, :, None] + forced)[..., 0]
    y = np.empty((b, blocks * m))
    for i in range(b):  # one BLAS product per system (stacked products of such thin matrices are far slower)
        y[i] = (starts[i] @ rows[i].T + offsets[i]).ravel()
    return y[0, :size] if single else y[:, :size]


def tf_to_ss(num: np.ndarray, den: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """State space ``(A, B, C, D)`` of a proper SISO transfer function (controllable canonical form); ``B``
    and ``C`` are vectors.

    Examples
    --------
    >>> A, B, C, D = tf_to_ss(np.array([2.0]), np.array([1.0, 3.0]))
    >>> A.tolist(), B.tolist(), C.tolist(), D
    ([[-3.0]], [1.0], [2.0], 0.0)
    >>> A, B, C, D = tf_to_ss(np.array([1.0, 2.0]), np.array([1.0, 3.0]))  # (s+2)/(s+3) = 1 - 1/(s+3)
    >>> C.tolist(), D
    ([-1.0], 1.0)
    """
    num = np.atleast_1d(np.asarray(num, float))
    den = np.atleast_1d(np.asarray(den, float))
    nz = np.flatnonzero(den != 0.0)
    if nz.size == 0:
        raise ValueError("the denominator is the zero polynomial")
    den = den[nz[0]:]
    nzn = np.flatnonzero(num != 0.0)
    num = num[nzn[0]:] if nzn.size else np.array([0.0])
    if num.size > den.size:
        raise ValueError("improper transfer function: numerator degree above the denominator's")
    num, den = num / den[0], den / den[0]
    if den.size == 1:
        return np.zeros((0, 0)), np.zeros(0), np.zeros(0), float(num[-1])
    n = den.size - 1
    num = np.concatenate([np.zeros(den.size - num.size), num])
    D = float(num[0])
    rest = num[1:] - D * den[1:]
    A = np.zeros((n, n))
    A[0, :] = -den[1:]
    A[np.arange(1, n), np.arange(n - 1)] = 1.0
    B = np.zeros(n)
    B[0] = 1.0
    return A, B, rest.copy(), D


def zoh(A: np.ndarray, B: np.ndarray, h: float | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(e^{A h}, int_0^h e^{A s} ds B)`` for ``B`` with one column per input. Stacked systems and steps
    (``A`` of shape ``(..., n, n)``, ``B`` ``(..., n, k)``, ``h`` broadcasting with ``A``'s leading axes) give
    both stacked, from one matrix exponential call.

    Examples
    --------
    >>> Ad, Gd = zoh(np.array([[-1.0]]), np.array([[1.0]]), np.log(2.0))
    >>> float(Ad[0, 0]), round(float(Gd[0, 0]), 12)
    (0.5, 0.5)
    >>> Ad, Gd = zoh(np.array([[[-1.0]]]), np.array([[[1.0]]]), np.log([[1.0, 2.0, 4.0]]))  # one system, 3 steps
    >>> Ad.shape, Gd[0, :, 0, 0].round(12).tolist()
    ((1, 3, 1, 1), [0.0, 0.5, 0.75])
    """
    A = np.asarray(A, float)
    n = A.shape[-1]
    B = np.asarray(B, float).reshape(*A.shape[:-2], n, -1)
    h = np.asarray(h, float)
    k = B.shape[-1]
    lead = np.broadcast_shapes(A.shape[:-2], h.shape)
    if n == 0:
        return np.zeros((*lead, 0, 0)), np.zeros((*lead, 0, k))
    if h.ndim == 0 and A.ndim == 2 and h == 0.0:
        return np.eye(n), np.zeros_like(B)
    M = np.zeros((*lead, n + k, n + k))
    M[..., :n, :n] = A * h[..., None, None]
    M[..., :n, n:] = B * h[..., None, None]
    E = expm(M)
    return E[..., :n, :n], E[..., :n, n:]


def generalized_bilinear(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: float, h: float, alpha: float,
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Discrete ``(Ad, Bd, Cd, Dd)`` of ``(A, B, C, D)`` (``B``, ``C`` vectors) sampled every ``h`` s by the
    generalized bilinear transform ``s -> (z - 1) / (h (alpha z + 1 - alpha))``.

    Examples
    --------
    Backward Euler of ``1/s`` (``alpha = 1``): ``x_k = x_{k-1} + h u_k``, ``Dd = h``:

    >>> Ad, Bd, Cd, Dd = generalized_bilinear(np.zeros((1, 1)), np.ones(1), np.ones(1), 0.0, 0.1, 1.0)
    >>> float(Ad[0, 0]), float(Bd[0]), float(Cd[0]), round(Dd, 12)
    (1.0, 0.1, 1.0, 0.1)
    """
    n = A.shape[0]
    eye = np.eye(n)
    lhs = eye - alpha * h * A
    Ad = np.linalg.solve(lhs, eye + (1.0 - alpha) * h * A)
    Bd = np.linalg.solve(lhs, h * np.asarray(B, float))
    Cd = np.linalg.solve(lhs.T, np.asarray(C, float))
    Dd = float(D + alpha * (np.asarray(C, float) @ Bd))
    return Ad, Bd, Cd, Dd


def ss_to_tf(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator (highest power first, monic denominator) of ``C (zI - A)^-1 B + D`` for a
    SISO state space with ``B`` and ``C`` vectors: ``den = det(zI - A)``, ``num = det(zI - A + B C) - den +
    D den`` (the identity ``scipy.signal.ss2tf`` uses).

    Examples
    --------
    >>> num, den = ss_to_tf(np.array([[0.5]]), np.array([1.0]), np.array([2.0]))
    >>> num.tolist(), den.tolist()  # 2 / (z - 0.5)
    ([0.0, 2.0], [1.0, -0.5])
    """
    A = np.atleast_2d(np.asarray(A, float))
    den = np.poly(A)
    num = np.poly(A - np.outer(np.asarray(B, float), np.asarray(C, float))) - den + D * den
    return num, den


def lfilter(b: np.ndarray, a: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Output of the discrete filter ``b(z^-1) / a(z^-1)`` for the input ``x`` from rest (coefficients in
    powers of ``z^-1``, as ``scipy.signal.lfilter`` with no initial conditions): the numerator by convolution,
    then the recursion ``sum_k a_k y[n-k] = (b * x)[n]`` as the forward substitution of a lower-triangular
    banded system (LAPACK ``dtbtrs``).

    Examples
    --------
    >>> lfilter(np.array([1.0]), np.array([1.0, -0.5]), np.array([1.0, 0.0, 0.0, 0.0])).tolist()
    [1.0, 0.5, 0.25, 0.125]
    """
    b = np.atleast_1d(np.asarray(b, float))
    a = np.atleast_1d(np.asarray(a, float))
    x = np.asarray(x, float)
    if a[0] == 0.0:
        raise ValueError("the filter's leading denominator coefficient is zero")
    b, a = b / a[0], a / a[0]
    rhs = np.convolve(x, b)[:x.size]
    if a.size == 1 or x.size == 0:
        return rhs
    band = np.repeat(a[:, None], x.size, axis=1)  # band storage of the lower-triangular Toeplitz matrix
    y, info = dtbtrs(band, rhs[:, None], uplo="L")
    if info != 0:
        raise ValueError(f"LAPACK dtbtrs failed (info {info})")
    return y[:, 0]
