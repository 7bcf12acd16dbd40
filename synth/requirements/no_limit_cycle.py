"""No limit cycle predicted by the describing function, for any in-loop delay in a range."""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import Field, NonNegativeFloat, field_validator, model_validator

from synth.freqgrid import characteristic_range, log_grid
from synth.requirements.base import NEPER_PER_DB, Bound, Requirement, RequirementResult, db, fmt, register
from synth.requirements.margins import closed_loop_unstable, unstable_result, with_unstable_rows
from synth.requirements.simulated import confirm_prediction
from synth.sim.describing import rate_limiter_df
from synth.sim.spec import BlockEntry, SimulationSpec

if TYPE_CHECKING:
    from synth.loop import Loop
    from synth.loop_batch import LoopBatch

__all__ = ["SUPPORTED_BLOCKS", "NoLimitCycle", "critical_gain_factor", "rate_limiter_locus"]

SUPPORTED_BLOCKS = ("saturation", "dead_zone", "rate_limit")
"""Actuator blocks whose critical locus ``-1/N`` is a fixed curve (independent of the frequency)."""

TWO_PI = 2.0 * np.pi

_UNIT_GAIN_FACTORS: dict[tuple[Any, ...], tuple[float, float | None, float | None]] = {}
"""Critical factors of loops with their controller's gain divided out (see ``NoLimitCycle._gain_factor``)."""


