"""The delayed linear loop of a step response, one delay's length of steps at a time, in numpy.

Within ``m`` steps (the delay) the plant's input is the controller's output of the ``m`` steps before, already
known: over such a block the plant is a linear map of its start state and of known inputs, and so is the
controller of its start state and of the errors the plant's block gives. Each block is then a few
matrix-vector products and two convolutions with the subsystems' impulse responses instead of ``m`` Python
steps: the same discrete loop as :func:`synth.delayed_step.delayed_loop`, in another order of floating-point
operations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synth.statespace import step_from_rest

__all__ = ["FFT_FROM", "delayed_loop_augmented", "delayed_loop_in_blocks"]

FFT_FROM = 512
"""Blocks of at least this many steps convolve by FFT (``O(m log m)``) instead of directly (``O(m^2)``)."""


@dataclass(frozen=True)
class _BlockMap:
    """``x[k+1] = A x[k] + B u[k]``, ``y[k] = C x[k] + D u[k]`` over ``m`` steps from ``x0``:
    ``y = O x0 + (h * u)[:m]`` and ``x[m] = Am x0 + R u``."""

    O: np.ndarray
    h: np.ndarray
    Am: np.ndarray
    R: np.ndarray
    h_fft: np.ndarray | None
    nfft: int

    @classmethod
    def of(cls, A: np.ndarray, B: np.ndarray, C: np.ndarray, D: float, m: int) -> _BlockMap:
        n = A.shape[0]
        O, G, P = np.asarray(C, float)[None, :], np.asarray(B, float)[:, None], A  # C A^i, A^i B; P = A^rows
        while O.shape[0] < m:  # doubling: log2(m) products instead of m
            O, G, P = np.vstack([O, O @ P]), np.hstack([G, P @ G]), P @ P
        O, R = O[:m], G[:, :m][:, ::-1]
        h = np.empty(m)
        h[0] = D
        h[1:] = O[:-1] @ B if n else 0.0
        Am = np.linalg.matrix_power(A, m) if n else np.zeros((0, 0))
        nfft = 1 << int(np.ceil(np.log2(2 * m))) if m >= FFT_FROM else 0
        return cls(O, h, Am, R, np.fft.rfft(h, nfft) if nfft else None, nfft)

    def output(self, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
        r = u.size
        if self.h_fft is None:
            forced = np.convolve(self.h[:r], u)[:r]
        else:
            forced = np.fft.irfft(np.fft.rfft(u, self.nfft) * self.h_fft, self.nfft)[:r]
        return self.O[:r] @ x0 + forced

    def state(self, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
        return self.Am @ x0 + self.R @ u


def delayed_loop_in_blocks(Ac: np.ndarray, Bc: np.ndarray, Cc: np.ndarray, Dc: float, Ap: np.ndarray,
                           Bp: np.ndarray, Cp: np.ndarray, Dp: float, m: int, steps: int) -> np.ndarray:
    """Output of the unit-step loop: controller ``(Ac, Bc, Cc, Dc)`` on the error, its output delayed ``m``
    steps into the plant ``(Ap, Bp, Cp, Dp)`` (both discrete), at steps ``0 .. steps``; the arguments of
    :func:`synth.delayed_step.delayed_loop`.

    Examples
    --------
    >>> e = np.exp(-0.01)  # 1/(s+1) held over 10 ms, a gain of 1, 5 steps of delay: y settles at 1/2
    >>> y = delayed_loop_in_blocks(np.zeros((0, 0)), np.zeros(0), np.zeros(0), 1.0, np.array([[e]]),
    ...                            np.array([1 - e]), np.array([1.0]), 0.0, 5, 3000)
    >>> round(float(y[-1]), 6), float(y[5]), y.size
    (0.5, 0.0, 3001)
    """
    plant = _BlockMap.of(np.asarray(Ap, float), np.asarray(Bp, float), np.asarray(Cp, float), float(Dp), m)
    ctrl = _BlockMap.of(np.asarray(Ac, float), np.asarray(Bc, float), np.asarray(Cc, float), float(Dc), m)
    total = steps + 1
    y_hist = np.empty(total)
    xp, xc = np.zeros(plant.Am.shape[0]), np.zeros(ctrl.Am.shape[0])
    u_delayed = np.zeros(m)  # the controller's output of the block before: the plant's input in this one
    for start in range(0, total, m):
        r = min(m, total - start)
        y = plant.output(xp, u_delayed[:r])
        y_hist[start:start + r] = y
        if start + r == total:
            break
        e = 1.0 - y
        u = ctrl.output(xc, e)
        xp, xc = plant.state(xp, u_delayed), ctrl.state(xc, e)
        u_delayed = u
    return y_hist


def delayed_loop_augmented(Ac: np.ndarray, Bc: np.ndarray, Cc: np.ndarray, Dc: float, Ap: np.ndarray,
                           Bp: np.ndarray, Cp: np.ndarray, Dp: float, m: int, steps: int) -> np.ndarray:
    """:func:`delayed_loop_in_blocks` for a short delay: the loop with its ``m`` delayed inputs as states is one
    discrete system of order ``n_plant + n_controller + m``, stepped from rest by
    :func:`synth.statespace.step_from_rest` (a block of samples per matrix product, where the delay's own
    blocks would be only ``m`` samples long).

    Examples
    --------
    A PI (a sum of the errors, held 10 ms) on ``1/(s+1)`` behind 3 steps: the same loop as the delay's blocks give

    >>> e, pi = np.exp(-0.01), (np.array([[1.0]]), np.array([1.0]), np.array([0.01]), 0.5)
    >>> args = (*pi, np.array([[e]]), np.array([1 - e]), np.array([1.0]), 0.0, 3, 2000)
    >>> y = delayed_loop_augmented(*args)
    >>> bool(np.allclose(y, delayed_loop_in_blocks(*args), rtol=0, atol=1e-12)), round(float(y[-1]), 4)
    (True, 1.0)
    """
    Ap, Bp, Cp = np.asarray(Ap, float), np.asarray(Bp, float).ravel(), np.asarray(Cp, float).ravel()
    Ac, Bc, Cc = np.asarray(Ac, float), np.asarray(Bc, float).ravel(), np.asarray(Cc, float).ravel()
    n_p, n_c = Ap.shape[0], Ac.shape[0]
    size = n_p + n_c + m  # z = [plant state, controller state, u[k-m], ..., u[k-1]]
    p, c, q = slice(0, n_p), slice(n_p, n_p + n_c), n_p + n_c  # q: the oldest input, the plant's now
    F = np.zeros((size, size))
    g = np.zeros(size)
    h = np.zeros(size)
    h[p], h[q] = Cp, Dp  # y = Cp xp + Dp u[k-m]; e = 1 - y
    F[p, p], F[p, q] = Ap, Bp  # xp' = Ap xp + Bp u[k-m]
    F[c, c] = Ac  # xc' = Ac xc + Bc e
    F[c, :] -= np.outer(Bc, h)
    g[c] = Bc
    F[q:size - 1, q + 1:] = np.eye(m - 1)  # the delay line shifts
    F[size - 1, c] = Cc  # u = Cc xc + Dc e enters at the young end
    F[size - 1, :] -= Dc * h
    g[size - 1] = Dc
    return step_from_rest(F, g, h, 0.0, steps + 1)
