"""Step metrics of a simulated (nonlinear) run: the linear metrics plus the actuator's story.

Rise time (10-90 %), overshoot and settling time come from
:func:`synth.timeresp.step_metrics` applied to the true output after the
step, from its value at the step to its final value (the given value, or the record's tail
extrapolated by :func:`tail_limit`). Added here: the actuator's peak rate
and amplitude, the time spent rate-limited, saturated (and in any other
limiting state), and whether the run ends in a sustained oscillation.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from synth.sim.authority import output_still
from synth.sim.limitcycle import Oscillation, detect_oscillation
from synth.sim.results import SimResult
from synth.timeresp import StepMetrics, step_metrics

__all__ = ["MAX_TAIL_CORRECTION", "MAX_TAIL_RATIO", "TAIL_SHARE", "NonlinearStepMetrics", "nonlinear_step_metrics",
           "tail_limit", "unsettled"]


@dataclass(frozen=True)
class NonlinearStepMetrics:
    """Metrics of a simulated step response.

    Attributes
    ----------
    rise_time, overshoot, settling_time, final_value, peak
        As :class:`synth.timeresp.StepMetrics` (s, %, s, output units); settling time is None
        (not settled) when the run ends oscillating.
    initial_value : float
        Output at the step.
    actuator_peak_rate : float
        Largest ``|da/dt|`` of the actuator output (input units/s).
    actuator_max, actuator_min : float
        Extremes of the actuator output (input units).
    actuator_peak_deviation : float
        Largest ``|a - a_before|`` after the step, ``a_before`` the actuator output just before
        it (input units).
    rate_limited_time, saturated_time : float
        Seconds a rate limiter / a saturation was active after the step.
    limited_time : dict
        Seconds each kind of limiting block was active (``in_dead_zone``, ``brown_out``, ...).
    limit_cycle : Oscillation
        Whether the run ends in a sustained oscillation, its amplitude and period (output).
    """

    rise_time: float
    overshoot: float
    settling_time: float | None
    final_value: float
    peak: float
    initial_value: float
    actuator_peak_rate: float
    actuator_max: float
    actuator_min: float
    actuator_peak_deviation: float
    rate_limited_time: float
    saturated_time: float
    limited_time: dict[str, float]
    limit_cycle: Oscillation

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict; ``limit_cycle`` as ``{"present", "amplitude", "period", ...}``.

        Examples
        --------
        >>> from synth.sim.limitcycle import Oscillation
        >>> osc = Oscillation(False, 0.0, None, None, None, None, 0, None, "flat")
        >>> m = NonlinearStepMetrics(0.1, 0.0, 0.3, 1.0, 1.0, 0.0, 5.0, 1.0, 0.0, 1.0, 0.0, 0.0, {}, osc)
        >>> m.to_dict()["limit_cycle"]["present"]
        False
        """
        out = {k: getattr(self, k) for k in self.__dataclass_fields__ if k != "limit_cycle"}
        out["limit_cycle"] = self.limit_cycle.to_dict()
        return out


def unsettled(metrics: NonlinearStepMetrics) -> NonlinearStepMetrics:
    """``metrics`` of a step that does not settle (a limit cycle, a divergence, undetermined): no rise time,
    overshoot, settling time or final value (NaN, None), which would only say where the horizon cut the run.

    Examples
    --------
    >>> from synth.sim.limitcycle import Oscillation
    >>> osc = Oscillation(True, 0.2, 4.5, 0.1, None, None, 12, None, "steady")
    >>> m = NonlinearStepMetrics(0.7, 121.5, None, 0.14, 0.3, 0.0, 5.0, 1.0, -1.0, 1.0, 0.0, 9.0, {}, osc)
    >>> u = unsettled(m); u.overshoot, u.final_value, u.actuator_max
    (nan, nan, 1.0)
    """
    nan = float("nan")
    return replace(metrics, rise_time=nan, overshoot=nan, settling_time=None, final_value=nan)


TAIL_SHARE = 0.05
"""Share of the record in each of the three windows at its end whose means :func:`tail_limit` extrapolates."""

MAX_TAIL_RATIO = 0.95
"""Largest ratio of the windows' successive changes that :func:`tail_limit` extrapolates (the correction is at
most ``ratio / (1 - ratio)`` times the last change, 19 times at this ratio)."""


MAX_TAIL_CORRECTION = 1e-3
"""Largest extrapolation :func:`tail_limit` makes, as a share of the record's range: a refinement of a tail that has
nearly converged, not a forecast. A run stopped mid-transient can still have window means that shrink by a steady
ratio (the X-4 PI of ``specs/x4_rotor_pi.yaml``, saturated and winding up at its 1 s horizon, extrapolated 3.9 rad/s
beyond anything it reached, 0.8 % of its range); so can one that drifts away for ever (a diverging loop of the
simulation benchmark's seed 105, 56 %). The slow tails this is for are 1e-5 of their range from the limit."""


