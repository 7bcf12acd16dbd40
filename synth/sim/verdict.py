"""A step verdict with its evidence: settled, limit cycle, diverging, or undetermined within N s.

:func:`step_verdict` simulates a reference step over a first horizon read from the loop's
dynamics (:func:`synth.sim.horizon.plan_horizon`), judges the run and, while the run does not
decide, doubles the horizon up to a cap. The rules (:func:`judge`), on the output after the step:

* **diverging**: the output is not finite or beyond 1e9 steps; or it grows on two horizons in a
  row (when the first horizon is already the cap: over the run and over its first half), growing
  meaning: over the last half, the RMS of the last third more than 3 times that of the first, or its
  largest distance from the reference over the last quarter more than 10 steps and 1.3 times that
  over the second quarter) and sets a new record (the largest distance over the last quarter is
  1.1 times the largest before it: bounded bursts do not count);
* **limit cycle**: a sustained oscillation (:func:`synth.sim.limitcycle.detect_oscillation`, at
  least 3 regular cycles) in each of the last three quarters of the run, at least
  :data:`MIN_CYCLES` whole cycles in the last two, with periods equal within :data:`STEADY` (1 %)
  and amplitudes (each quarter's mean cycle: a slowly drifting centre does not count) within 1 %,
  or varying by less than 20 % without a trend (not monotone over the quarters, and a
  least-squares drift of the whole cycles' amplitudes of at most 1 % over them: a quantized or
  sampled cycle whose waveform changes from cycle to cycle); or, when the crossings are irregular
  (a waveform crossing its mean more than twice per period), the last two quarters repeat
  themselves (autocorrelation above 0.98) with the same period and amplitude within 1 %, or (a
  sustained irregular oscillation, e.g. quasi-periodic relay or quantizer chatter) the peak-to-peak
  ranges of the last three quarters are equal within 10 % and above twice ``min_amplitude`` and
  the numerical floor (amplitude: half that range; period: the mean of the crossings); so do regular crossings of
  cycles that do not repeat whose quarter-mean periods differ by more than 1 %, when those ranges show no trend.
  Regular cycles also need the output's centre and the controller's command, each averaged over the quarters'
  whole cycles, to have stopped moving one way (within 1 % of its half range, or converging geometrically to within that): a
  command still winding towards a block's threshold ends the cycle there. A limit
  cycle whose whole cycles do not repeat (lengths within 1 %, maxima and minima within 1 % of the
  amplitude: :attr:`Oscillation.periodic <synth.sim.limitcycle.Oscillation>`) is reported as
  oscillating but not periodic, with the range of its cycles' amplitudes and lengths;
* **settled**: no sustained oscillation in the last quarter, which stays within :data:`SETTLED`
  (0.01 %) of the step (or ``min_amplitude``) of the final value, does not creep (the least-squares line
  through it changes by at most 0.01 % of the step, or less than the ripple about it: ``min_amplitude``
  floors a ripple below a sensor's quantum, not a slow mode's creep under a quantizer's still reading), and
  moves (peak to peak) at most half as much as the quarter before, its last eighth at most :data:`SHRINK` times the eighth
  before (or less than twice ``min_amplitude``, or 1e-9 of the step: the numerical floor);
* **not settled** either, where a loop of linear blocks only has a root on or right of the imaginary axis, while the
  controller's command under the still output does not die out (:func:`synth.sim.hidden_mode.hidden_drift`: a
  mode the output does not see); on two horizons in a row (at the cap alone: over the run and its first half)
  that is **diverging**;
* a run shorter than the linear loop's settling time (:class:`~synth.sim.horizon.HorizonPlan`, the cap
  permitting) is not settled yet, whatever its last quarter shows (a 1 s run of the X-4 loop under its
  sensor's quantizer looked settled 1.3 % of the step from where it settles after 6 s);
* otherwise the horizon is doubled; at the cap the verdict is **undetermined** and says what was
  seen (cycles, the rule that failed).

Every verdict carries its evidence: the horizons tried, the sample time and count, the cycles
seen and the rule that decided.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.sim.authority import short_of_reference
from synth.sim.centre_drift import STEADY, centre_drift
from synth.sim.cycles import autocorrelation_period, measure_cycle
from synth.sim.hidden_mode import hidden_drift, unseen_root
from synth.sim.holding import winding_behind
from synth.sim.horizon import plan_horizon
from synth.sim.limitcycle import SAMPLED_HYSTERESIS, Oscillation, cycle_table, detect_oscillation
from synth.sim.loops import NonlinearLoop
from synth.sim.metrics import NonlinearStepMetrics, nonlinear_step_metrics
from synth.sim.results import SimResult
from synth.sim.verdict_results import Evidence, Judgement, StepVerdict

__all__ = [
    "MAX_SAMPLES",
    "MIN_CYCLES",
    "SETTLED",
    "SHRINK",
    "STEADY",
    "VERDICTS",
    "Evidence",
    "Judgement",
    "StepVerdict",
    "default_cap",
    "judge",
    "step_verdict",
    "warm_up",
]

VERDICTS = ("settled", "limit_cycle", "diverging", "undetermined")
"""The four answers of a step simulation."""
MIN_CYCLES = 6
"""Whole cycles a limit cycle needs in the last half of the run."""
SETTLED = 1e-4
"""Largest distance from the final value over the last quarter of a settled run (fraction of the step)."""
SHRINK = 0.75
"""Largest ratio of the motion (peak to peak) over the last eighth of a settled run to that over the eighth
before: an exponential decay that halves the motion per quarter shrinks it by 0.71 per eighth; a small
sustained oscillation reached within the last quarter keeps a ratio near 1."""
PROBE_SAMPLES = 50
"""Samples at the starting reference that show whether the loop's linear rest holds with its blocks."""
MAX_SAMPLES = 1_000_000
"""Most samples of one run under the default cap (:func:`default_cap`)."""


