"""The compiled loop of a delayed linear step response (:func:`synth.timeresp.step_response`, long runs)."""

from __future__ import annotations

import numpy as np

from synth.jit import jit

__all__ = ["delayed_loop"]


@jit
def delayed_loop(Ac, Bc, Cc, Dc, Ap, Bp, Cp, Dp, m, steps):  # pragma: no cover - compiled
    """Output of the unit-step loop: controller ``(Ac, Bc, Cc, Dc)`` on the error, its output delayed ``m``
    steps into the plant ``(Ap, Bp, Cp, Dp)`` (both zero-order-hold discretizations), at steps ``0 .. steps``.

    Examples
    --------
    >>> e = np.exp(-0.01)  # 1/(s+1) held over 10 ms, a gain of 1, 5 steps of delay: y settles at 1/2
    >>> y = delayed_loop(np.zeros((0, 0)), np.zeros(0), np.zeros(0), 1.0, np.array([[e]]), np.array([1 - e]),
    ...                  np.array([1.0]), 0.0, 5, 3000)
    >>> round(float(y[-1]), 6), float(y[5])
    (0.5, 0.0)
    """
    nc, nplant = Ac.shape[0], Ap.shape[0]
    xc = np.zeros(nc)
    xp = np.zeros(nplant)
    xc_next = np.zeros(nc)
    xp_next = np.zeros(nplant)
    buffer = np.zeros(m)  # u[k - m] is read at step k
    y_hist = np.empty(steps + 1)
    for k in range(steps + 1):
        u_delayed = buffer[k % m]
        y = Dp * u_delayed
        for i in range(nplant):
            y += Cp[i] * xp[i]
        y_hist[k] = y
        e = 1.0 - y
        u = Dc * e
        for i in range(nc):
            u += Cc[i] * xc[i]
        for i in range(nc):
            acc = Bc[i] * e
            for j in range(nc):
                acc += Ac[i, j] * xc[j]
            xc_next[i] = acc
        for i in range(nplant):
            acc = Bp[i] * u_delayed
            for j in range(nplant):
                acc += Ap[i, j] * xp[j]
            xp_next[i] = acc
        xc, xc_next = xc_next, xc
        xp, xp_next = xp_next, xp
        buffer[k % m] = u
    return y_hist