def tail_limit(y: np.ndarray, extrapolate: bool = True) -> float:
    """The final value of a record that still converges: the means ``m1, m2, m3`` of three consecutive windows
    at its end (:data:`TAIL_SHARE` of the record each) extrapolated as a geometric sequence (Aitken's delta
    squared: exact for a tail ``a + b exp(-t / tau)``, whose window means change by a constant ratio), when the
    changes have one sign and shrink by a ratio below :data:`MAX_TAIL_RATIO` and the extrapolation is within
    :data:`MAX_TAIL_CORRECTION` of the record's range; otherwise, or with ``extrapolate`` False (a run that ends
    oscillating or diverging), the last window's mean.
    A loop with a slow pole 11 s long, stopped at 99 s, is 4.6e-5 short of its final value on the last
    window's mean, which moved its 2 % settling time by 6 samples of 1 ms; extrapolated, it is 1.3e-8 short.

    Examples
    --------
    >>> t = np.linspace(0.0, 40.0, 4001)
    >>> y = 2.0 - np.exp(-t / 10.0)
    >>> round(float(np.mean(y[-200:])), 4), round(tail_limit(y), 9)  # the last window's mean; the limit
    (1.9797, 2.0)
    >>> tail_limit(np.ones(100))  # nothing moves: the mean
    1.0
    >>> slow = 2.0 - np.exp(-t / 30.0)  # a quarter of its range from the limit at 40 s: not extrapolated
    >>> tail_limit(slow) == float(np.mean(slow[-200:]))
    True
    """
    w = max(1, round(TAIL_SHARE * y.size))
    last = float(np.mean(y[-w:]))
    if y.size < 3 * w or not extrapolate:
        return last
    m1, m2 = float(np.mean(y[-3 * w:-2 * w])), float(np.mean(y[-2 * w:-w]))
    d1, d2 = m2 - m1, last - m2
    if d1 == 0.0 or d2 == 0.0 or (d1 > 0) != (d2 > 0) or abs(d2) >= MAX_TAIL_RATIO * abs(d1):
        return last
    q = d2 / d1
    correction = d2 * q / (1.0 - q)
    return last + correction if abs(correction) <= MAX_TAIL_CORRECTION * float(np.ptp(y)) else last


def nonlinear_step_metrics(result: SimResult, t_step: float = 0.0, final_value: float | None = None,
                           settle_band: float = 0.02, min_amplitude: float = 0.0,
                           window: float | None = None, hysteresis: float = 0.5,
                           whole_cycles: bool = False, step_size: float | None = None) -> NonlinearStepMetrics:
    """Step metrics of a simulated run whose reference steps at ``t_step``.

    Parameters
    ----------
    result : SimResult
    t_step : float
        Time of the step (s).
    final_value : float, optional
        Final value of the output (default: :func:`tail_limit` of the record after the step, or the mean over
        its last 5 % when it ends oscillating or diverging).
    settle_band : float
        Settling band as a fraction of the change.
    min_amplitude : float
        Smallest oscillation amplitude that counts as a limit cycle (output units).
    window : float, optional
        Seconds at the end examined for a limit cycle (default: the last half after the step).
    hysteresis, whole_cycles
        As in :func:`~synth.sim.limitcycle.detect_oscillation` (:func:`~synth.sim.verdict.step_verdict`
        passes :data:`~synth.sim.limitcycle.SAMPLED_HYSTERESIS` and True).
    step_size : float, optional
        The reference's change at ``t_step``: 0 leaves rise time, overshoot and settling time undefined (NaN; a run
        held at its operating point, where the output's change is rounding), as does an output that did not move
        (:func:`synth.sim.authority.output_still`: a command change inside a backlash's play).

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.blocks import RateLimit, Saturation
    >>> from synth.sim.loops import NonlinearLoop, OperatingPoint
    >>> from synth.sim.simulator import simulate
    >>> from synth.sim.signals import step_reference
    >>> loop = NonlinearLoop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3}),
    ...                      actuator=[RateLimit(10000), Saturation(0, 255)],
    ...                      operating_point=OperatingPoint(200, 870))
    >>> m = nonlinear_step_metrics(simulate(loop, step_reference(820, 920), 1.0))
    >>> round(m.rise_time, 3), round(m.actuator_peak_rate), m.limit_cycle.present
    (0.053, 10000, False)
    """
    t, y, a = result.t, result.output, result.actuator
    after = t >= t_step - 1e-12
    i0 = int(np.argmax(after))
    ta, ya = t[after], y[after]
    span = ta[-1] - ta[0]
    osc = detect_oscillation(ta, ya, window=window if window is not None else span / 2,
                             min_amplitude=min_amplitude, hysteresis=hysteresis,
                             whole_cycles=whole_cycles)
    if final_value is not None:
        yf = float(final_value)
    else:
        yf = tail_limit(ya, extrapolate=not (osc.present or osc.diverging))
    y0 = float(y[i0])
    if step_size == 0.0 or (step_size is not None and output_still(ya, y0, step_size)):
        # the reference does not step, or the output did not move: no rise, overshoot or settling to measure
        base = StepMetrics(float("nan"), float("nan"), float("nan"), yf, float(np.max(ya)))
    else:
        base = step_metrics(ta - ta[0], ya, y0=y0, y_final=yf, settle_band=settle_band)
    settling = None if (osc.present or osc.diverging or not np.isfinite(base.settling_time)) \
        else float(base.settling_time)
    before = float(a[i0 - 1]) if i0 > 0 else result.actuator_rest
    aa = a[after]
    if not np.isfinite(before):
        before = float(aa[0])
    rate = np.abs(np.diff(np.concatenate([[before], aa]))) / result.dt
    names = sorted({f for f in result.actuator_flags + result.sensor_flags if f})
    limited = {name: float(np.count_nonzero(result.active(name)[after]) * result.dt) for name in names}
    return NonlinearStepMetrics(
        rise_time=float(base.rise_time), overshoot=float(base.overshoot), settling_time=settling,
        final_value=yf, peak=float(base.peak), initial_value=y0,
        actuator_peak_rate=float(np.max(rate)) if rate.size else 0.0,
        actuator_max=float(np.max(aa)), actuator_min=float(np.min(aa)),
        actuator_peak_deviation=float(np.max(np.abs(aa - before))),
        rate_limited_time=limited.get("rate_limited", 0.0), saturated_time=limited.get("saturated", 0.0),
        limited_time=limited, limit_cycle=osc,
    )