def _oscillation(t: np.ndarray, y: np.ndarray, window: float, min_amplitude: float) -> Oscillation:
    """:func:`~synth.sim.limitcycle.detect_oscillation` with the hysteresis of a noise-free simulated output."""
    return detect_oscillation(t, y, window=window, min_amplitude=min_amplitude, hysteresis=SAMPLED_HYSTERESIS,
                              whole_cycles=True)


def _drift(ta: np.ndarray, ya: np.ndarray) -> float:
    """Relative drift of the cycles' size over the last three quarters of the run: the least-squares
    line through each whole cycle's half peak-to-peak range against its start time, its change over
    those quarters divided by the mean (inf with fewer than 3 cycles)."""
    keep = ta >= ta[-1] - 0.75 * (ta[-1] - ta[0])
    starts, halves = cycle_table(ta[keep], ya[keep])
    if halves.size < 3 or float(np.mean(halves)) <= 0:
        return float("inf")
    slope = np.polyfit(starts - starts[0], halves, 1)[0]
    return float(abs(slope) * (ta[-1] - ta[keep][0]) / float(np.mean(halves)))


def _mean_cycle(t: np.ndarray, y: np.ndarray) -> float:
    """Mean half peak-to-peak range of the whole cycles of ``y`` (0 without any)."""
    halves = cycle_table(t, y)[1]
    return float(np.mean(halves)) if halves.size else 0.0


def _steady(a: Oscillation, b: Oscillation, c: Oscillation, drift: float,
            sizes: tuple[float, float, float]) -> tuple[str | None, str]:
    """(None, how) when the last three quarters ``c``, ``b``, ``a`` show the same cycle: periods within
    STEADY, and amplitudes (``sizes``: each quarter's mean half peak-to-peak of a whole cycle) within
    STEADY, or varying (by less than 20 %) without a trend: not monotone over the quarters, and
    ``drift`` (:func:`_drift`) within STEADY, or converging geometrically (the quarters' changes shrinking
    by a ratio below 0.8) to a limit within STEADY of the last quarter's."""
    if not (b.present and c.present and a.amplitude and b.amplitude and c.amplitude and a.period and b.period
            and c.period):
        return "the two quarters before the last do not both show a sustained cycle", ""
    # the size of the cycle itself: the mean of its whole cycles' half peak-to-peak ranges, not the
    # quarter's range, which a slowly drifting centre (a hunting integrator) keeps changing
    a, b, c = (dataclasses.replace(o, amplitude=size or o.amplitude) for o, size in zip((a, b, c), sizes, strict=True))
    dp = max(abs(a.period - b.period), abs(b.period - c.period)) / a.period
    if dp > STEADY:
        return f"the period still changes {100 * dp:.2g} % between the last three quarters", ""
    da = max(abs(a.amplitude - b.amplitude), abs(b.amplitude - c.amplitude)) / a.amplitude
    if da <= STEADY:
        return None, f"amplitude and period steady within {100 * STEADY:g} % over the last three quarters"
    if (a.amplitude - b.amplitude) * (b.amplitude - c.amplitude) < 0 and da < 0.2 and drift <= STEADY:
        return None, (f"period steady within {100 * STEADY:g} %; amplitude varies {100 * da:.2g} % between "
                      f"the last three quarters without a trend (least-squares drift of the cycles {100 * drift:.2g} %)")
    d1, d2 = b.amplitude - c.amplitude, a.amplitude - b.amplitude
    if d1 * d2 > 0 and abs(d2) < 0.8 * abs(d1):  # converging geometrically: the rest of the way is d2 r/(1-r)
        r = d2 / d1
        rest = abs(d2) * r / (1.0 - r) / a.amplitude
        if rest <= STEADY:
            return None, (f"period steady within {100 * STEADY:g} %; amplitude converging (the quarters' changes "
                          f"shrink by {r:.2g}; the limit lies within {100 * rest:.2g} % of the last quarter's)")
    if da < 0.2 and drift > STEADY:
        return f"the amplitude varies {100 * da:.2g} % and drifts {100 * drift:.2g} % over the last three quarters", ""
    return f"the amplitude still changes {100 * da:.2g} % between the last three quarters", ""


