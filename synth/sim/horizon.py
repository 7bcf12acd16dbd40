"""How long to simulate a step before judging it: a first horizon read from the loop's dynamics.

Three things set it, and each is kept as evidence:

* the **slowest closed-loop mode that shows** in the linear loop (every nonlinear block
  off, the delay as a (2, 2) Pade approximant): the time at which the envelope
  ``sum |r_i| exp(Re(p_i) t)`` of the step response's modes falls below 0.2 % of the step (a
  slow pole almost cancelled by a zero has a small residue and does not count);
* the **describing-function period**: a limit cycle of a memoryless odd nonlinearity (saturation,
  dead zone, relay, quantizer) sits where the sampled loop's phase is -180 deg; the longest such
  period is taken, and the horizon holds :data:`CYCLES` of it (so the last half holds enough whole
  cycles to measure an amplitude and a period);
* the **step schedule**: the step time is added.

A horizon the user gave (``--horizon``, ``simulation.horizon``) is taken as the first horizon
instead; either way the verdict extends it when it does not decide.

:func:`synth.sim.verdict.step_verdict` starts there and doubles until the verdict is determined.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

__all__ = ["CYCLES", "HorizonPlan", "linear_loop_stable", "plan_horizon"]

CYCLES = 14
"""Whole periods of the describing-function cycle the first horizon holds."""

_ENVELOPE = 2e-3


@dataclass(frozen=True)
class HorizonPlan:
    """The first horizon and why.

    Attributes
    ----------
    horizon : float
        First simulated time (s), from 0 (the step is at ``t_step``).
    slowest_mode : float or None
        Time constant of the slowest visible closed-loop mode of the linear loop (s); None when
        the linear loop is unstable.
    linear_stable : bool
        The linear loop (every nonlinear block off) is stable.
    settle_time : float or None
        When the linear step response's mode envelope falls below 0.2 % of the step (s).
    cycle_period : float or None
        Longest period at which the sampled loop's phase is -180 deg (s): where a limit cycle of a
        memoryless nonlinearity would sit.
    reason : str
        Which of these set the horizon.
    """

    horizon: float
    slowest_mode: float | None
    linear_stable: bool
    settle_time: float | None
    cycle_period: float | None
    reason: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict.

        Examples
        --------
        >>> HorizonPlan(10.0, 1.0, True, 6.9, None, "linear settling").to_dict()["horizon"]
        10.0
        """
        return asdict(self)


def _pade22(delay: float) -> tuple[np.ndarray, np.ndarray]:
    a = delay * delay / 12.0
    return np.array([a, -delay / 2.0, 1.0]), np.array([a, delay / 2.0, 1.0])


def _closed_loop(loop: Any) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of the linear loop's reference-to-output transfer function."""
    nc, dc = loop.controller.tf()
    ng, dg = np.asarray(loop.plant.num, float), np.asarray(loop.plant.den, float)
    num = np.polymul(nc, ng)
    den_open = np.polymul(dc, dg)
    delay = float(loop.total_delay)
    if delay > 0:
        pn, pd = _pade22(delay)
        num, den_open = np.polymul(num, pn), np.polymul(den_open, pd)
    return num, np.polyadd(den_open, num)


def _linear_settling(loop: Any) -> tuple[bool, float | None, float | None]:
    """(stable, slowest visible time constant, envelope time) of the linear step response."""
    num, den = _closed_loop(loop)
    den = np.trim_zeros(den, "f")
    if den.size < 2:
        return True, None, 0.0
    poles = np.roots(den)
    if np.any(poles.real >= -1e-9 * (1 + np.abs(poles))):
        return False, None, None
    dden = np.polyder(den)
    dc = np.polyval(num, 0.0) / np.polyval(den, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):  # a repeated pole has no simple residue
        res = np.abs(np.polyval(num, poles) / (np.polyval(dden, poles) * poles)) / max(abs(dc), 1e-12)
    res = np.where(np.isfinite(res), res, 1.0)  # counted as a visible mode of the step's size
    visible = res > _ENVELOPE / max(len(poles), 1)
    taus = -1.0 / poles.real
    slowest = float(np.max(taus[visible])) if np.any(visible) else float(np.max(taus))
    grid = np.geomspace(1e-3 * float(np.min(taus)), 50 * float(np.max(taus)), 400)
    env = (res[None, :] * np.exp(np.outer(grid, poles.real))).sum(axis=1)
    below = np.nonzero(env <= _ENVELOPE)[0]
    t_env = float(grid[below[0]]) if below.size else float(grid[-1])
    return True, slowest, t_env


