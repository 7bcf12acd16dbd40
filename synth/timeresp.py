"""Linear closed-loop step responses and step metrics.

Without a delay the response of ``T`` is computed exactly (matrix exponential
of the closed-loop state-space model at each sample time). With a delay the
loop is simulated with the plant and controller held over each step (zero-order
hold) at three steps ``dt``, ``2 dt``, ``4 dt`` that divide the delay, extrapolated
(Richardson) with an estimate of the remaining error, and the step halved until
that estimate is within :data:`STEP_TOLERANCE` (:func:`linear_step`); the step
and the estimate are reported. The loop runs a delay's length of steps at a time
(:mod:`synth.delayed_blocks`); long runs step by step, compiled (:mod:`synth.delayed_step`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from synth.delayed_blocks import delayed_loop_augmented, delayed_loop_in_blocks
from synth.exact_steps import exact_step
from synth.loop import Loop
from synth.polynomials import trim
from synth.statespace import tf_to_ss, zoh

__all__ = ["LinearStep", "StepMetrics", "default_horizon", "discrete_loop", "linear_step", "metric_rows",
           "step_metrics", "step_response", "step_tail"]


@dataclass(frozen=True)
class StepMetrics:
    """Step-response metrics.

    Attributes
    ----------
    rise_time : float
        10 % to 90 % of the change to the final value (s).
    overshoot : float
        Peak beyond the final value, percent of the change.
    settling_time : float
        Last time the response is outside +-2 % of the change around the final value (s).
    final_value : float
        Final value used.
    peak : float
        Largest excursion in the direction of the step.
    """

    rise_time: float
    overshoot: float
    settling_time: float
    final_value: float
    peak: float

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return asdict(self)


def step_metrics(t: np.ndarray, y: np.ndarray, y0: float = 0.0, y_final: float | None = None,
                 settle_band: float = 0.02, error: np.ndarray | None = None) -> StepMetrics:
    """Rise time (10-90 %), overshoot, settling time of a step response.

    Parameters
    ----------
    t, y : ndarray
        Time (s) and response.
    y0 : float
        Value before the step.
    y_final : float, optional
        Final value (default: the last sample).
    settle_band : float
        Settling band as a fraction of the change.
    error : ndarray, optional
        A bound on the error of ``y`` at each sample (:class:`LinearStep`): the metrics are then the worst the
        response allows, the peak raised by it and the band narrowed by it (its negative gives the best).

    Examples
    --------
    >>> t = np.linspace(0, 10, 10001)
    >>> m = step_metrics(t, 1 - np.exp(-t))
    >>> round(m.rise_time, 3), round(m.settling_time, 2)
    (2.197, 3.91)
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    yf = float(y[-1]) if y_final is None else float(y_final)
    change = yf - y0
    if change == 0 or not np.isfinite(change):
        return StepMetrics(float("nan"), float("nan"), float("nan"), yf, float(y.max()))
    frac = (y - y0) / change
    slack = None if error is None else np.nan_to_num(np.asarray(error, float) / abs(change))[None]
    rise, peak_frac, settling = (float(v[0]) for v in metric_rows(t, frac[None], slack, settle_band))
    return StepMetrics(rise, max(0.0, (peak_frac - 1.0) * 100.0), settling, yf, float(y0 + peak_frac * change))