def _ranges(ta: np.ndarray, ya: np.ndarray, span: float, min_amplitude: float, scale: float,
            final: float) -> tuple[list[float], float, float]:
    """The peak-to-peak ranges of the last, second-last and third-last quarters, their largest change between
    neighbours relative to the last, and the floor a sustained range must exceed (the settled rule's)."""
    spans = [float(np.ptp(ya[(ta >= ta[-1] - k * span / 4) & (ta < ta[-1] - (k - 1) * span / 4 + 1e-12)]))
             for k in (1, 2, 3)]
    change = max(abs(spans[0] - spans[1]), abs(spans[1] - spans[2])) / max(spans[0], 1e-300)
    return spans, change, 2 * max(min_amplitude, 1e-9 * (scale + abs(final)))


def _excursion_grows(ta: np.ndarray, ya: np.ndarray, end: float, scale: float) -> bool:
    """The largest distance from the reference over the last quarter is more than 10 steps and 1.3
    times that over the second quarter: a drift, or an oscillation growing without a bound."""
    span = ta[-1] - ta[0]
    last = np.abs(ya[ta >= ta[-1] - span / 4] - end)
    second = np.abs(ya[(ta >= ta[0] + span / 4) & (ta < ta[0] + span / 2)] - end)
    return bool(last.size and second.size and last.max() > 10 * scale and last.max() > 1.3 * second.max())


def _growing(ta: np.ndarray, ya: np.ndarray, end: float, scale: float, min_amplitude: float) -> tuple[bool, str, int]:
    """(grows, why, cycles): the growth rule of :func:`judge` on one record."""
    half = _oscillation(ta, ya, window=(ta[-1] - ta[0]) / 2, min_amplitude=min_amplitude)
    grows = (half.diverging or _excursion_grows(ta, ya, end, scale)) and _new_record(ta, ya, end)
    why = half.reason if half.diverging else "the distance from the reference grows past 10 steps"
    return grows, why, half.cycles


def _new_record(ta: np.ndarray, ya: np.ndarray, end: float) -> bool:
    """The largest distance from the reference over the last quarter exceeds 1.1 times the largest
    before it (a bounded, bursting oscillation sets no new record; a growing one does)."""
    last = ta >= ta[-1] - (ta[-1] - ta[0]) / 4
    before = np.abs(ya[~last] - end)
    return bool(before.size and np.max(np.abs(ya[last] - end)) > 1.1 * np.max(before))