def _cycle_period(loop: Any) -> float | None:
    """Longest period where the sampled loop's phase crosses -180 deg (None if it never does)."""
    from synth.sim.describing import sampled_loop_response

    w = np.geomspace(1e-3, 0.999 * np.pi / loop.dt, 1500)
    with np.errstate(all="ignore"):
        L = sampled_loop_response(loop, w)
    ok = np.isfinite(L) & (np.abs(L) > 0)
    if ok.sum() < 2:
        return None
    w, L = w[ok], L[ok]
    im = L.imag
    cross = np.nonzero((np.sign(im[:-1]) != np.sign(im[1:])) & (L.real[:-1] < 0) & (L.real[1:] < 0))[0]
    if cross.size == 0:
        return None
    i = int(cross[0])
    wc = w[i] + (w[i + 1] - w[i]) * im[i] / (im[i] - im[i + 1])
    return float(2 * np.pi / wc)


def linear_loop_stable(loop: Any) -> bool:
    """Whether the loop's linear part (its blocks left out) has every closed-loop root left of the imaginary axis,
    the roots a controller pole cancelled by a plant zero included.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.loops import NonlinearLoop
    >>> pi = Controller("PI", {"kp": 1, "ki": 1})
    >>> linear_loop_stable(NonlinearLoop(Plant.from_string("1/(s+1)^2"), pi))
    True
    >>> linear_loop_stable(NonlinearLoop(Plant.from_string("s/(s+1)^2"), pi))  # the integrator on the zero at 0
    False
    """
    return _linear_settling(loop)[0]


def plan_horizon(loop: Any, t_step: float = 0.0, given: float | None = None) -> HorizonPlan:
    """The first horizon for a step at ``t_step`` of ``loop``, from its dynamics.

    Parameters
    ----------
    loop : NonlinearLoop
    t_step : float
        Time of the step (s).
    given : float, optional
        A horizon the user asked for (s): it is the first horizon (the dynamics are still
        described in the plan).

    Examples
    --------
    The issue's loop: the linear loop is unstable, the saturation holds a cycle at the -180 deg
    frequency (1.41 rad/s, 4.4 s):

    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.loops import NonlinearLoop
    >>> from synth.sim.blocks import Saturation
    >>> loop = NonlinearLoop(Plant.from_string("1/(s*(s+1)*(s+2))"), Controller("P", {"kp": 20}),
    ...                      actuator=[Saturation(-1, 1)], dt=0.001)
    >>> plan = plan_horizon(loop)
    >>> plan.linear_stable, round(plan.cycle_period, 2), round(plan.horizon, 1)
    (False, 4.45, 62.2)
    >>> plan_horizon(NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}))).reason
    'linear loop settles (0.2 % of the step) after 3.2 s; slowest visible mode 0.5 s'
    """
    stable, slowest, t_env = _linear_settling(loop)
    period = _cycle_period(loop) if any(not b.linear for b in (*loop.actuator, *loop.sensor)) or not stable \
        else None
    parts, reasons = [], []
    if stable and t_env is not None:
        parts.append(1.5 * t_env)
        reasons.append(f"linear loop settles (0.2 % of the step) after {t_env:.2g} s; slowest visible mode "
                       f"{slowest:.2g} s")
    elif not stable:
        reasons.append("linear loop unstable")
    if period is not None and (not stable or any(not b.linear for b in loop.actuator)):
        parts.append(CYCLES * period)
        reasons.append(f"{CYCLES} periods of the -180 deg frequency ({period:.3g} s)")
    if not parts:
        poles = np.roots(np.asarray(loop.plant.den, float))
        fastest = [abs(p) for p in poles if abs(p) > 0]
        parts.append(20.0 / min(fastest) if fastest else 10.0)
        reasons.append("20 times the slowest plant time constant")
    horizon = max(t_step + max(parts), t_step + 20 * loop.dt)
    if given is not None:
        horizon = float(given)
        reasons.insert(0, f"the given horizon {horizon:g} s")
    return HorizonPlan(float(horizon), slowest, stable, t_env, period, "; ".join(reasons))
