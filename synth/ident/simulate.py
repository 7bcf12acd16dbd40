"""A plant (rational transfer function times an exact delay) driven by a sampled input.

The input is held between samples (zero-order hold, as a digital command is);
the delay may be any real number, not only whole samples: the discretization
of :func:`synth.sim.discretize.delayed_zoh` is exact for a piecewise-constant
input. The discrete filter runs as one banded triangular solve
(:func:`synth.statespace.lfilter`, LAPACK), so a record of half a million
samples takes milliseconds, without importing :mod:`scipy.signal` (0.5 s).
"""

from __future__ import annotations

import numpy as np

from synth.errors import DataError, ModelError
from synth.plant import Plant
from synth.sim.discretize import delayed_zoh, tf_to_ss
from synth.statespace import lfilter, ss_to_tf

__all__ = ["simulate_plant"]


def _shift(x: np.ndarray, k: int) -> np.ndarray:
    """``x`` delayed by ``k`` samples, zero before the start."""
    if k <= 0:
        return x
    out = np.zeros_like(x)
    if k < x.size:
        out[k:] = x[:-k]
    return out


def _filter(Ad: np.ndarray, B: np.ndarray, C: np.ndarray, x: np.ndarray) -> np.ndarray:
    if not np.any(B):
        return np.zeros_like(x)
    num, den = ss_to_tf(Ad, B, C)
    return lfilter(num, den, x)


def simulate_plant(plant: Plant, t: np.ndarray, u: np.ndarray, initial: str = "steady") -> np.ndarray:
    """Output of ``plant`` at the times ``t`` for the held input samples ``u``.

    Parameters
    ----------
    plant : Plant
        Rational transfer function times ``exp(-delay s)``.
    t : numpy.ndarray
        Uniformly spaced sample times [s].
    u : numpy.ndarray
        Input samples, held constant over each interval.
    initial : {"steady", "zero"}
        ``"steady"``: the plant starts at rest at the steady state of the first
        input sample (output ``G(0) u[0]``; the input before ``t[0]`` equals
        ``u[0]``); ``"zero"``: it starts from zero state with zero input before ``t[0]``.
        A plant with an integrator has no steady output: ``"steady"`` starts it at rest with output 0 and its
        input's deviation from ``u[0]`` driving it (as :func:`synth.ident.timefit.fit_structure` assumes).

    Returns
    -------
    numpy.ndarray
        The output at each sample time.

    Examples
    --------
    >>> import numpy as np
    >>> G = Plant.from_string("2/(s+1)", delay=0.25)
    >>> t = np.arange(0, 3, 0.1)
    >>> y = simulate_plant(G, t, np.where(t >= 1.0, 1.0, 0.0))
    >>> float(y[12]), round(float(y[22]), 6), round(float(2 * (1 - np.exp(-(2.2 - 1.25)))), 6)
    (0.0, 1.226518, 1.226518)
    """
    t = np.asarray(t, float)
    u = np.asarray(u, float)
    if t.shape != u.shape or t.size < 2:
        raise DataError("time and input must be arrays of the same length (at least 2 samples)")
    dt = (t[-1] - t[0]) / (t.size - 1)
    if initial not in ("steady", "zero"):
        raise ModelError(f"initial must be 'steady' or 'zero', got {initial!r}")
    u0 = u[0] if initial == "steady" else 0.0
    gain = plant.dc_gain() if u0 != 0.0 else 0.0
    y0 = gain * u0 if np.isfinite(gain) else 0.0  # an integrator at rest: its level is the caller's offset
    w = u - u0
    A, B, C, D = tf_to_ss(plant.num, plant.den)
    z = delayed_zoh(A, B, dt, plant.delay) if A.size else None
    steps = z.steps if z is not None else int(np.floor(plant.delay / dt + 1e-9))
    fraction = z.fraction if z is not None else plant.delay - steps * dt
    y = np.full_like(w, y0)
    if z is not None:
        y += _filter(z.Ad, z.B_late, C, _shift(w, steps)) + _filter(z.Ad, z.B_early, C, _shift(w, steps + 1))
    if D != 0.0:
        y += D * _shift(w, steps + (1 if fraction > 1e-9 * dt else 0))
    return y