def judge(result: SimResult, t_step: float, step: tuple[float, float], metrics: NonlinearStepMetrics,
          min_amplitude: float = 0.0, previous: Judgement | None = None, last_run: bool = False,
          actuator: Sequence[Any] = (), unseen_root: bool = False) -> Judgement:
    """Does this run decide? (The rules are in the module docstring.)

    Parameters
    ----------
    result : SimResult
    t_step : float
        Time of the step (s).
    step : (float, float)
        Reference before and after the step (output units).
    metrics : NonlinearStepMetrics
        Its step metrics, with the limit cycle examined over the last quarter of the run.
    min_amplitude : float
        Smallest oscillation that counts (output units).
    previous : Judgement, optional
        The judgement of the previous (half as long) run: a second growing run confirms divergence.
    last_run : bool
        No longer run will follow (the cap): with no previous run, growth over the run and over its
        first half confirms divergence.
    actuator : sequence of Block
        The loop's actuator chain: a still output is not settled while the command winds behind a block
        that holds it only for a while (a dead zone, backlash, quantizer, relay).
    unseen_root : bool
        The loop has linear blocks only and a closed-loop root on or right of the imaginary axis
        (:func:`synth.sim.hidden_mode.unseen_root`): a still output over a command that does not die out is that
        root, which the output does not see (:func:`synth.sim.hidden_mode.hidden_drift`): not settled; on two runs
        in a row, diverging.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.simulator import simulate_step
    >>> r = simulate_step(NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1})), 0, 1, 2.0)
    >>> judge(r, 0.0, (0.0, 1.0), nonlinear_step_metrics(r, window=0.5)).criterion  # still moving at 2 s
    'the last quarter is 1.5 % of the step from its final value (settled needs 0.01 %)'
    """
    scale = abs(step[1] - step[0]) or 1.0
    t, y = result.t, result.output
    after = t >= t_step - 1e-12
    ta, ya = t[after], y[after]
    if not np.all(np.isfinite(ya)) or np.max(np.abs(ya - ya[0])) > 1e9 * scale:
        return Judgement("diverging", "the output left every bound (not finite or 1e9 times the step)", 0, True)
    span = float(ta[-1] - ta[0])
    grows, why, cycles = _growing(ta, ya, step[1], scale, min_amplitude)
    if grows:
        if previous is not None and previous.growing:
            return Judgement("diverging", f"grows on two horizons in a row ({why})", cycles, True)
        if last_run and previous is None:  # no longer run allowed: its first half stands for the previous one
            early = ta <= ta[0] + span / 2
            if _growing(ta[early], ya[early], step[1], scale, min_amplitude)[0]:
                return Judgement("diverging", f"grows over the run and over its first half ({why})", cycles, True)
        return Judgement(None, f"growing ({why}); confirming on a longer horizon", cycles, True)
    a = metrics.limit_cycle
    if not a.present and a.reason.startswith("irregular"):
        cut = ta < ta[-1] - span / 4
        last = ~cut & (ta >= ta[-1] - span / 4)
        pa = autocorrelation_period(ta[last], ya[last], min_amplitude)
        pb = autocorrelation_period(ta[cut & (ta >= ta[-1] - span / 2)], ya[cut & (ta >= ta[-1] - span / 2)], min_amplitude)
        if pa and pb and abs(pa[0] - pb[0]) <= STEADY * pa[0] and abs(pa[1] - pb[1]) <= STEADY * pa[1]:
            return Judgement("limit_cycle", f"the last two quarters repeat with period {pa[0]:.4g} s (autocorrelation "
                             "above 0.98; the waveform crosses its mean more than twice per period) and equal "
                             f"amplitudes within {100 * STEADY:g} %", int(span / 2 / pa[0]))
        spans, change, floor = _ranges(ta, ya, span, min_amplitude, scale, metrics.final_value)
        if min(spans) > floor and change <= 0.1 and a.cycles >= 3:
            return Judgement("limit_cycle", f"a sustained irregular oscillation: its peak-to-peak range is equal within "
                             f"{100 * change:.2g} % over the last three quarters ({a.cycles} cycles of mean period "
                             f"{a.period:.4g} s in the last); its waveform does not repeat exactly", a.cycles)
    if a.present:
        cut = ta < ta[-1] - span / 4
        b = _oscillation(ta[cut], ya[cut], window=span / 4, min_amplitude=min_amplitude)
        cycles = a.cycles + b.cycles
        if cycles < MIN_CYCLES:
            return Judgement(None, f"only {cycles} cycles in the last half (need {MIN_CYCLES})", cycles)
        cut2 = ta < ta[-1] - span / 2
        c = _oscillation(ta[cut2], ya[cut2], window=span / 4, min_amplitude=min_amplitude)
        sizes = tuple(_mean_cycle(ta[(ta >= ta[-1] - k * span / 4) & (ta <= ta[-1] - (k - 1) * span / 4)],
                                  ya[(ta >= ta[-1] - k * span / 4) & (ta <= ta[-1] - (k - 1) * span / 4)])
                      for k in (1, 2, 3))
        why, how = _steady(a, b, c, _drift(ta, ya), sizes)  # type: ignore[arg-type]
        if why is not None and why.startswith("the period still") and not a.periodic:  # quasi-periodic chatter: the
            spans, change, floor = _ranges(ta, ya, span, min_amplitude, scale, metrics.final_value)  # irregular rule
            if min(spans) > floor and change <= 0.1 and (spans[0] - spans[1]) * (spans[1] - spans[2]) <= 0:
                return Judgement("limit_cycle", f"a sustained oscillation whose cycles do not repeat ({why}): its "
                                 f"peak-to-peak range is equal within {100 * change:.2g} % over the last three quarters "
                                 "without a trend", cycles)
        if why is None:
            why = centre_drift(ta, ya, ya, "output") or centre_drift(ta, ya, result.command[after],
                                                                      "controller's command")
        if why is not None:
            return Judgement(None, why, cycles)
        return Judgement("limit_cycle", f"{how} ({span / 4:.3g} s each)", cycles)
    quarter = ta >= ta[-1] - span / 4
    previous_quarter = (ta >= ta[-1] - span / 2) & ~quarter
    yq = ya[quarter] - metrics.final_value
    off = float(np.max(np.abs(yq)))
    if off > max(SETTLED * scale, min_amplitude):
        return Judgement(None, f"the last quarter is {100 * off / scale:.2g} % of the step from its final value "
                         f"(settled needs {100 * SETTLED:g} %)", a.cycles)
    trend, ripple = _trend(ta[quarter], ya[quarter])
    if trend > SETTLED * scale and trend > ripple:  # min_amplitude floors a ripple, not a steady creep
        return Judgement(None, f"the output still creeps by {100 * trend / scale:.2g} % of the step over the last "
                         f"quarter (a trend, its ripple about it {100 * ripple / scale:.2g} %; settled needs "
                         f"{100 * SETTLED:g} %)", a.cycles)
    late, early = float(np.ptp(ya[quarter])), float(np.ptp(ya[previous_quarter]))
    quiet = max(2 * min_amplitude, 1e-9 * (scale + abs(metrics.final_value)))
    if late > quiet and late > 0.5 * early:
        return Judgement(None, f"the motion over the last quarter is {late / max(early, 1e-300):.2g} times that "
                         "over the quarter before (settled needs 0.5)", a.cycles)
    eighth = ta >= ta[-1] - span / 8
    last8, before8 = float(np.ptp(ya[eighth])), float(np.ptp(ya[quarter & ~eighth]))
    if last8 > quiet and last8 > SHRINK * before8:
        return Judgement(None, f"the motion over the last eighth is {last8 / max(before8, 1e-300):.2g} times that "
                         f"over the eighth before (settled needs {SHRINK:g}: still shrinking, not a sustained "
                         "small oscillation)", a.cycles)
    held = winding_behind(result, after, span, actuator, SHRINK)
    if held is not None:
        return Judgement(None, held.text, a.cycles, wait=held.wait)
    hidden = hidden_drift(result, after, span) if unseen_root else None
    if hidden is not None:
        if previous is not None and previous.growing:
            return Judgement("diverging", f"on two horizons in a row, {hidden.text()}", a.cycles, True)
        if last_run and previous is None and hidden_drift(result, after & (t <= ta[0] + span / 2), span / 2) is not None:
            return Judgement("diverging", f"over the run and over its first half, {hidden.text()}", a.cycles, True)
        return Judgement(None, f"{hidden.text()}; confirming on a longer horizon", a.cycles, True)
    return Judgement("settled", f"within {100 * SETTLED:g} % of the step over the last {span / 4:.2g} s, "
                     f"its motion at most half that of the quarter before and still shrinking", a.cycles)


