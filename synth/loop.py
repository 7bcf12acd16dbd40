"""The feedback loop of a plant and a controller: L, S, T, KS and classical loop metrics.

Unity negative feedback, ``L = C G``, ``S = 1/(1 + L)``, ``T = L/(1 + L)``,
``KS = C S``. The plant delay stays exact: every frequency response is
evaluated as rational part times ``exp(-j w delay)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from synth.controllers import Controller, as_controller
from synth.freqgrid import characteristic_range, first_fall, log_grid
from synth.narrow_peaks import LIGHT_DAMPING, narrow_peak_frequencies
from synth.plant import Plant, as_plant
from synth.polynomials import dc_value, format_factored, horner, magnitude_squared_in_w2, polymul, trim
from synth.stability import StabilityResult, closed_loop_stability, neutral_with_any_delay, stability_floor
from synth.stability_sets import gain_margin_factors

__all__ = ["BANDWIDTH_LEVEL", "Loop", "Margins", "bandwidth_span"]

BANDWIDTH_LEVEL = 10 ** (-3 / 20)
"""|T| relative to |T(0)| that defines the closed-loop bandwidth (-3 dB)."""


@dataclass(frozen=True, eq=False)
class Margins:
    """Classical stability margins of a loop (delay included).

    Attributes
    ----------
    gain_margin_db : float
        ``20 log10`` of the loop-gain factor above 1 at which the loop turns
        marginal (``inf`` if none within 80 dB).
    lower_gain_margin_db : float
        Same for a gain reduction (``-inf`` if none): conditionally stable loops.
    phase_crossover : float or None
        Frequency of the gain-margin crossing (rad/s).
    phase_margin_deg : float
        Smallest phase margin over all gain crossovers (``inf`` without a crossover).
    gain_crossover : float or None
        Crossover frequency where the phase margin is smallest (rad/s).
    delay_margin : float
        Extra loop delay that makes the loop marginal (s): min over crossovers of PM/w, the phase
        margin taken in (0, 360] deg (0 when the closed loop is not stable).
    closed_loop_stable : bool
        The margins describe a stable closed loop; when False they are not margins of anything (a
        requirement on them is not met).
    lower_phase_crossover : float or None
        Frequency of the lower gain limit's crossing (rad/s): the loop of an open-loop unstable plant
        turns unstable when its gain falls by ``-lower_gain_margin_db``.
    """

    gain_margin_db: float
    lower_gain_margin_db: float
    phase_crossover: float | None
    phase_margin_deg: float
    gain_crossover: float | None
    delay_margin: float
    closed_loop_stable: bool = True
    lower_phase_crossover: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: the six classical fields, plus ``closed_loop_stable`` only when False and
        ``lower_phase_crossover`` only when there is a lower gain limit (reports of stable loops keep
        their layout).

        Examples
        --------
        >>> sorted(Margins(6.0, -np.inf, 1.0, 45.0, 0.5, 1.5).to_dict())[:3]
        ['delay_margin', 'gain_crossover', 'gain_margin_db']
        """
        out = dict(self.__dict__)
        if out["closed_loop_stable"]:
            del out["closed_loop_stable"]
        if out["lower_phase_crossover"] is None:
            del out["lower_phase_crossover"]
        return out


def bandwidth_span(lo: float, hi: float, crossovers: np.ndarray) -> tuple[float, float]:
    """The frequencies :meth:`Loop.bandwidth` searches, from a loop's :attr:`Loop.frequency_range` ``(lo, hi)`` and
    its gain crossovers: two decades beyond the crossovers too, and one more above.

    Examples
    --------
    >>> bandwidth_span(0.1, 100.0, np.array([5000.0]))
    (0.1, 5000000.0)
    """
    if crossovers.size:  # |T| falls near a crossover, which moves with the gain, not with the corners: a low-gain
        # loop's far below them, and a PI's with its integral corner at 1e-3 rad/s on 1.15/s (no other corner) at
        # 1.7 rad/s, above a range that ended at 0.11 rad/s (seed 9 #28: "inf")
        lo, hi = min(lo, float(np.min(crossovers)) / 100.0), max(hi, float(np.max(crossovers)) * 100.0)
    return lo, hi * 10


