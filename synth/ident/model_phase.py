"""The exact, continuous phase of a model and a frequency grid that brackets its features.

Used by :func:`synth.ident.hq.hq_from_plant` to read the handling-qualities metrics off a
model's exact response (crossings refined by Brent's method).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from synth.errors import ModelError
from synth.ident.hq_metrics import DEG
from synth.plant import Plant

__all__ = ["anchored_phase", "continuous_phase", "low_frequency_form", "model_grid"]


def anchored_phase(H: np.ndarray, at: int = 0) -> np.ndarray:
    """Phase of a measured response ``H`` [deg], unwrapped along its grid and shifted by a multiple of 360 deg so that
    it lies in (-270, 90] deg at point ``at`` (the branch ``synth hq`` and ``synth freqresp`` read).

    Examples
    --------
    >>> anchored_phase(np.exp(1j * np.radians([250.0, 240.0, 230.0]))).round(1)
    array([-110., -120., -130.])
    """
    phase = np.unwrap(np.angle(H)) * DEG
    return phase - 360.0 * np.ceil((phase[at] - 90.0) / 360.0)


def _zeros(plant: Plant) -> np.ndarray:
    num = np.trim_zeros(plant.num, "f")
    return np.roots(num) if num.size > 1 else np.array([], complex)


def low_frequency_form(plant: Plant) -> tuple[int, float]:
    """Integrators (poles minus zeros at s = 0) and the sign of the low-frequency gain.

    Examples
    --------
    >>> low_frequency_form(Plant.from_string("-4/(s*(0.1*s+1))"))
    (1, -1.0)
    """
    num, den = np.trim_zeros(plant.num, "f"), plant.den
    nz0 = int(num.size - np.trim_zeros(num, "b").size)
    np0 = int(den.size - np.trim_zeros(den, "b").size)
    c = np.trim_zeros(num, "b")[-1] / np.trim_zeros(den, "b")[-1]
    return np0 - nz0, float(np.sign(c))


def _factor_phase(roots: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Sum over ``roots`` of the angle of ``jw - r`` [rad], each on a branch continuous in ``w >= 0``."""
    total = np.zeros_like(w)
    for r in roots:
        y = w - r.imag
        if r.real > 0:  # right half-plane: the branch through pi is the continuous one
            total += np.pi - np.arctan2(y, r.real)
        else:
            total += np.arctan2(y, -r.real)
    return total


def _characteristic_frequencies(plant: Plant) -> np.ndarray:
    roots = np.concatenate([plant.poles(), _zeros(plant)])
    chars = np.abs(roots[np.abs(roots) > 1e-12])
    if plant.delay > 0:
        chars = np.append(chars, 1.0 / plant.delay)
    return chars


def continuous_phase(plant: Plant, w: Sequence[float] | np.ndarray) -> np.ndarray:
    """Unwrapped phase of ``plant(jw)`` in degrees, continuous in ``w`` (exact, delay included).

    The phase is the sum of the angles of ``jw - z`` over the zeros minus those over the poles,
    each on a branch continuous for ``w >= 0``, minus ``w * delay``, shifted by a multiple of
    360 deg so that it starts at -90 deg times the number of integrators (-180 deg more for a
    negative low-frequency gain).

    Examples
    --------
    >>> G = Plant.from_string("1/(s^2+s+1)", delay=0.1)
    >>> continuous_phase(G, [1e-6, 1.0, 10.0]).round(2)
    array([  -0.  ,  -95.73, -231.53])
    """
    w = np.asarray(w, float)
    if not np.any(plant.num):
        raise ModelError("the transfer function is zero; it has no phase")
    zeros, poles = _zeros(plant), plant.poles()
    lead = np.pi if np.trim_zeros(plant.num, "f")[0] < 0 else 0.0  # angle of the leading gain
    integrators, sign = low_frequency_form(plant)
    start = -np.pi / 2 * integrators + (0.0 if sign > 0 else -np.pi)
    chars = _characteristic_frequencies(plant)
    w0 = np.array([1e-9 * (chars.min() if chars.size else 1.0)])
    ref = lead + float((_factor_phase(zeros, w0) - _factor_phase(poles, w0))[0])
    shift = lead + 2 * np.pi * np.round((start - ref) / (2 * np.pi))
    return (_factor_phase(zeros, w) - _factor_phase(poles, w) - w * plant.delay + shift) * DEG


def model_grid(plant: Plant, points_per_decade: int = 200) -> np.ndarray:
    """Logarithmic frequency grid [rad/s] for crossing searches on a model.

    It spans three decades below the slowest and two above the fastest characteristic
    frequency (pole and zero moduli, ``1/delay``), with extra points across the resonance of
    every lightly damped pole or zero so that narrow phase features are bracketed.

    Examples
    --------
    >>> w = model_grid(Plant.from_string("1/(s^2+s+1)", delay=0.1))
    >>> float(w[0]), float(w[-1])
    (0.001, 1000.0)
    """
    chars = _characteristic_frequencies(plant)
    lo, hi = (chars.min() / 1e3, chars.max() * 1e2) if chars.size else (1e-3, 1e3)
    n = int(np.ceil(np.log10(hi / lo) * points_per_decade)) + 1
    parts = [np.logspace(np.log10(lo), np.log10(hi), n)]
    for r in np.concatenate([plant.poles(), _zeros(plant)]):
        wn = abs(r)
        if wn > 0 and abs(r.imag) > 0:
            zeta = -r.real / wn
            if abs(zeta) < 0.05:
                width = max(10 * abs(zeta), 1e-6)
                parts.append(wn * np.linspace(1 - width, 1 + width, 201))
    w = np.unique(np.concatenate(parts))
    return w[w > 0]