def metric_rows(t: np.ndarray, frac: np.ndarray, slack: np.ndarray | None, settle_band: float,
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The metrics of :func:`step_metrics` for many responses at once: rows of ``frac`` (the response as a fraction
    of its change, ``(k, m)``) at the times ``t`` (``(m,)``, or ``(k, m)``: each row's own), ``slack`` a bound on each
    sample's error as a fraction (None: exact). Returns the rise times (10-90 %, worst case), the peak fractions and the
    settling times (``nan`` where the last sample is outside the band), each ``(k,)``.

    Examples
    --------
    >>> t = np.linspace(0.0, 10.0, 10001)
    >>> rise, peak, settle = metric_rows(t, 1.0 - np.exp(-t)[None], None, 0.02)
    >>> round(float(rise[0]), 3), round(float(peak[0]), 4), round(float(settle[0]), 2)
    (2.197, 1.0, 3.91)
    """
    t = np.broadcast_to(np.asarray(t, float), frac.shape)
    rows = np.arange(frac.shape[0])

    def first_cross(f: np.ndarray, level: float) -> np.ndarray:
        hit = f >= level
        i = np.argmax(hit, axis=1)
        before = np.maximum(i - 1, 0)
        f0, f1, t0, t1 = f[rows, before], f[rows, i], t[rows, before], t[rows, i]
        with np.errstate(divide="ignore", invalid="ignore"):
            at = np.where(i == 0, t[:, 0], t0 + (level - f0) / (f1 - f0) * (t1 - t0))
        return np.where(hit[rows, i], at, np.nan)

    exact = slack is None  # no error bound: the arrays with it added or taken off are ``frac`` itself
    low, high = (frac, frac) if exact else (frac - slack, frac + slack)
    rise = first_cross(low, 0.9) - first_cross(high, 0.1)
    peak = np.max(high, axis=1)
    outside = np.abs(frac - 1.0) > settle_band if exact else np.abs(frac - 1.0) + slack > settle_band
    last = frac.shape[1] - 1 - np.argmax(outside[:, ::-1], axis=1)  # the last sample outside the band
    after = t[rows, np.minimum(last + 1, frac.shape[1] - 1)]
    settling = np.where(~outside.any(axis=1), t[:, 0], np.where(last == frac.shape[1] - 1, np.nan, after))
    return rise, peak, settling


def default_horizon(loop: Loop, poles: np.ndarray | None = None) -> float:
    """A time span that shows the dominant closed-loop dynamics: 12 time constants of the fastest
    dominant pole, at least 20 delays. ``poles``: the loop's :meth:`~synth.loop.Loop.closed_loop_poles`, when
    the caller has them (with a delay they cost a Pade model and Newton's method).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> float(default_horizon(Loop(Plant.from_string("1/s"), Controller("P", {"kp": 2.0}))))  # 12 / 2
    6.0
    """
    poles = loop.closed_loop_poles() if poles is None else poles
    fast = [abs(p.real) for p in poles if p.real < 0]
    span = 12.0 / max(fast) if fast else 1.0
    dominant = sorted(fast)
    if len(dominant) > 1 and dominant[-1] / dominant[0] > 50:
        span = 12.0 / dominant[-1]
    return max(span, 20 * loop.delay, 1e-3)


def step_tail(loop: Loop, poles: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The closed loop's step as ``y(t) = T(0) + sum_i c_i e^(p_i t)`` over its poles ``p_i`` (with a delay, the
    dominant roots :meth:`~synth.loop.Loop.closed_loop_poles` finds): ``(p, |c|)``. ``c_i`` is the residue of
    ``T(s)/s`` at ``p_i``, ``N(p) e^(-tau p) / (p Delta'(p))`` with ``Delta = D + N e^(-tau s)``; ``inf`` at a
    repeated root. What is left of the step after ``t`` is at most ``sum |c_i| e^(Re p_i t)`` (a slow pole that a
    zero nearly cancels creeps after the fast part has settled).

    Examples
    --------
    ``T = 1/(s+1)``: ``y = 1 - e^(-t)``, one pole with ``|c| = 1``

    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> p, c = step_tail(Loop(Plant.from_string("1/s"), Controller("P", {"kp": 1.0})))
    >>> p.real.round(6).tolist(), c.round(6).tolist()
    ([-1.0], [1.0])
    """
    p = np.asarray(loop.closed_loop_poles() if poles is None else poles, complex)
    num, den, tau = loop.num, loop.den, loop.delay
    e = np.exp(-tau * p)
    slope = np.polyval(np.polyder(den), p) + (np.polyval(np.polyder(num), p) - tau * np.polyval(num, p)) * e
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.abs(np.polyval(num, p) * e / (p * slope))
    return p, np.where(np.isfinite(c), c, np.inf)


def step_response(loop: Loop, t_end: float | None = None, n: int = 2001) -> tuple[np.ndarray, np.ndarray, float]:
    """Response of the output to a unit reference step.

    Returns
    -------
    t, y : ndarray
    dt : float
        Simulation step with a delay (0 when the response is exact).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3.0}))
    >>> t, y, dt = step_response(loop, 0.2)
    >>> round(step_metrics(t, y, y_final=loop.T0()).rise_time, 4)
    0.025
    """
    run = linear_step(loop, t_end, n)
    return run.t, run.y, run.dt


@dataclass(frozen=True)
class LinearStep:
    """A closed loop's unit step as :func:`linear_step` computes it.

    Attributes
    ----------
    t, y : ndarray
        Time (s) and output.
    dt : float
        Simulation step with a delay (0 when the response is exact).
    error : ndarray
        Estimated error of ``y`` at each ``t``: the simulation's (the extrapolations' difference) and the linear
        interpolation's between its samples (0 when exact; NaN where it could not be estimated).
    """

    t: np.ndarray
    y: np.ndarray
    dt: float
    error: np.ndarray

    def to_dict(self) -> dict:
        """JSON-ready dict (NaN errors as None).

        Examples
        --------
        >>> LinearStep(np.zeros(2), np.ones(2), 0.0, np.zeros(2)).to_dict()["y"]
        [1.0, 1.0]
        """
        return {"t": self.t.tolist(), "y": self.y.tolist(), "dt": self.dt,
                "error": [None if not np.isfinite(e) else float(e) for e in self.error]}


def linear_step(loop: Loop, t_end: float | None = None, n: int = 2001,
                decided: Callable[[LinearStep], bool] | None = None, times: np.ndarray | None = None,
                extremes: bool = False) -> LinearStep:
    """The closed loop's unit step with an estimate of its error: exact without a delay; with one, held at a
    step refined until the estimated error is at most :data:`STEP_TOLERANCE` of the response's largest value
    (or until :data:`MAX_STEPS`). ``decided(run)``: the caller's test that a run is accurate enough for what it
    judges (a step limit whose verdict its error cannot change); refinement then stops as soon as it is true
    and the error is within :data:`DECIDED_TOLERANCE`. The response is given at ``n`` even times over
    ``[0, t_end]``, or at ``times`` (from 0, increasing; runs of even spacing such as
    :func:`synth.exact_steps.doubling_grid`'s). ``extremes``: with a delay, the simulation's highest and lowest
    values are also given, at their own times, where they lie beyond every one of those samples (for step
    metrics: :func:`_with_extremes`).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = Loop(Plant.from_string("1/(s+1)", delay=0.1), Controller("PI", {"kp": 0.5, "ki": 0.5}))
    >>> run = linear_step(loop, 8.0)
    >>> bool(0.0 < float(run.error.max()) <= 1e-4 * float(np.abs(run.y).max()))
    True
    """
    if times is None:
        t = np.linspace(0.0, default_horizon(loop) if t_end is None else float(t_end), n)
    else:
        t = np.asarray(times, float)
    if loop.delay == 0.0:
        return LinearStep(t, exact_step(loop.num, trim(np.polyadd(loop.den, loop.num)), t), 0.0, np.zeros(t.size))
    return _delayed_step(loop, t, decided, extremes)


STEP_PER_CROSSOVER = 0.02
"""Largest first simulation step of a delayed loop times its highest gain-crossover frequency: the loop samples
its error and holds it for one step, a lag of half a step (0.57 deg at crossover for ``w_c dt = 0.02``), an error
of first order that the extrapolation of :func:`linear_step` cancels; its estimate then halves the step where the
rest is not small enough. With only the horizon setting the step (1/20000 of it), a PI with a slow integral tail,
simulated for 512 s, ran at 25.6 ms steps and overshot 24.9 % where a fine simulation gives 24.0 % (before the
extrapolation). The rule was ``w_c dt <= 0.002`` until the error was estimated and controlled; starting ten times
coarser, a PI behind 20 ms simulated 20,000-80,000 steps instead of 100,000-400,000 (the report's feasibility map of
such a PI: 3.7 -> 2.2 s). On 300 random delayed loops the largest difference from a run started at
``w_c dt = 0.0005`` was within the estimate on 299 with either start (at most 0.41 of it, 0.44 before); the other
is a biproper plant, whose step jumps at each multiple of the delay, with either start."""

STEP_PER_POLE = 0.01
"""Largest simulation step of a delayed loop times the largest magnitude of the controller's and the plant's
poles: the holds' error, after the extrapolation, is of second order in the step times the fastest dynamics (a
PID's derivative filter). A PID with its filter pole at 39 rad/s behind 0.88 s, held at 2 to 3.5 ms by the
crossover's rule, overshot 19.99 % where the method of steps gives 20.29 % (a fresh seed of the step-design
benchmark)."""

AUGMENTED_UP_TO = 128
"""A delay of at most this many steps runs as one discrete system with the delayed inputs as states
(:func:`synth.delayed_blocks.delayed_loop_augmented`, 64 samples per matrix product: under 1 ms for 20,000
steps up to 32 steps of delay, 2.3 ms at 128); a longer one a delay's length at a time
(:func:`synth.delayed_blocks.delayed_loop_in_blocks`, faster from there on)."""

BLOCK_STEPS = 20_000
"""Up to this many steps a delay longer than :data:`AUGMENTED_UP_TO` steps runs in blocks (0.3 to 3 us per step);
longer runs are compiled with numba (about 10 ms per million steps once numba is imported and the loop loaded,
0.2-0.6 s once per process). A step limit's horizon now waits for slow poles: a design's checks ran 100,000-
200,000 steps each in blocks at about 20-40 ms (a PI behind 20 ms: 17.5 -> 13.9 s for the whole command)."""

MAX_STEPS = 4_000_000
"""Most simulation steps of the finest run of a delayed step response (the compiled loop takes about 10 ms per
million; the two coarser runs add three quarters of that)."""


STEP_TOLERANCE = 1e-4
"""Largest estimated error of a delayed step, relative to the response's largest magnitude: the step is halved
until the estimate is below it (or :data:`MAX_STEPS` is reached). A PI behind 5.7 ms ringing for 22 cycles, held
at 25 us (the crossover's rule), was extrapolated 4e-4 of its final value low at 1.745 s, inside a settling band
that the method of steps puts it just outside (settling 1.711 s instead of 1.748 s: a false "met" at 1.725 s in
a fresh seed of the step-design benchmark)."""


DECIDED_TOLERANCE = 1e-2
"""Largest estimated error, relative to the response's largest magnitude, at which a caller's ``decided`` test
may stop the refinement (:func:`linear_step`): beyond it the estimate itself is not to be trusted."""


def discrete_loop(loop: Loop, t_end: float) -> tuple[tuple, float]:
    """The delayed loop as :func:`step_response` first simulates it over ``t_end`` (its finest run): the
    arguments of :func:`synth.delayed_blocks.delayed_loop_in_blocks` (controller and plant held over the step,
    the delay in steps, the number of steps) and the step. A delay of at least one step is a multiple of four
    steps (the coarser runs take every other and every fourth step: :func:`linear_step` extrapolates from the
    three and estimates the error).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> args, dt = discrete_loop(Loop(Plant.from_string("1/(s+1)", delay=0.1), Controller("P", {"kp": 0.5})), 4.0)
    >>> args[-2:], dt
    ((500, 20000), 0.0002)
    """
    crossovers = loop.gain_crossovers()
    dt_target = t_end / 20000
    if crossovers.size:
        dt_target = min(dt_target, STEP_PER_CROSSOVER / float(np.max(crossovers)))
    fastest = max(float(np.max(np.abs(p), initial=0.0))
                  for p in (np.roots(trim(loop.controller.tf()[1])), loop.plant.poles()))
    if fastest > 0:
        dt_target = min(dt_target, STEP_PER_POLE / fastest)
    dt_target = max(dt_target, t_end / MAX_STEPS)
    if loop.delay >= dt_target:
        m = 4 * int(np.ceil(loop.delay / dt_target / 4))
        dt = loop.delay / m
    elif t_end / loop.delay <= MAX_STEPS / 4:  # a delay shorter than the step: the step shortened to a quarter of it
        m, dt = 4, loop.delay / 4
    else:  # a delay too short for that within MAX_STEPS: one step of delay (error of order dt), not extrapolated
        m, dt = 1, dt_target
    steps = 4 * int(np.ceil(t_end / dt / 4))
    return _loop_arguments(loop, dt, m, steps), dt


def _loop_arguments(loop: Loop, dt: float, m: int, steps: int) -> tuple:
    cn, cd = loop.controller.tf()
    Ac, Bc, Cc, Dc = _zoh(cn, cd, dt)
    Ap, Bp, Cp, Dp = _zoh(loop.plant.num, loop.plant.den, dt)
    return (Ac, Bc, np.asarray(Cc, float).ravel(), float(np.ravel(Dc)[0]), Ap, Bp, np.asarray(Cp, float).ravel(),
            float(np.ravel(Dp)[0]), m, steps)


def _simulated(args: tuple) -> np.ndarray:
    """The kernel's output at steps ``0 .. steps`` (:data:`AUGMENTED_UP_TO`, :data:`BLOCK_STEPS`)."""
    m, steps = args[-2:]
    with np.errstate(over="ignore", invalid="ignore"):
        if m <= AUGMENTED_UP_TO:
            return delayed_loop_augmented(*args)
        if steps <= BLOCK_STEPS:
            return delayed_loop_in_blocks(*args)
        from synth.delayed_step import delayed_loop  # numba: compiled once, cached on disk

        return delayed_loop(*args)


def _delayed_step(loop: Loop, t: np.ndarray, decided: Callable[[LinearStep], bool] | None,
                  extremes: bool = False) -> LinearStep:
    """The held loop at ``dt``, ``2 dt`` and ``4 dt`` (the delay a multiple of four steps, so that all three hold
    it exactly), extrapolated (Richardson). The holds' error is of first order in the step: ``2 y_dt - y_2dt``
    cancels it (a PID behind 0.33 s overshot 9.998 % held at 0.66 ms where the method of steps gives 10.123 %;
    extrapolated, 10.12 %), and the same from ``2 dt`` and ``4 dt`` differs from it by three times its own
    error, of second order: that difference is the error estimate, and a third of it is added (the answer is of
    third order). The step is halved until the estimate is within :data:`STEP_TOLERANCE` of the response's
    largest value, or within :data:`DECIDED_TOLERANCE` and ``decided`` says that is enough.
    When the delay is shorter than the step would be, the step becomes a quarter of the delay (a PI behind
    0.15 ms, held at 0.3 ms with one step of delay, overshot 51.90 % where the method of steps gives 51.77 %);
    only a delay too short for that within :data:`MAX_STEPS` is held as one step, its error not estimated (NaN)."""
    args, dt = discrete_loop(loop, float(t[-1]))
    m, steps = args[-2:]
    if m == 1:
        y = _simulated(args)
        return LinearStep(t, _on_grid(t, dt, y), dt, np.full(t.size, np.nan))
    runs = {m: _simulated(args)}

    def run(k: int) -> np.ndarray:  # the loop held at delay / k, k steps of delay
        if k not in runs:
            runs[k] = _simulated(_loop_arguments(loop, loop.delay / k, k, steps * k // m))
        return runs[k]

    with np.errstate(over="ignore", invalid="ignore"):
        while True:
            fine, half, quarter = run(m), run(m // 2), run(m // 4)
            # (2 y_dt - y_2dt) - (2 y_2dt - y_4dt) at the 4 dt grid: three times the error of the first
            gap = (2.0 * fine[::4] - 3.0 * half[::2] + quarter) / 3.0
            worst = float(np.max(np.abs(gap)))
            scale = float(np.max(np.abs(quarter)))
            done = not np.isfinite(worst) or worst <= STEP_TOLERANCE * scale or 2 * steps > MAX_STEPS
            if done or (decided is not None and worst <= DECIDED_TOLERANCE * scale):
                out = LinearStep(t, _on_grid(t, dt, fine) + _on_grid(t, 2.0 * dt, fine[::2] - half)
                                 + _on_grid(t, 4.0 * dt, gap), dt,
                                 _on_grid(t, 4.0 * dt, np.abs(gap)) + _between_samples(t, dt, fine))
                if extremes:
                    out = LinearStep(*_with_extremes(out.t, out.y, out.error, dt, fine, half, gap))
                if done or (decided is not None and decided(out)):
                    return out
            runs.pop(m // 4)
            m, steps, dt = 2 * m, 2 * steps, dt / 2.0


def _with_extremes(t: np.ndarray, y: np.ndarray, error: np.ndarray, dt: float, fine: np.ndarray, half: np.ndarray,
                   gap: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """``(t, y, dt, error)`` with the simulation's highest and lowest extrapolated values inserted at their own
    times where they lie beyond every output sample (``error`` there: the extrapolation's, and the second
    difference of the simulation around them over 8, the most its linear interpolation misses). A delayed
    loop's response has corners at multiples of the delay, and its peak fell between the output samples (a
    lead-lag on ``13.08/s`` behind 3.26 s, output every 16 ms: overshoot 2.785 % with an error of 2.3e-5 where
    the response reaches 2.826 %, a false "met" of a 2.8 % limit).

    Examples
    --------
    >>> fine = np.r_[np.linspace(0, 1.2, 6), np.linspace(1.15, 1.0, 11)]  # held at 0.25 s: a peak at 1.25 s
    >>> out = _with_extremes(np.array([0.0, 2.0, 4.0]), fine[[0, 8, 16]], np.zeros(3), 0.25, fine, fine[::2],
    ...                      np.zeros(5))
    >>> out[0].tolist(), np.round(out[1], 3).tolist()
    ([0.0, 1.25, 2.0, 4.0], [0.0, 1.2, 1.12, 1.0])
    """
    last = min(int(np.floor(t[-1] * (1.0 + 1e-12) / dt)), fine.size - 1)  # the fine samples within t
    if last < 8 or not np.all(np.isfinite(y)):
        return t, y, dt, error
    with np.errstate(over="ignore", invalid="ignore"):  # the extrapolated response at every fourth sample first
        coarse = (fine[::4] + (fine[::2] - half)[::2] + gap)[:last // 4 + 1]
    if not np.all(np.isfinite(coarse)):
        return t, y, dt, error
    extra = []
    for j, higher in ((int(np.argmax(coarse)), True), (int(np.argmin(coarse)), False)):
        lo, hi = max(4 * j - 4, 0), min(4 * j + 4, last)  # then every sample around it
        times = dt * np.arange(lo, hi + 1)
        with np.errstate(over="ignore", invalid="ignore"):
            values = fine[lo:hi + 1] + _on_grid(times, 2.0 * dt, fine[::2] - half) + _on_grid(times, 4.0 * dt, gap)
        k = int(np.argmax(values) if higher else np.argmin(values))
        if ((values[k] > y.max()) if higher else (values[k] < y.min())) and not np.any(
                np.isclose(t, times[k], rtol=0.0, atol=1e-12 * t[-1])):
            i = lo + k
            second = np.abs(np.diff(fine[max(i - 2, 0):i + 3], 2))
            extra.append((times[k], values[k], float(_on_grid(times[k:k + 1], 4.0 * dt, np.abs(gap))[0])
                          + float(np.max(second, initial=0.0)) / 8))
    if not extra:
        return t, y, dt, error
    extra = sorted({e[0]: e for e in extra}.values())
    at = np.array([e[0] for e in extra])
    where = np.searchsorted(t, at)
    return (np.insert(t, where, at), np.insert(y, where, [e[1] for e in extra]), dt,
            np.insert(error, where, [e[2] for e in extra]))


def _between_samples(t: np.ndarray, h: float, values: np.ndarray) -> np.ndarray:
    """A bound on the error of :func:`_on_grid`'s linear interpolation at ``t``: the second difference of
    ``values`` around the interval times ``f (1 - f) / 2`` at the fraction ``f`` of the interval
    (``h^2 |y''| f (1 - f) / 2``, at most an eighth; at the delay's kink it covers the kink). A time on a sample
    is exact: a loop whose response jumps at the delay's multiples (a biproper one) got an eighth of the jump at
    its samples there (an error of 0.062 of the final value reported for 1e-4)."""
    x = t / h
    i = np.clip(x.astype(np.int64), 1, values.size - 3)
    frac = np.clip(x - np.minimum(x.astype(np.int64), values.size - 2), 0.0, 1.0)
    second = np.maximum(np.abs(values[i + 1] - 2.0 * values[i] + values[i - 1]),
                        np.abs(values[i + 2] - 2.0 * values[i + 1] + values[i]))
    return second * frac * (1.0 - frac) / 2.0


def _on_grid(t: np.ndarray, h: float, values: np.ndarray) -> np.ndarray:
    """``values`` (at ``0, h, 2 h, ...``) linearly interpolated at the times ``t`` (within the grid)."""
    x = t / h
    i = np.minimum(x.astype(np.int64), values.size - 2)
    return values[i] + (x - i) * (values[i + 1] - values[i])


def _zoh(num: np.ndarray, den: np.ndarray, dt: float):
    num, den = trim(num), trim(den)
    if den.size == 1:
        return np.zeros((0, 0)), np.zeros(0), np.zeros(0), float(num[-1] / den[0])
    A, B, C, D = tf_to_ss(num, den)
    Ad, Bd = zoh(A, B, dt)
    return Ad, Bd[:, 0], C, D