def _own_rest(loop: NonlinearLoop, start: float, end: float, plan: Any, seed: int) -> float:
    """Seconds to run at the starting reference before t = 0 (0 where the loop's rest with its blocks taken as
    the identity holds with the blocks: a saturation, dead zone or quantizer that changes the rest command
    moves the loop at once)."""
    from synth.sim.simulator import simulate_step

    probe = simulate_step(loop, start, start, PROBE_SAMPLES * loop.dt, 0.0, (), seed)
    scale = abs(end - start) or max(abs(start), 1.0)
    if float(np.max(np.abs(probe.output - probe.output[0]))) <= 1e-9 * scale or plan.settle_time is None:
        return 0.0
    return max(2.0 * plan.settle_time, PROBE_SAMPLES * loop.dt)


def _trend(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """The change of the least-squares line through ``y`` over ``t``, and the peak-to-peak range about it."""
    if t.size < 3:
        return 0.0, 0.0
    slope, offset = np.polyfit(t - t[0], y, 1)
    return abs(float(slope) * float(t[-1] - t[0])), float(np.ptp(y - (offset + slope * (t - t[0]))))


def default_cap(loop: NonlinearLoop, first: float) -> float:
    """The longest horizon :func:`step_verdict` tries by default: 64 times the first horizon, 200
    times the slowest plant time constant (``1/|p|`` of its slowest non-zero pole), at least 60 s,
    and at most :data:`MAX_SAMPLES` samples.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> default_cap(NonlinearLoop(Plant.from_string("1/(s+0.5)"), Controller("P", {"kp": 1})), 2.0)
    400.0
    """
    poles = np.abs(np.roots(np.asarray(loop.plant.den, float)))
    poles = poles[poles > 1e-12]
    slow = 200.0 / float(np.min(poles)) if poles.size else 0.0
    return float(min(max(64 * first, slow, 60.0), MAX_SAMPLES * loop.dt))


#: samples after the step a verdict needs at least (its rules compare quarters of the run after the step)
MIN_SAMPLES_AFTER_STEP = 8


def step_verdict(loop: NonlinearLoop, start: float, end: float, t_step: float = 0.0, horizon: float | None = None,
                 max_horizon: float | None = None, disturbances: Sequence[Any] = (), seed: int = 0,
                 min_amplitude: float = 0.0, window: float | None = None) -> StepVerdict:
    """Simulate a step until the run decides: settled, limit cycle, diverging, or undetermined.

    Parameters
    ----------
    loop : NonlinearLoop
    start, end : float
        Reference before and after the step (absolute output units).
    t_step : float
        Time of the step (s).
    horizon : float, optional
        First horizon (s); default from the loop's dynamics (:func:`~synth.sim.horizon.plan_horizon`).
    max_horizon : float, optional
        Cap (s); default :func:`default_cap`.
    disturbances, seed
        As in :func:`synth.sim.simulator.simulate`.
    min_amplitude : float
        Smallest oscillation that counts as a limit cycle (output units).
    window : float, optional
        Seconds at the end examined for the reported oscillation (default: the last half of the run
        for a limit cycle, whose two quarters the verdict found equal; else the last quarter).

    Returns
    -------
    StepVerdict

    Examples
    --------
    The issue's loop: P(20) on ``1/(s(s+1)(s+2))`` with the actuator saturated at +-1; no horizon
    given, the saturation's cycle is found and measured:

    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.blocks import Saturation
    >>> loop = NonlinearLoop(Plant.from_string("1/(s*(s+1)*(s+2))"), Controller("P", {"kp": 20}),
    ...                      actuator=[Saturation(-1, 1)], dt=0.001)
    >>> v = step_verdict(loop, 0.0, 0.1)
    >>> v.verdict, round(v.metrics.limit_cycle.amplitude, 3), round(v.metrics.limit_cycle.period, 2)
    ('limit_cycle', 0.217, 4.53)
    >>> short = step_verdict(loop, 0.0, 0.1, max_horizon=5.0)
    >>> short.verdict, short.evidence.horizons, short.summary()[:24]
    ('undetermined', (5.0,), 'undetermined within 5 s:')
    """
    from synth.sim.simulator import simulate_step

    if horizon is not None and not (np.isfinite(horizon) and horizon > t_step):
        raise ModelError(f"horizon must be a finite number of seconds after the step ({t_step:g} s), got {horizon!r}")
    if not (np.isfinite(start) and np.isfinite(end) and np.isfinite(t_step)):
        raise ModelError(f"the step {start!r} -> {end!r} at {t_step!r} s must be finite")
    plan = plan_horizon(loop, t_step, horizon)
    first = plan.horizon
    cap = max_horizon if max_horizon is not None else default_cap(loop, first)
    if not (np.isfinite(cap) and cap > t_step):
        raise ModelError(f"max_horizon must be a finite number of seconds after the step, got {max_horizon!r}")
    for name, value in (("horizon", horizon), ("max_horizon", cap)):
        if value is not None and (value - t_step) / loop.dt < MIN_SAMPLES_AFTER_STEP:
            raise ModelError(f"{name} {value:g} s leaves {max(0.0, (value - t_step) / loop.dt):.3g} samples of "
                             f"{loop.dt:g} s after the step; a verdict needs at least {MIN_SAMPLES_AFTER_STEP}")
    if cap / loop.dt > 50 * MAX_SAMPLES:
        raise ModelError(f"max_horizon {cap:g} s is {cap / loop.dt:.3g} samples of {loop.dt:g} s; "
                         f"at most {50 * MAX_SAMPLES:.3g}")
    T = min(first, cap)
    tried: list[float] = []
    previous: Judgement | None = None
    settle = _own_rest(loop, start, end, plan, seed)
    while True:
        tried.append(T)
        result = simulate_step(loop, start, end, T, t_step, disturbances, seed, settle)
        metrics = nonlinear_step_metrics(result, t_step, min_amplitude=min_amplitude, hysteresis=SAMPLED_HYSTERESIS,
                                         whole_cycles=True, step_size=end - start,
                                         window=window if window is not None else (T - t_step) / 4)
        j = judge(result, t_step, (start, end), metrics, min_amplitude, previous, T >= cap * (1 - 1e-12),
                  loop.actuator, unseen_root(loop, plan.linear_stable))
        linear_settles = t_step + plan.settle_time if plan.settle_time is not None else None
        if j.verdict == "settled" and linear_settles is not None and T < min(linear_settles, cap):
            # a slow mode under a small creep (a quantizer's still reading holds the command): not before the
            # linear loop itself settles
            j = Judgement(None, f"{j.criterion}, but the linear loop settles only after {linear_settles:.3g} s",
                          j.cycles)
        if j.verdict is None and T >= cap * (1 - 1e-12) and max_horizon is None and np.isfinite(j.wait):
            # the output waits behind a block the winding command leaves within j.wait: the default cap gives way
            # to a run that sees it let go, as far as the sample cap allows
            cap = max(cap, min(T + 2.0 * j.wait, MAX_SAMPLES * loop.dt))
        if j.verdict is not None or T >= cap * (1 - 1e-12):
            break
        previous = j
        T = min(2 * T, cap)
    if j.verdict == "limit_cycle" and window is None:  # steady over the last half: measure it there
        metrics = nonlinear_step_metrics(result, t_step, min_amplitude=min_amplitude, hysteresis=SAMPLED_HYSTERESIS,
                                         whole_cycles=True, window=(T - t_step) / 2, step_size=end - start)
    if j.verdict == "limit_cycle":  # periodic, or not (with its ranges); a complex waveform by autocorrelation
        span = (T - t_step) / 2 if window is None else window
        keep = result.t >= T - span
        metrics = dataclasses.replace(metrics, settling_time=None, limit_cycle=measure_cycle(
            result.t[keep], result.output[keep], metrics.limit_cycle, j.cycles, min_amplitude))
    verdict = j.verdict or "undetermined"
    short = short_of_reference(result, t_step, (start, end)) if verdict == "settled" else None
    criterion = j.criterion + (f"; {short}" if short else "")
    if settle:
        criterion += (f"; the loop's blocks hold it off its linear rest at the starting reference {start:.6g}, so "
                      f"it ran {settle:.3g} s at that reference before t = 0 to find its own rest")
    if verdict == "settled" and start == end and plan.linear_stable is False and not np.any(result.output
                                                                                           != result.output[0]):
        verdict = "undetermined"  # nothing moved the loop off an equilibrium its linear part does not hold
        criterion = ("the reference does not step and nothing moved the loop from rest, while its linear part is "
                     "unstable: whether it stays there is not shown (give a step, or a disturbance)")
    evidence = Evidence(float(result.t[-1]), loop.dt, int(result.t.size), j.cycles, tuple(tried), float(cap),
                        criterion, plan)
    return StepVerdict(verdict, evidence, metrics, result)


def warm_up() -> None:
    """Run one short saturated step to its verdict: numba loads the compiled simulation and cycle-detection
    kernels from its disk cache (about 0.3 s on first use in a process). The design command does this on
    one core while the design runs on the other, so that its report's simulations start warm.

    Examples
    --------
    >>> warm_up()
    """
    from synth.controllers import Controller
    from synth.plant import Plant
    from synth.sim.blocks import Saturation

    loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 2.0}), actuator=[Saturation(-1, 1)],
                         dt=0.01)
    step_verdict(loop, 0.0, 1.0, max_horizon=2.0)
