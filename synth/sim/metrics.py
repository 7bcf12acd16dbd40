"""Step metrics of a simulated (nonlinear) run: the linear metrics plus the actuator's story.

Rise time (10-90 %), overshoot and settling time come from
:func:`synth.timeresp.step_metrics` applied to the true output after the
step, from its value at the step to its final value (the mean over the last
5 % of the record, or the given value). Added here: the actuator's peak rate
and amplitude, the time spent rate-limited, saturated (and in any other
limiting state), and whether the run ends in a sustained oscillation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.sim.limitcycle import Oscillation, detect_oscillation
from synth.sim.results import SimResult
from synth.timeresp import StepMetrics, step_metrics

__all__ = ["NonlinearStepMetrics", "nonlinear_step_metrics"]


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


def nonlinear_step_metrics(result: SimResult, t_step: float = 0.0, final_value: float | None = None,
                           settle_band: float = 0.02, min_amplitude: float = 0.0,
                           window: float | None = None, hysteresis: float = 0.5,
                           whole_cycles: bool = False) -> NonlinearStepMetrics:
    """Step metrics of a simulated run whose reference steps at ``t_step``.

    Parameters
    ----------
    result : SimResult
    t_step : float
        Time of the step (s).
    final_value : float, optional
        Final value of the output (default: mean over the last 5 % of the record).
    settle_band : float
        Settling band as a fraction of the change.
    min_amplitude : float
        Smallest oscillation amplitude that counts as a limit cycle (output units).
    window : float, optional
        Seconds at the end examined for a limit cycle (default: the last half after the step).
    hysteresis, whole_cycles
        As in :func:`~synth.sim.limitcycle.detect_oscillation` (:func:`~synth.sim.verdict.step_verdict`
        passes :data:`~synth.sim.limitcycle.SAMPLED_HYSTERESIS` and True).

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
    tail = max(1, round(0.05 * ya.size))
    yf = float(np.mean(ya[-tail:])) if final_value is None else float(final_value)
    y0 = float(y[i0])
    base: StepMetrics = step_metrics(ta - ta[0], ya, y0=y0, y_final=yf, settle_band=settle_band)
    span = ta[-1] - ta[0]
    osc = detect_oscillation(ta, ya, window=window if window is not None else span / 2,
                             min_amplitude=min_amplitude, hysteresis=hysteresis,
                             whole_cycles=whole_cycles)
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