@cache
def rate_limiter_locus(points: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """The rate limiter's critical locus ``-1/N(rho)``, ``rho = R/(A w)`` in ``(0, 1]``, in polar form:
    ``(psi, r)`` with ``psi`` the counter-clockwise angle from the negative real axis (rad,
    increasing from 0 at ``-1`` towards ``pi/2``) and ``r = |-1/N|`` (increasing from 1).

    N depends on ``A`` and ``w`` only through ``rho``, so the locus is one curve for every frequency.

    Examples
    --------
    >>> psi, r = rate_limiter_locus()
    >>> round(float(psi[0]), 6), round(float(r[0]), 6), bool(np.all(np.diff(psi) > 0))
    (0.0, 1.0, True)
    """
    rho = np.geomspace(1.0, 1e-4, points)
    c = np.array([-1.0 / rate_limiter_df(1.0, 1.0, float(q)) for q in rho])
    psi = np.mod(np.angle(c) + np.pi, TWO_PI)
    psi = np.where(psi > np.pi, psi - TWO_PI, psi)  # the -1 point itself: 0 (not 2 pi)
    psi[0] = 0.0
    keep = np.concatenate([[True], np.diff(psi) > 0])
    return psi[keep], np.abs(c)[keep]


def _interior(L: np.ndarray, w: np.ndarray, delays: tuple[float, float], rate_limit: bool) -> np.ndarray:
    """Gain factor at each frequency at which the swept angle interval meets a critical locus."""
    lo, hi = delays
    mag = np.abs(L)
    psi0 = np.angle(L) + np.pi  # angle from the negative real axis
    a, b = psi0 - w * hi, psi0 - w * lo  # the delays sweep [a, b] at each frequency
    a_mod = np.mod(a, TWO_PI)
    contains_axis = (b - a >= TWO_PI) | (a_mod + (b - a) >= TWO_PI) | (a_mod == 0.0)
    with np.errstate(divide="ignore"):
        inv = np.where(mag > 0, 1.0 / mag, np.inf)
    k = np.where(contains_axis, inv, np.inf)
    if rate_limit:
        psi_c, r_c = rate_limiter_locus()
        inside = ~contains_axis & (a_mod < psi_c[-1])
        k = np.minimum(k, np.where(inside, np.interp(a_mod, psi_c, r_c) * inv, np.inf))
    return k


LOW_DECADES = 6
"""Decades searched below the grid where the critical factor still falls at its lowest frequency."""


def critical_gain_factor(L: Callable[[np.ndarray], np.ndarray], w: np.ndarray, delays: tuple[float, float],
                         kinds: tuple[str, ...]) -> tuple[float, float | None, float | None]:
    """Smallest loop-gain factor ``k`` at which ``k L(jw) exp(-jw tau)`` meets a block's critical locus for
    some ``tau`` in ``delays``: ``(k, w, tau)`` of the worst point (``inf`` when it never does).

    Every locus here contains ``-1`` (N = 1 at small amplitude); saturation and dead zone add the
    negative real axis left of ``-1``, the rate limiter its curve :func:`rate_limiter_locus`. A delay
    only turns ``L`` clockwise, so the delays in the range sweep an angle interval at each frequency and
    the test is exact in the delay. In frequency the grid ``w`` brackets the minima, which are then
    refined (bounded Brent), and the crossings of the negative real axis at both ends of the delay range
    are solved for (Brent): the result does not depend on the grid once it resolves the curve.

    Examples
    --------
    ``L = 20/(s (s+1) (s+2))`` with a saturation: a cycle is predicted (``|L|`` is 3.33 at 1.414 rad/s
    on the negative real axis), and a loop gain reduced by 3.33 would avoid it:

    >>> L = lambda w: 20 / (1j * w * (1j * w + 1) * (1j * w + 2))
    >>> k, wk, _ = critical_gain_factor(L, np.geomspace(0.01, 100, 201), (0.0, 0.0), ("saturation",))
    >>> round(k, 8), round(wk, 6)
    (0.3, 1.414214)
    """
    from scipy.optimize import brentq, minimize_scalar

    lo, hi = delays
    rate = "rate_limit" in kinds
    w = np.asarray(w, float)
    Lw = L(w)

    def k_at(x: float) -> float:
        v = float(_interior(L(np.array([x])), np.array([x]), delays, rate)[0])
        return v if np.isfinite(v) else 1e300  # Brent needs finite values

    k = _interior(Lw, w, delays, rate)
    if k.size > 1 and np.isfinite(k[0]) and k[0] < k[1]:
        # still falling at the grid's low end: the locus is met lower still (a loop on the negative real axis at
        # w = 0, e.g. an unstable pole under positive gain, approaches 1/|L(0)|; one with integrators, 0);
        # LOW_DECADES more decades below it
        low = w[0] * np.logspace(-LOW_DECADES, 0.0, 20 * LOW_DECADES + 1)[:-1]
        w = np.concatenate([low, w])
        Lw = np.concatenate([L(low), Lw])
        k = _interior(Lw, w, delays, rate)
    k_star, w_star, tau_star = np.inf, None, None
    if np.any(np.isfinite(k)):
        best = float(np.min(k))
        left = np.concatenate([[np.inf], k[:-1]])
        right = np.concatenate([k[1:], [np.inf]])
        minima = np.isfinite(k) & (k <= left) & (k <= right) & (k <= 1.5 * best)
        for i in np.flatnonzero(minima)[:20]:
            a, b = w[max(i - 1, 0)], w[min(i + 1, w.size - 1)]
            x, v = w[i], float(k[i])
            if b > a:
                res = minimize_scalar(k_at, bounds=(a, b), method="bounded", options={"xatol": 1e-12 * b})
                if res.fun < v:
                    x, v = float(res.x), float(res.fun)
            if v < k_star:
                k_star, w_star, tau_star = v, x, hi
    for edge in (lo, hi):  # negative-real-axis crossings at the ends of the delay range
        z = Lw * np.exp(-1j * w * edge)
        im = z.imag
        idx = np.flatnonzero((np.sign(im[:-1]) != np.sign(im[1:])) & ((z.real[:-1] < 0) | (z.real[1:] < 0)))
        for i in idx:
            f = lambda x, e=edge: float((L(np.array([x]))[0] * np.exp(-1j * x * e)).imag)  # noqa: E731
            fa, fb = f(w[i]), f(w[i + 1])  # no strict sign change: one end is on the axis itself
            x = brentq(f, w[i], w[i + 1], xtol=1e-14 * w[i + 1], rtol=1e-13) if fa * fb < 0 else \
                (w[i] if fa == 0 else w[i + 1])
            zx = L(np.array([x]))[0] * np.exp(-1j * x * edge)
            if zx.real < 0 and 1.0 / abs(zx) < k_star:
                k_star, w_star, tau_star = 1.0 / abs(zx), float(x), float(edge)
    return float(k_star), w_star, tau_star


@register
class NoLimitCycle(Requirement):
    """No limit cycle predicted (describing function) for any extra in-loop delay in ``delay``, with the
    loop gain free to rise by ``min_gain_margin_db`` (and to fall to zero).

    ``actuator`` lists the loop's nonlinear actuator blocks in the ``simulation:`` syntax (saturation,
    dead_zone, rate_limit; the chain is checked block by block, each by its own critical locus, as the
    chain's describing function is not the product of theirs). The measured value is the describing
    function gain margin: the smallest loop-gain factor at which the Nyquist curve, turned by any delay
    in the range, meets a critical locus (:func:`critical_gain_factor`, exact in the delay; in frequency
    bracketed on a log grid of ``per_decade`` points per decade and refined). Harmonic balance is a prediction:
    :meth:`evaluate` (the check, the design's certificate) confirms it by simulating a step with these blocks
    at both ends of the delay range and at the worst delay (:func:`~synth.requirements.simulated.confirm_prediction`:
    the spec's ``simulation:`` block sets the sample time, operating point and step; ``confirm: false``
    skips it); a simulated cycle where none is predicted makes it NOT met, and any disagreement is stated.
    :meth:`slack`, which the design searches with, is the prediction's alone. On a closed loop that is not
    stable (small signals already grow) the requirement is not met.

    Examples
    --------
    >>> from synth.loop import Loop; from synth.plant import Plant; from synth.controllers import Controller
    >>> req = NoLimitCycle(actuator=[{"type": "saturation", "min": -1, "max": 1}])
    >>> G = Plant.from_string("1/(s*(s+1)*(s+2))")
    >>> r = req.evaluate(Loop(G, Controller("P", {"kp": 5.0})))
    >>> r.met, round(r.value, 2), round(r.binding_frequency, 3)  # |L| = 5/6 on the negative real axis
    (True, 1.58, 1.414)
    >>> r.details["confirmation"], [s["verdict"] for s in r.details["simulations"]]
    ('confirmed', ['settled'])
    >>> late = req.model_copy(update={"delay": (0.0, 0.3)})
    >>> r = late.evaluate(Loop(G, Controller("P", {"kp": 5.0})))
    >>> r.met, round(r.details["delay_at_binding"], 2), r.details["confirmation"]
    (False, 0.3, 'confirmed')
    >>> [(s["delay"], s["verdict"]) for s in r.details["simulations"]]
    [(0.0, 'settled'), (0.3, 'limit_cycle')]
    """

    type: Literal["no_limit_cycle"] = "no_limit_cycle"
    actuator: list[BlockEntry] = Field(min_length=1)  # type: ignore[valid-type]
    delay: tuple[NonNegativeFloat, NonNegativeFloat] = (0.0, 0.0)
    min_gain_margin_db: NonNegativeFloat = 0.0
    confirm: bool = True
    simulation: SimulationSpec | None = None
    title: ClassVar[str] = "no limit cycle"
    costly: ClassVar[bool] = True
    bounds: ClassVar[dict[str, Bound]] = {"min_gain_margin_db": Bound("lower", "dB")}
    example: ClassVar[dict[str, Any]] = {"type": "no_limit_cycle", "delay": [0.0, 0.01],
                                         "actuator": [{"type": "saturation", "min": -1.0, "max": 1.0}]}

    @field_validator("actuator")
    @classmethod
    def _supported(cls, blocks: list[Any]) -> list[Any]:
        for b in blocks:
            if b.type not in SUPPORTED_BLOCKS:
                raise ValueError(f"block type {b.type!r} is not supported here (use {', '.join(SUPPORTED_BLOCKS)})")
        return blocks

    @model_validator(mode="after")
    def _delay_range(self) -> NoLimitCycle:
        if self.delay[1] < self.delay[0]:
            raise ValueError(f"delay must be [low, high], got [{self.delay[0]:g}, {self.delay[1]:g}]")
        return self

    def kinds(self) -> tuple[str, ...]:
        """The actuator's block types, sorted (each is checked by its own critical locus).

        Examples
        --------
        >>> NoLimitCycle(actuator=[{"type": "saturation", "min": -1, "max": 1}, {"type": "rate_limit", "rate": 5}]).kinds()
        ('rate_limit', 'saturation')
        """
        return tuple(sorted({b.type for b in self.actuator}))

    def _gain_factor(self, loop: Loop, per_decade: int) -> tuple[np.ndarray, tuple[float, float | None, float | None]]:
        """The critical factor of ``loop``. ``k L`` meets a locus at ``1/k`` times the factor of ``L``, so
        the factor of the loop with its controller's gain divided out is kept (:data:`_UNIT_GAIN_FACTORS`)
        and scaled: a gain swept over one plant costs one evaluation."""
        cnum, cden = loop.controller.tf()
        # the corners' range, not the loop's (which reaches beyond its crossovers, and so moves with the gain):
        # the factor kept for one gain is computed on the grid every gain of the sweep would use
        lo, hi = characteristic_range(cnum, cden, loop.plant.num, loop.plant.den, delay=loop.delay)
        w = log_grid(lo, hi * 10, per_decade)
        gain = float(cnum[np.flatnonzero(cnum)[0]] / cden[np.flatnonzero(cden)[0]]) if np.any(cnum) else 0.0
        if not gain > 0:
            return w, critical_gain_factor(loop.L, w, self.delay, self.kinds())
        key = (self.kinds(), self.delay, per_decade, loop.plant.num.tobytes(), loop.plant.den.tobytes(),
               loop.plant.delay, (cnum / gain).tobytes(), cden.tobytes())
        if key not in _UNIT_GAIN_FACTORS:
            if len(_UNIT_GAIN_FACTORS) >= 4096:
                _UNIT_GAIN_FACTORS.clear()
            # the unit-gain loop itself, not ``loop.L / gain``: the rounding of that quotient (and so the
            # refined minimum) would depend on the gain that came first, and results on the order of evaluation
            from synth.loop import Loop

            unit = Loop((np.polymul(cnum / gain, loop.plant.num), np.polymul(cden, loop.plant.den)), "P(1)",
                        delay=loop.plant.delay)
            _UNIT_GAIN_FACTORS[key] = critical_gain_factor(unit.L, w, self.delay, self.kinds())
        k, wk, tau = _UNIT_GAIN_FACTORS[key]
        return w, (k / gain, wk, tau)

    @classmethod
    def wants_simulation(cls, entry: dict[str, Any]) -> bool:
        """Whether a spec entry takes the spec's ``simulation:`` block (for its confirming runs).

        Examples
        --------
        >>> NoLimitCycle.wants_simulation({"type": "no_limit_cycle"}), NoLimitCycle.wants_simulation({"confirm": False})
        (True, False)
        """
        return bool(entry.get("confirm", True))

    def slack(self, loop: Loop, per_decade: int = 80) -> float:
        """The describing function's slack alone (the confirming simulations are :meth:`evaluate`'s)."""
        return self.predict(loop, per_decade).slack

    def evaluate(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        """:meth:`predict`, confirmed by simulation unless ``confirm`` is false or the loop is unstable."""
        r = self.predict(loop, per_decade)
        if not self.confirm or r.details.get("closed_loop_stable") is False:
            return r
        return confirm_prediction(self, r, loop)

    def predict(self, loop: Loop, per_decade: int = 80) -> RequirementResult:
        """The describing-function verdict (no simulation)."""
        if closed_loop_unstable(loop):
            return unstable_result(self, loop, "limit-cycle check")
        kinds = self.kinds()
        w, (k, wk, tau) = self._gain_factor(loop, per_decade)
        value = db(k) if np.isfinite(k) else np.inf
        slack = (value - self.min_gain_margin_db) * NEPER_PER_DB
        where = "" if wk is None else f", nearest at {fmt(wk)} rad/s with {fmt(tau * 1e3)} ms added"
        msg = (f"describing-function gain margin {fmt(value)} dB >= {fmt(self.min_gain_margin_db)} dB over "
               f"in-loop delays [{fmt(self.delay[0] * 1e3)}, {fmt(self.delay[1] * 1e3)}] ms: "
               f"{'met (no limit cycle predicted)' if slack >= 0 else 'NOT met (a limit cycle is predicted)'}"
               f"{where}; {', '.join(kinds)}; exact in the delay, bracketed on {per_decade} points/decade "
               "in frequency and refined")
        return self.result(value=value, bound=self.min_gain_margin_db, unit="dB", slack=slack,
                           margin=value - self.min_gain_margin_db, binding_frequency=wk, message=msg,
                           gain_factor=k, delay_at_binding=tau, blocks=list(kinds),
                           grid_points_per_decade=per_decade, grid=[float(w[0]), float(w[-1])],
                           method="describing function: critical loci -1/N against the delayed Nyquist curve")

    def batch_slack(self, batch: LoopBatch, per_decade: int = 80) -> np.ndarray:
        """Vectorized slack. The describing-function margin scales with the loop gain (``k L`` meets a
        locus at ``k`` times the factor of ``L``), so where the controllers differ by a gain only
        (:meth:`~synth.loop_batch.LoopBatch.gain_multiples`, e.g. a P gain swept) one exact evaluation
        gives every row; otherwise the rows are evaluated one by one. Unstable rows carry the scalar
        verdict.

        Examples
        --------
        >>> from synth.loop_batch import LoopBatch; from synth.plant import Plant; from synth.controllers import Controller
        >>> from synth.loop import Loop
        >>> req = NoLimitCycle(actuator=[{"type": "saturation", "min": -1, "max": 1}])
        >>> batch = LoopBatch(Plant.from_string("1/(s*(s+1)*(s+2))"), [Controller("P", {"kp": k}) for k in (2.0, 5.0)])
        >>> [round(float(v), 6) for v in req.batch_slack(batch)] == [round(req.slack(Loop(batch.plant, c)), 6)
        ...                                                          for c in batch.controllers]
        True
        """
        from synth.loop import Loop

        multiples = batch.gain_multiples()
        if multiples is None:
            return super().batch_slack(batch, per_decade)
        r, c = multiples
        _, (k_ref, _, _) = self._gain_factor(Loop(batch.plant, batch.controllers[r]), per_decade)
        with np.errstate(divide="ignore"):
            k = np.where(c > 0, k_ref / np.where(c > 0, c, 1.0), np.inf)
            value = np.where(np.isfinite(k), 20.0 * np.log10(k), np.inf)
        return with_unstable_rows(self, batch, (value - self.min_gain_margin_db) * NEPER_PER_DB)