@dataclass(frozen=True, eq=False, init=False)
class Loop:
    """Plant and controller in unity negative feedback.

    Parameters
    ----------
    plant : Plant, str, control.TransferFunction, control.StateSpace or (num, den)
        Anything :func:`synth.plant.as_plant` takes.
    controller : Controller or str
        A :class:`~synth.controllers.Controller` or its text, e.g. ``"P(3)"``.
    delay : float, keyword only
        Exact delay [s] added to the plant's own (a python-control model has none); not stored
        apart: it becomes part of :attr:`plant`.

    Examples
    --------
    >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
    >>> loop = Loop(G, Controller("P", {"kp": 3.0}))
    >>> np.sort(-loop.closed_loop_poles().real).round(3)
    array([ 0.443, 78.697])
    >>> round(loop.bandwidth(), 2)
    83.16

    A python-control model and a controller's text work as well:

    >>> import control
    >>> G = control.tf([23.0, 23.0 * 0.43], np.polymul([1.0, 9.6], [1.0, 0.54]))
    >>> round(Loop(G, "P(3)").bandwidth(), 2)
    83.16
    >>> round(Loop(G, "P(3)", delay=0.02).margins().gain_margin_db, 2)
    1.79
    >>> Loop(G, "P(3)", delay=0.02).plant.delay
    0.02
    """

    plant: Plant
    controller: Controller

    def __init__(self, plant: Any, controller: Controller | str, *, delay: float = 0.0) -> None:
        object.__setattr__(self, "plant", as_plant(plant, delay))
        object.__setattr__(self, "controller", as_controller(controller))

    # ----------------------------------------------------------- rational parts
    @cached_property
    def num(self) -> np.ndarray:
        """Numerator of the rational part of L."""
        return trim(polymul(self.controller.tf()[0], self.plant.num))

    @cached_property
    def den(self) -> np.ndarray:
        """Denominator of the rational part of L."""
        return trim(polymul(self.controller.tf()[1], self.plant.den))

    @property
    def delay(self) -> float:
        """Loop delay (s)."""
        return self.plant.delay

    # --------------------------------------------------------------- responses
    def L(self, w: Any) -> np.ndarray:
        """Loop response ``C(jw) G(jw)``; ``inf`` at a loop pole on the axis (``w = 0`` with integral action)."""
        w = np.asarray(w, dtype=float)
        s = 1j * w
        d = np.polyval(self.den, s)
        with np.errstate(divide="ignore", invalid="ignore"):
            L = np.polyval(self.num, s) / d * np.exp(-s * self.delay)
        return np.where(d == 0, complex(np.inf, 0.0), L)

    @staticmethod
    def _infinite(L: np.ndarray) -> np.ndarray:
        return np.isinf(L.real) | np.isinf(L.imag)

    def S(self, w: Any) -> np.ndarray:
        """Sensitivity ``1/(1 + L)`` (0 where ``L`` is infinite)."""
        L = self.L(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self._infinite(L), 0j, 1.0 / (1.0 + L))

    def T(self, w: Any) -> np.ndarray:
        """Complementary sensitivity ``L/(1 + L)``; ``1`` where ``L`` is infinite."""
        L = self.L(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            T = L / (1.0 + L)
        return np.where(self._infinite(L), 1.0 + 0j, T)

    def KS(self, w: Any) -> np.ndarray:
        """Control sensitivity ``C/(1 + L)`` (input per unit reference or output disturbance);
        ``1/G`` where the controller has a pole on the axis."""
        C = self.controller.freqresp(w)
        G = self.plant.freqresp(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            KS = C / (1.0 + C * G)
            return np.where(self._infinite(C) | np.isnan(C), 1.0 / G, KS)

    def T0(self) -> float:
        """``|T(0)|``: 1 with integral action, ``|L(0)/(1 + L(0))|`` otherwise (the bandwidth's reference level;
        a step's final value is :meth:`dc_gain`, with its sign)."""
        return abs(self._t0)

    def dc_gain(self) -> float:
        """``T(0)`` with its sign, a unit reference step's final value: 1 with integral action, ``L(0)/(1 + L(0))``
        otherwise (negative where ``-1 < L(0) < 0``).

        Examples
        --------
        >>> Loop(Plant.from_string("-2/(s+1)"), Controller("P", {"kp": 0.3})).dc_gain()
        -1.4999999999999998
        """
        return self._t0

    @cached_property
    def _t0(self) -> float:
        l0 = dc_value(self.num, self.den)  # exact: s cancels first
        if np.isinf(l0):
            return 1.0
        if 1.0 + l0 == 0.0:  # a closed-loop pole at s = 0: T(0) is unbounded
            return float("inf")
        return float(l0 / (1.0 + l0))

    # --------------------------------------------------------------- frequencies
    @cached_property
    def frequency_range(self) -> tuple[float, float]:
        """Two decades beyond every corner frequency of C, G and ``1/delay`` and every gain crossover (rad/s).

        The crossovers count because the peaks of ``|S|`` and ``|T|`` sit near them, and they move with the gain,
        not with the corners: ``C = (0.037 s + 115)/s`` on ``2.52/s`` has its only corner at 3116 rad/s and a
        45 dB peak of ``|S|`` at its crossover, 17 rad/s (a design the corners' range called feasible under a
        peak |S| bound of 8.5 dB: seed 13 #7 of the design benchmark).

        Examples
        --------
        >>> loop = Loop(Plant.from_string("2.52/s"), Controller("PI", {"kp": 0.037, "ki": 115.0}))
        >>> [round(w, 2) for w in loop.frequency_range], loop.gain_crossovers().round(1).tolist()
        ([0.17, 310810.81], [17.0])
        """
        cn, cd = self.controller.tf()
        lo, hi = characteristic_range(cn, cd, self.plant.num, self.plant.den, delay=self.delay)
        with np.errstate(over="ignore", invalid="ignore"):  # gains near 1e300 overflow |L|^2: corners alone
            q = trim(np.polysub(magnitude_squared_in_w2(self.num), magnitude_squared_in_w2(self.den)))
        crossovers = _unit_crossings(q) if np.all(np.isfinite(q)) else np.array([])
        if crossovers.size:
            lo, hi = min(lo, float(crossovers[0]) / 100.0), max(hi, float(crossovers[-1]) * 100.0)
        return lo, hi

    def grid(self, per_decade: int = 80) -> np.ndarray:
        """Log frequency grid over :attr:`frequency_range`."""
        return log_grid(*self.frequency_range, per_decade)

    @cached_property
    def narrow_peaks(self) -> np.ndarray:
        """Frequencies around lightly damped closed-loop poles, whose peaks a log grid can step over
        (:func:`synth.narrow_peaks.narrow_peak_frequencies`).

        Examples
        --------
        >>> loop = Loop(Plant.from_string("1/(s^2 + 0.001*s + 1)"), Controller("P", {"kp": 0.1}))
        >>> bool(np.any(np.abs(loop.narrow_peaks - np.sqrt(1.1)) < 1e-6))
        True
        """
        try:
            if self.delay == 0.0:
                return narrow_peak_frequencies(self.closed_loop_poles())
            # with a delay, only a closed-loop pole next to a lightly damped open-loop pole or zero (that nearly
            # cancels it in |S| or |T|) hides its peak from the grid: Newton's method from those alone
            seeds = np.concatenate([np.roots(self.den), np.roots(self.num)]) if self.num.size > 1 else np.roots(self.den)
            seeds = seeds[(seeds.imag > 0) & (np.abs(seeds.real) < LIGHT_DAMPING * np.abs(seeds))]
            return narrow_peak_frequencies(self.quasi_roots(seeds)) if seeds.size else np.zeros(0)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError):  # no poles found: the grid alone
            return np.zeros(0)

    def gain_crossovers(self) -> np.ndarray:
        """All frequencies where ``|L(jw)| = 1`` (exact polynomial roots; the delay has |.| = 1).

        Examples
        --------
        >>> loop = Loop(Plant.from_string("10/(s+1)"), Controller("P", {"kp": 1.0}))
        >>> loop.gain_crossovers().round(4)
        array([9.9499])
        """
        return _unit_crossings(trim(np.polysub(magnitude_squared_in_w2(self.num), magnitude_squared_in_w2(self.den))))

    def crossover(self) -> float | None:
        """Lowest gain-crossover frequency (rad/s), or None if ``|L|`` never crosses 1."""
        wc = self.gain_crossovers()
        return float(wc[0]) if wc.size else None

    def bandwidth(self, per_decade: int = 80) -> float:
        """Closed-loop bandwidth: first frequency where ``|T|`` falls 3 dB below ``|T(0)|`` (rad/s).

        The level is ``|T(0)| * 10**(-3/20)`` (python-control's convention); a dip below it narrower than the
        grid counts (:func:`synth.freqgrid.first_fall`).
        Returns ``nan`` when ``T(0) = 0`` and ``inf`` when ``|T|`` never falls that far.
        """
        t0 = self.T0()
        if t0 == 0.0 or not np.isfinite(t0):
            return float("nan")
        level = t0 * BANDWIDTH_LEVEL
        return first_fall(lambda w: np.abs(self.T(w)), level,
                          log_grid(*bandwidth_span(*self.frequency_range, self.gain_crossovers()), per_decade))

    # ------------------------------------------------------------------ stability
    @cached_property
    def _stability(self) -> StabilityResult:
        return closed_loop_stability(self.num, self.den, self.delay,
                                     stability_floor(self.plant.num, self.plant.den, self.plant.delay))

    def stability(self) -> StabilityResult:
        """Exact closed-loop stability (Nyquist count with the delay)."""
        return self._stability

    @cached_property
    def gain_factors(self) -> tuple[float, float, float | None, float | None]:
        """``(k_lo, k_hi, w_lo, w_hi)`` of :func:`synth.stability_sets.gain_margin_factors` (cached)."""
        return gain_margin_factors(self.num, self.den, self.delay)

    def margins(self) -> Margins:
        """Gain, phase and delay margins, delay included.

        The gain limits come from the D-decomposition in the loop gain (a Nyquist-exact count): for a
        conditionally stable loop or an open-loop unstable plant both a lower and an upper limit are
        reported. On a closed loop that is not stable the margins are flagged (``closed_loop_stable``)
        and the delay margin is 0.

        Examples
        --------
        >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))", delay=0.02)
        >>> m = Loop(G, Controller("P", {"kp": 3.0})).margins()
        >>> round(m.gain_margin_db, 2), round(m.phase_crossover, 2)
        (1.79, 84.28)

        An open-loop unstable plant has a lower gain limit (here ``k > 0.5``, i.e. -12.04 dB from 2):

        >>> m = Loop(Plant.from_string("10/((s-1)*(s+5))"), Controller("P", {"kp": 2.0})).margins()
        >>> round(m.lower_gain_margin_db, 2), m.gain_margin_db, round(m.phase_margin_deg, 2)
        (-12.04, inf, 39.99)
        """
        k_lo, k_hi, w_lo, w_hi = self.gain_factors
        gm = 20 * np.log10(k_hi) if np.isfinite(k_hi) else np.inf
        lgm = 20 * np.log10(k_lo) if k_lo > 0 else -np.inf
        pm, wpm, dm = np.inf, None, np.inf
        for wc in self.gain_crossovers():
            phase = np.degrees(np.angle(self.L(np.array([wc]))[0]))
            this = 180.0 - (-phase) % 360.0  # phase + 180 wrapped to (-180, 180]: L = +1 is 180 deg from -1
            if this < pm:
                pm, wpm = float(this), float(wc)
            # extra delay turns L(j wc) clockwise: it reaches -1 after the phase margin taken in (0, 360] deg
            turn = this if this > 0 else this + 360.0
            dm = min(dm, np.radians(turn) / wc) if this != 0.0 else 0.0
        if neutral_with_any_delay(self.num, self.den):  # any added delay: neutral type (|L(j inf)| >= 1)
            dm = 0.0
        stable = self.stability().stable
        return Margins(float(gm), float(lgm), w_hi, pm, wpm, float(dm) if stable else 0.0, stable, w_lo)

    # --------------------------------------------------------- closed-loop poles
    def closed_loop_poles(self, pade_order: int = 10) -> np.ndarray:
        """Closed-loop poles, sorted by decreasing real part.

        Without a delay: roots of ``den + num``. With a delay: roots of the
        quasi-polynomial ``den(s) + num(s) exp(-delay s)`` found by Newton's
        method from the roots of a Pade approximation, keeping only converged
        roots (the dominant ones; there are infinitely many).
        """
        if self.delay == 0.0:
            roots = np.roots(trim(np.polyadd(self.den, self.num)))
            return roots[np.argsort(-roots.real)]
        pn, pd = _pade(self.delay, pade_order)
        return self.quasi_roots(np.roots(trim(np.polyadd(polymul(self.den, pd), polymul(self.num, pn)))))

    def quasi_roots(self, seeds: np.ndarray) -> np.ndarray:
        """Roots of ``den(s) + num(s) exp(-delay s)`` by Newton's method from ``seeds`` (the converged ones,
        without repeats, sorted by decreasing real part).

        Examples
        --------
        >>> loop = Loop(Plant.from_string("1/(s+1)", delay=0.1), Controller("P", {"kp": 2.0}))
        >>> r = loop.quasi_roots(np.array([-3.0 + 0j]))
        >>> float(abs(r[0] + 1 + 2 * np.exp(-0.1 * r[0])))
        0.0
        """
        polys = [self.den, self.num, np.polyder(self.den), np.polyder(self.num)]
        width = max(p.size for p in polys)
        rows = np.array([np.concatenate([np.zeros(width - p.size), p]) for p in polys])

        def values(z: np.ndarray) -> np.ndarray:
            """den, num, den', num' at ``z`` (rows), the four at once."""
            return horner(rows, z[None, :])

        s = seeds.astype(complex)
        active = np.ones(s.size, dtype=bool)  # Newton's method on every seed at once; each stops on its own
        with np.errstate(all="ignore"):
            for _ in range(50):
                if not active.any():
                    break
                z = s[active]
                e = np.exp(-self.delay * z)
                d0, n0, d1, n1 = values(z)
                f = d0 + n0 * e
                df = d1 + (n1 - self.delay * n0) * e
                flat = df == 0
                step = np.where(flat, 0.0, f / np.where(flat, 1.0, df))
                z = z - step
                s[active] = z
                done = flat | (np.abs(step) <= 1e-13 * np.maximum(1.0, np.abs(z)))
                active[np.flatnonzero(active)[done]] = False
            e = np.exp(-self.delay * s)
            d0, n0 = values(s)[:2]
            resid = np.abs(d0 + n0 * e)
            scale = np.abs(d0) + np.abs(n0 * e) + 1e-300
        found: list[complex] = []
        for root, ok in zip(s, resid <= 1e-9 * scale):
            if ok and not any(abs(root - f0) <= 1e-7 * max(1, abs(root)) for f0 in found):
                found.append(complex(root))
        roots = np.array(found)
        return roots[np.argsort(-roots.real)]

    def closed_loop_text(self, digits: int = 4) -> str | None:
        """``T(s)`` in factored form (None with a delay: T is not rational).

        Examples
        --------
        >>> G = Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))")
        >>> Loop(G, Controller("P", {"kp": 3.0})).closed_loop_text()
        '69*(s+0.43)/((s+78.7)*(s+0.4429))'
        """
        if self.delay:
            return None
        return format_factored(self.num, np.polyadd(self.den, self.num), digits)


def _pade(delay: float, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Pade approximation of ``exp(-delay s)`` (numerator, denominator)."""
    from math import factorial

    n = order
    coeffs = [factorial(2 * n - k) * factorial(n) / (factorial(2 * n) * factorial(k) * factorial(n - k))
              for k in range(n + 1)]
    den = np.array([c * delay**k for k, c in enumerate(coeffs)])[::-1]
    num = np.array([c * (-delay) ** k for k, c in enumerate(coeffs)])[::-1]
    return num / den[0], den / den[0]


def _unit_crossings(q: np.ndarray) -> np.ndarray:
    """The positive real ``w`` (sorted) where ``|N|^2 - |D|^2``, the polynomial ``q`` in ``w^2``, is zero."""
    if q.size < 2:
        return np.array([])
    r = np.roots(q)
    keep = (np.abs(r.imag) <= 1e-9 * (1 + np.abs(r.real))) & (r.real > 0)
    return np.sort(np.sqrt(r[keep].real))
