"""A periodic step train's delay is known only up to its period: the fitted delay's aliases, screened on the whole
record.

The periodic steady state of a train of period ``P`` answers a delay ``d`` exactly as it answers ``d + j P``; a
symmetric train (two levels, each held half the period) answers ``d + P/2 + j P`` with the opposite gain as well
(``u(t - P/2) = u_hi + u_lo - u(t)``, the constant taken up by the output offset). A fit of the averaged period
therefore returns one of these aliases, and a model 2.3 s behind a train of period 2 s came out with a delay of
0.3 s (a black-box test). Only what is not periodic in the record tells them apart: the start-up from rest
before the train. :func:`screen_aliases` simulates the fitted model on the whole record once per distinct
fractional delay and scores each alias by shifting that output (the plant at rest before the record answers
nothing before its delay); :func:`alias_start` turns the best alias into a start for the whole-record fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synth.data import Record
from synth.errors import ModelError
from synth.ident.simulate import simulate_plant
from synth.ident.steps import StepAverage
from synth.ident.structure import Structure
from synth.ident.timefit import TimeFitResult
from synth.plant import Plant

__all__ = ["ALIAS_CRITICAL", "MAX_ALIASES", "AliasScreen", "alias_start", "ambiguity_note", "fixed_delay_note",
           "screen_aliases", "whole_record_start"]

ALIAS_CRITICAL = 3.84
"""Least drop of the weighted squared residual, in units of the noise variance, by which the record must prefer
one alias to every other for the screen to call the delay resolved (the chi-square quantile of one degree of
freedom at 95 %: a likelihood-ratio test between two fixed models)."""

MAX_ALIASES = 400
"""Most aliases screened (a long record of a fast train); the nearest to the fitted delay are kept."""


@dataclass(frozen=True)
class AliasScreen:
    """The aliases of a fitted delay and how well each explains the whole record from rest.

    Attributes
    ----------
    period : float
        The train's period [s].
    delays : numpy.ndarray
        The aliases [s], the fitted delay first.
    signs : numpy.ndarray
        +1, or -1 for a half-period alias (the gain negated).
    ssr : numpy.ndarray
        Weighted sum of squared residuals of each alias, the output offset fitted.
    noise_var : float
        The noise variance the differences are measured in: the best alias's residual variance.

    Examples
    --------
    >>> scr = AliasScreen(2.0, np.array([0.3, 1.3, 2.3]), np.array([1.0, -1.0, 1.0]), np.array([9.0, 7.0, 1.0]), 1.0)
    >>> scr.best, scr.margin, scr.resolved
    (2, 6.0, True)
    """

    period: float
    delays: np.ndarray
    signs: np.ndarray
    ssr: np.ndarray
    noise_var: float

    @property
    def best(self) -> int:
        """Index of the alias with the smallest residual."""
        return int(np.argmin(self.ssr))

    @property
    def margin(self) -> float:
        """How much worse the runner-up explains the record than the best, in noise variances (inf: one alias)."""
        if self.ssr.size < 2:
            return float("inf")
        two = np.partition(self.ssr, 1)[:2]
        return float((two[1] - two[0]) / self.noise_var)

    @property
    def resolved(self) -> bool:
        """Whether the record prefers one alias by at least :data:`ALIAS_CRITICAL`."""
        return self.margin >= ALIAS_CRITICAL


def _lagged_sums(a_spectrum: np.ndarray, r: np.ndarray, size: int) -> np.ndarray:
    """``c[k] = sum_i a[i] r[i - k]`` for ``k = 0 .. n-1`` (``r`` zero before its start; ``a_spectrum`` is
    ``rfft(a, size)`` with ``size >= 2 n - 1``): the sums of ``a`` times ``r`` delayed by every whole number of
    samples, by one FFT correlation.

    Examples
    --------
    >>> from scipy import fft
    >>> a = np.array([1.0, 2.0, 3.0])
    >>> _lagged_sums(fft.rfft(a, 6), np.array([1.0, 10.0, 100.0]), 6).round(9).tolist()
    [321.0, 32.0, 3.0]
    """
    from scipy import fft

    return fft.irfft(a_spectrum * np.conj(fft.rfft(r, size)), size)[: r.size]


def screen_aliases(t: np.ndarray, u: np.ndarray, y: np.ndarray, model: Plant, period_samples: int,
                   weights: np.ndarray | None, max_delay: float) -> AliasScreen:
    """Score the fitted ``model``'s delay and its aliases on a whole record that starts at rest.

    Parameters
    ----------
    t, u, y : numpy.ndarray
        The record (uniform ``t``), the plant at rest at ``u[0]`` before it.
    model : Plant
        The fitted model, delay included (sensor included: what the output answers with).
    period_samples : int
        The train's period in samples.
    weights : numpy.ndarray or None
        0/1 weights of the samples (a start-up of unknown state weighted 0).
    max_delay : float
        Longest alias screened [s].

    Examples
    --------
    >>> t = np.arange(0, 20, 0.01); u = np.where(t < 3, 0.0, ((t - 3) // 1.0) % 2 == 0).astype(float)
    >>> y = simulate_plant(Plant.from_string("1/(0.2*s+1)", delay=2.3), t, u)
    >>> scr = screen_aliases(t, u, y + 0.01 * np.random.default_rng(0).normal(size=t.size),
    ...                      Plant.from_string("1/(0.2*s+1)", delay=0.3), 200, None, 10.0)
    >>> float(scr.delays[scr.best].round(6)), int(scr.signs[scr.best]), scr.resolved
    (2.3, 1, True)
    >>> float(scr.delays[0]), float(scr.delays[1])  # the fitted delay first, then its aliases
    (0.3, 1.3)
    """
    dt = float(t[1] - t[0])
    period = period_samples * dt
    half = 0.5 * period
    w = u - u[0]
    d0 = float(model.delay)
    m0 = int(np.floor(d0 / half + 1e-9))  # the fitted delay is the alias m0 of the shortest, d0 - m0 P/2 >= 0
    shortest = max(d0 - m0 * half, 0.0)
    last = int(np.floor((max(max_delay, d0) - shortest) / half + 1e-9))
    ms = sorted(range(last + 1), key=lambda m: (abs(m - m0), m))[:MAX_ALIASES]
    from scipy import fft

    wts = np.ones_like(y) if weights is None else np.asarray(weights, float)
    total = float(wts.sum())
    wy = wts * y
    wy_sum = float(wy.sum())
    base = float(np.dot(wy, y)) - wy_sum ** 2 / total  # the weighted squares of y about its mean
    size = fft.next_fast_len(2 * t.size - 1, real=True)
    wy_spectrum, w_spectrum = fft.rfft(wy, size), fft.rfft(wts, size)
    sums = {}  # per extra half sample: sum w y R_k, sum w R_k, sum w R_k^2 at every shift k of the shortest alias

    def lagged(extra: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if extra not in sums:
            resp = simulate_plant(Plant(model.num, model.den, delay=shortest + extra * dt), t, w, initial="zero")
            sums[extra] = (_lagged_sums(wy_spectrum, resp, size), _lagged_sums(w_spectrum, resp, size),
                           _lagged_sums(w_spectrum, resp * resp, size))
        return sums[extra]

    signs = np.array([(-1.0) ** (m - m0) for m in ms])
    ssr = np.empty(len(ms))
    for i, m in enumerate(ms):
        k = (m * period_samples) // 2
        if k >= t.size:
            ssr[i] = base
            continue
        wyr, wr, wrr = (c[k] for c in lagged(0.5 * ((m * period_samples) % 2)))
        # y - s R_k with its weighted mean removed: sum w r^2 - (sum w r)^2 / W
        ssr[i] = base - 2 * signs[i] * (wyr - wy_sum * wr / total) + (wrr - wr * wr / total)
    delays = np.array([d0 if m == m0 else shortest + m * half for m in ms])
    # the best alias's residual variance: the noise's if that alias is right, more (a stricter test) if not
    return AliasScreen(period, delays, signs, ssr, float(ssr.min() / max(total - 1.0, 1.0)))


def alias_start(structure: Structure, parameters: dict[str, float], delay: float, sign: float) -> dict[str, float]:
    """Start values for a whole-record fit at the alias ``delay`` (``sign`` -1: the gain negated).

    The gain is negated by the parameter whose sign change negates the numerator alone (``k`` of ``k/(s+p)``);
    without one, by matching the negated model to the structure.

    Raises
    ------
    ModelError
        No parameters of the structure give the negated model.

    Examples
    --------
    >>> from synth.ident.structure import parse_structure
    >>> alias_start(parse_structure("K/(T*s+1)"), {"K": 2.0, "T": 0.5, "delay": 0.1}, 1.1, -1.0)
    {'K': -2.0, 'T': 0.5, 'delay': 1.1}
    """
    theta = np.array([float(parameters[k]) for k in structure.parameters])
    if sign < 0:
        num, den = structure.coefficients(theta)
        for i in range(theta.size):
            flipped = theta.copy()
            flipped[i] = -flipped[i]
            n2, d2 = structure.coefficients(flipped)
            if np.allclose(n2, -num, rtol=1e-12, atol=0.0) and np.allclose(d2, den, rtol=1e-12, atol=0.0):
                theta = flipped
                break
        else:
            from synth.ident.srivc import map_to_structure

            theta = map_to_structure(structure, -np.asarray(num, float), np.asarray(den, float))
            n2, _ = structure.coefficients(theta)
            if not np.all(np.isfinite(theta)) or np.dot(n2[-1:], num[-1:]) >= 0:
                raise ModelError(f"structure {structure.formula!r} cannot take the negated gain")
    named = [k for k in parameters if k not in structure.parameters] or ["delay"]  # the delay's name
    return {**dict(zip(structure.parameters, theta.tolist())), **{k: float(delay) for k in named}}


def whole_record_start(record: Record, avg: StepAverage, fit: TimeFitResult, structure: Structure,
                       weights: np.ndarray | None) -> tuple[dict[str, float], str]:
    """Where a whole-record fit from rest that follows a periodic fit starts: the periodic fit's parameters, or the
    alias of its fitted delay that the record prefers; and a note (that alias, or that the record cannot tell the
    aliases apart: :func:`ambiguity_note`).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.identification import identify
    >>> t = np.arange(0, 30, 0.01); u = np.where(t < 3, 0.0, ((t - 3) // 1.0) % 2 == 0).astype(float)
    >>> y = simulate_plant(Plant.from_string("1/(0.2*s+1)", delay=2.3), t, u)
    >>> y = y + 0.02 * np.random.default_rng(0).normal(size=t.size)
    >>> res = identify(record_from_arrays(t, u, y), "K/(T*s+1)", delay="fit")
    >>> {k: round(v, 2) for k, v in res.fit.parameters.items()}
    {'K': 1.0, 'T': 0.2, 'delay': 2.3}
    """
    start = {**fit.parameters}
    if not fit.periodic:
        return start, ""
    if not fit.delay_fitted:  # the user's delay: kept, with a note where an alias fits better
        return start, fixed_delay_note(record, avg, fit, weights)
    screen = _screen(record, avg, fit, weights)
    if screen.best == 0 or not screen.resolved:  # below ALIAS_CRITICAL the start-up prefers nothing: the note says so
        return start, ambiguity_note(fit, avg, screen)
    delay, sign = float(screen.delays[screen.best]), float(screen.signs[screen.best])
    try:
        start = alias_start(structure, fit.parameters, delay, sign)
    except ModelError:
        return start, ambiguity_note(fit, avg, screen)
    return start, (f"the averaged period fits a delay of {fit.delay:.6g} s as well as {delay:.6g} s"
                           f"{' with the gain reversed' if sign < 0 else ''} (delays differing by a period, or a "
                           f"half period with the gain reversed, of the {screen.period:.6g} s train); the start-up "
                           f"from rest prefers {delay:.6g} s by {screen.margin:.3g} noise variances "
                           f"({screen.delays.size} aliases screened): the whole record was fitted from there")


def _screen(record: Record, avg: StepAverage, fit: TimeFitResult, weights: np.ndarray | None) -> AliasScreen:
    period_samples = len(avg.t)
    train = float(record.t[avg.steps.index[0]])
    return screen_aliases(record.t, record.u, record.y, fit.measured, period_samples, weights,
                          float(record.t[-1]) - train - period_samples * record.dt)


def fixed_delay_note(record: Record, avg: StepAverage | None, fit: TimeFitResult, weights: np.ndarray | None) -> str:
    """A note when the start-up from rest prefers an alias of a delay the user fixed ('' otherwise): the periodic
    fit answers the given delay as well as one a period, or a half period with the gain reversed, away from it.
    Screened with ``weights`` (:func:`synth.ident.periodic_start.start_up_weights`: the constant input before the
    train weighted 0 up to the model's settling time, as the whole-record fit from rest weights it); ``None``: no
    constant start to screen on.

    Examples
    --------
    >>> from synth.ident.identification import identify
    >>> t = np.arange(0, 40, 0.01); u = np.where(t < 3, 0.0, ((t - 3) // 2.0) % 2 == 0).astype(float)
    >>> y = simulate_plant(Plant.from_string("2/(0.5*s+1)", delay=0.1), t, u)
    >>> res = identify((t, u, y + 0.02 * np.random.default_rng(0).normal(size=t.size)), "k/(T*s+1)", delay=2.1)
    >>> round(res.fit.parameters["k"], 2), "prefers a delay of 0.1 s with the gain reversed" in res.whole_record_note
    (-2.0, True)
    """
    if avg is None or not fit.periodic or fit.delay_fitted or weights is None:
        return ""
    screen = _screen(record, avg, fit, weights)
    if screen.best == 0 or not screen.resolved:
        return ""
    delay, sign = float(screen.delays[screen.best]), float(screen.signs[screen.best])
    return (f"the delay was given as {fit.delay:.6g} s, but the start-up from rest prefers a delay of {delay:.6g} s"
            f"{' with the gain reversed' if sign < 0 else ''} by {screen.margin:.3g} noise variances (the averaged "
            f"period of the {screen.period:.6g} s train answers delays a period apart alike, and a half period apart "
            "with the gain reversed): check the given delay, or fit it (--delay fit)")


def ambiguity_note(fit: TimeFitResult, avg: StepAverage | None, screen: AliasScreen | None) -> str:
    """A note when a fitted delay is known only up to the train's period: a periodic fit that stays, or a whole
    record whose start-up does not tell the aliases apart ('' otherwise).

    Examples
    --------
    >>> from synth.ident.identification import identify
    >>> t = np.arange(0, 30, 0.01); u = (((t // 1.0) % 2) == 0).astype(float)  # a train from its first sample
    >>> y = simulate_plant(Plant.from_string("1/(0.2*s+1)", delay=0.3), t, u, initial="zero")
    >>> res = identify((t, u, y + 0.01 * np.random.default_rng(1).normal(size=t.size)), "K/(T*s+1)", delay="fit")
    >>> ambiguity_note(res.fit, res.average, None)[:60]
    'the delay is known only up to the 2 s period of the averaged'
    """
    if not fit.delay_fitted or avg is None or not avg.periodic or (screen is not None and screen.resolved):
        return ""
    period = len(avg.t) * float(avg.t[1] - avg.t[0])
    why = ("no alias is preferred by the start-up from rest by "
           f"{ALIAS_CRITICAL} noise variances" if screen is not None else "the train is fitted as its averaged period")
    return (f"the delay is known only up to the {period:.6g} s period of the averaged train: {fit.delay:.6g} s, "
            f"{fit.delay + period:.6g} s, ... fit it alike, and {fit.delay + period / 2:.6g} s, ... with the gain "
            f"reversed for a train holding its two levels alike ({why}); a record with the input at rest before the "
            "train, longer than the plant's settling time and delay, tells them apart")
