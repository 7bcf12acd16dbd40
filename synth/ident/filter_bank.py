"""The state-variable filter bank of SRIVC: ``s^k / den(s)`` of held samples, exactly (ZOH), for every ``k`` at once.

One exact zero-order-hold discretization of the companion form of ``1/den`` (a fractional delay included) gives the
transfer functions to all its states, whose outputs are ``s^k/den x``; each is one ``lfilter`` call. The
discretization and its transfer functions are kept per denominator: an SRIVC step filters four signals through the
same ``1/den``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["filter_bank"]


def _expm_np(M: np.ndarray) -> np.ndarray:
    """Matrix exponential of a small matrix (Taylor series, scaling and squaring).

    Used instead of :func:`scipy.linalg.expm` on the hot paths: for 2x2 to 6x6
    matrices scipy's BLAS calls can cost milliseconds each when the machine is
    busy (thread start-up), this costs microseconds.
    """
    norm = float(np.max(np.sum(np.abs(M), axis=0))) if M.size else 0.0
    k = max(0, int(np.ceil(np.log2(norm))) + 2) if norm > 0 else 0
    X = M / 2.0**k
    eye = np.eye(M.shape[0])  # one identity for all 16 terms (each step makes a new E)
    E = eye
    for j in range(16, 0, -1):
        E = eye + (X @ E) / j
    for _ in range(k):
        E = E @ E
    return E


def _delayed_zoh(A: np.ndarray, B: np.ndarray, dt: float, delay: float) -> Any:
    """:func:`synth.sim.discretize.delayed_zoh` with :func:`_expm_np`."""
    from synth.sim.discretize import DelayedZOH

    n = A.shape[0]

    def zoh(h: float) -> tuple[np.ndarray, np.ndarray]:
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n] = A * h, B * h
        E = _expm_np(M)
        return E[:n, :n], E[:n, n]

    steps = int(np.floor(delay / dt + 1e-9))
    fraction = delay - steps * dt
    Ad, G = zoh(dt)
    if fraction < 1e-9 * dt:
        return DelayedZOH(Ad, np.zeros(n), G, steps, 0.0)
    A_rest, G_late = zoh(dt - fraction)
    _, G_f = zoh(fraction)
    return DelayedZOH(Ad, A_rest @ G_f, G_late, steps, fraction)


_ZOH_KEPT: dict[tuple[bytes, float, float], tuple[Any, np.ndarray, np.ndarray]] = {}
""":func:`_companion_zoh`'s answers by (monic denominator, step, delay): an SRIVC step filters the output, the input,
the simulated output and its instruments through the same ``1/den`` (emptied past 256 entries)."""


def _companion_zoh(den: np.ndarray, dt: float, delay: float) -> tuple[Any, np.ndarray, np.ndarray]:
    """The delayed ZOH discretization of the companion form of ``1/den`` (monic), whose states are ``s^k/den``,
    and the transfer functions to its states (:func:`_numerators`)."""
    key = (den.tobytes(), float(dt), float(delay))
    if key not in _ZOH_KEPT:
        if len(_ZOH_KEPT) >= 256:
            _ZOH_KEPT.clear()
        n = den.size - 1
        A = np.zeros((n, n))
        A[:-1, 1:] = np.eye(n - 1)
        A[-1, :] = -den[1:][::-1]
        B = np.zeros(n)
        B[-1] = 1.0
        z = _delayed_zoh(A, B, dt, delay)
        _ZOH_KEPT[key] = (z, *_numerators(z))
    return _ZOH_KEPT[key]


def _numerators(z: Any) -> tuple[np.ndarray, np.ndarray]:
    """The discrete transfer functions from the held input, delayed by ``z.steps`` samples, to each state of the
    delayed ZOH system ``z``: their common denominator ``dd = det(zI - Ad)`` and one numerator row per state, in
    powers of ``1/z`` (scipy's ``lfilter`` convention).

    The state responds to the sample held over the step (``B_late``) and to the one before it (``B_early``, a
    fractional delay), so a numerator is ``C adj(zI - Ad) (B_late + B_early / z)``. ``adj(zI - Ad) b`` follows
    from the Faddeev-LeVerrier recursion ``v_0 = b``, ``v_j = Ad v_(j-1) + dd_j b``: the coefficient of
    ``z^(n-1-j)`` is ``v_j``, for every state at once, without an eigenvalue problem per state.

    Examples
    --------
    ``1/(s+2)`` held over 0.01 s, no delay: ``(1 - e^-0.02)/2 z^-1 / (1 - e^-0.02 z^-1)``.

    >>> z, dd, nums = _companion_zoh(np.array([1.0, 2.0]), 0.01, 0.0)
    >>> dd.round(6).tolist(), nums.round(8).tolist()
    ([1.0, -0.980199], [[0.0, 0.00990066, 0.0]])
    """
    Ad = z.Ad
    n = Ad.shape[0]
    dd = np.poly(Ad)
    nums = np.zeros((n, n + 2))
    for b, lag in ((z.B_late, 1), (z.B_early, 2)):
        if not np.any(b):
            continue
        v = b.copy()
        for j in range(n):
            if j:
                v = Ad @ v + dd[j] * b
            nums[:, lag + j] += v
    return dd, nums


def filter_bank(den: np.ndarray, dt: float, x: np.ndarray, count: int, delay: float = 0.0) -> list[np.ndarray]:
    """``s^k / den(s)`` applied to the held samples ``x`` (delayed), ``k = 0 .. count - 1``, zero initial state.

    One exact ZOH discretization of the companion form of ``1/den`` serves every ``k``
    (its states are ``s^k/den x``); ``k = deg(den)`` follows from ``den`` itself.

    Examples
    --------
    ``1/(s+2)`` and ``s/(s+2)`` of a unit step held from the first sample, 0.5 s later: ``(1 - e^-1)/2`` and
    ``e^-1``:

    >>> x = np.ones(51)
    >>> [round(float(v[-1]), 6) for v in filter_bank(np.array([1.0, 2.0]), 0.01, x, 2)]
    [0.31606, 0.367879]
    """
    from scipy.signal import lfilter

    den = np.asarray(den, float) / den[0]
    n = den.size - 1
    z, dd, nums = _companion_zoh(den, dt, delay)

    def shift(v: np.ndarray, k: int) -> np.ndarray:
        out = np.zeros_like(v)
        if k < v.size:
            out[k:] = v[:v.size - k]
        return out

    late = shift(x, z.steps)
    out = [lfilter(nums[k], dd, late) for k in range(min(count, n))]
    if count > n:
        direct = shift(x, z.steps + (1 if z.fraction > 0 else 0))
        out.append(direct - sum(den[n - k] * out[k] for k in range(n)))
    return out
