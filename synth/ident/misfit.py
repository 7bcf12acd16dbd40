"""Does the fitted structure explain the record? Its residuals beside the record's own noise.

A least-squares fit converges whatever the structure: ``exp(-s)/(T s + 1)`` fitted to a plant of gain 2 ends with a
time constant, a std column and a fit of 50 %, its residuals 80 times the output's noise. The std column assumes the
residuals are noise, and other tests on the residuals (whiteness, the start state) then answer for a model error
they cannot see. The record's noise level comes without a model (:func:`synth.ident.noise_floor.noise_sigma`); where
the residuals exceed it many times and leave more than a tenth of the output's variation unexplained, the fit says
so, and where scaling the model's response would take most of the misfit out, that a gain is what the structure lacks.
The second condition keeps a close fit quiet on a record whose sensor filters its noise (the second difference then
finds almost none: the DC motor of ``../shared/data/dcmotor_speed_lab``, fitted to 99.3 %, has residuals 490 times it).
"""

from __future__ import annotations

import numpy as np

from synth.errors import ModelError
from synth.ident.noise_floor import noise_sigma

__all__ = ["FIT_FLOOR", "MISFIT", "does_not_explain", "misfit_note", "misfit_ratio", "times_the_noise"]

MISFIT = 10.0
"""Residual std over the record's noise std above which the structure is said not to explain the record: white
residuals are at 1, and coloured noise (which the second difference underrates) or a noise floor estimated on a
fast response rarely reach a few."""

FIT_FLOOR = 90.0
"""Fit [%] (``100 (1 - ||residual|| / ||y - mean(y)||)``) below which residuals past :data:`MISFIT` are called a
structure that does not explain the record."""

GAIN_SHARE = 0.75
"""Share of the misfit a scaled response must take out for the note to name a missing gain."""


def misfit_ratio(y: np.ndarray, residuals: np.ndarray) -> float:
    """The residuals' std over the noise std of ``y`` (the fitted output, in time order); NaN where the output has
    no measurable noise (a quantized or noise-free record).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = np.linspace(0, 10, 5000); y = 1 - np.exp(-t) + 0.01 * rng.normal(size=t.size)
    >>> round(misfit_ratio(y, y - (1 - np.exp(-t))), 1)  # the true model: its residuals are the noise
    1.0
    >>> round(misfit_ratio(y, y - 0.5 * (1 - np.exp(-t))))  # half the gain
    10
    """
    return float(np.std(np.asarray(residuals, float)) / _noise_floor(y))


def _noise_floor(y: np.ndarray) -> float:
    """The white-noise std of ``y`` from its second difference; NaN where it has none to measure."""
    try:
        sigma = noise_sigma(np.asarray(y, float))
    except ModelError:
        return float("nan")
    return float(sigma) if sigma > 0.0 else float("nan")


def times_the_noise(ratio: float) -> str:
    """``ratio`` as text: a noise-free record's noise floor is its rounding, so ratios past 1000 say only that.

    Examples
    --------
    >>> times_the_noise(41.26), times_the_noise(5.6e7)
    ('41.3 times', 'over 1000 times')
    """
    return f"{ratio:.3g} times" if ratio < 1000.0 else "over 1000 times"


def does_not_explain(y: np.ndarray, residual_rms: float) -> float:
    """The ratio of a residual RMS to the record's noise (as :func:`misfit_ratio`) where it is past :data:`MISFIT` and
    the fit it implies on ``y`` below :data:`FIT_FLOOR`; else 0.

    Examples
    --------
    >>> t = np.linspace(0, 10, 5000); y = 2 * (1 - np.exp(-t)) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> round(does_not_explain(y, float(np.std(1 - np.exp(-t))))), does_not_explain(y, 0.02)
    (20, 0.0)
    """
    y = np.asarray(y, float)
    spread = float(np.linalg.norm(y - np.mean(y)))
    fit = 100.0 * (1.0 - residual_rms * np.sqrt(y.size) / spread) if spread > 0.0 else 100.0
    ratio = float(residual_rms / _noise_floor(y))
    return ratio if ratio > MISFIT and fit < FIT_FLOOR else 0.0


def misfit_note(y: np.ndarray, response: np.ndarray, residuals: np.ndarray) -> str:
    """A note when the residuals are more than :data:`MISFIT` times the record's noise and the fit is below
    :data:`FIT_FLOOR`, else ``""``.

    Parameters
    ----------
    y : numpy.ndarray
        The fitted output samples, in time order.
    response : numpy.ndarray
        The model's response to the input on the same samples, without any fitted constant offset.
    residuals : numpy.ndarray
        ``y`` less the fitted model's output (offset included).

    Examples
    --------
    >>> t = np.linspace(0, 10, 5000); y = 2 * (1 - np.exp(-t)) + 0.01 * np.random.default_rng(0).normal(size=t.size)
    >>> model = 1 - np.exp(-t)
    >>> misfit_note(y, model, y - model)[:39]
    "the residuals are 92 times the record's"
    >>> "about 2 times the model's" in misfit_note(y, model, y - model)
    True
    >>> misfit_note(y, 2 * model, y - 2 * model)
    ''
    """
    y, response, residuals = (np.asarray(a, float) for a in (y, response, residuals))
    rms = float(np.sqrt(np.mean(residuals**2)))
    ratio = does_not_explain(y, rms)
    if not ratio:
        return ""
    note = (f"the residuals are {times_the_noise(ratio)} the record's noise (residual RMS {rms:.3g}, "
            f"noise std {rms / ratio:.3g} from the output's second differences): the structure does not explain the record "
            "(a missing gain, pole, zero or delay, or an effect no linear model has), and the stds take the misfit for "
            "noise")
    basis = np.c_[response, np.ones_like(response)]
    if np.ptp(response) > 0.0:
        coefficients = np.linalg.lstsq(basis, y, rcond=None)[0]
        scale, scaled = float(coefficients[0]), y - basis @ coefficients
        if scale > 0.0 and abs(np.log(scale)) > np.log(1.2) \
                and float(scaled @ scaled) < (1.0 - GAIN_SHARE) * float(residuals @ residuals):
            note += (f"; the output is about {scale:.3g} times the model's response (scaled, the misfit falls by "
                     f"{1.0 - float(scaled @ scaled) / float(residuals @ residuals):.0%}): does the structure lack a "
                     "gain parameter?")
    return note
