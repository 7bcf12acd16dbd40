"""The sampled nonlinear closed loop (and open loop) of a plant, a controller and block chains.

The plant (rational part and exact delay) is discretized exactly for a
piecewise-constant input (zero-order hold); a delay that is not a whole
number of steps is handled exactly too (:mod:`synth.sim.discretize`).
Linear blocks next to the plant (the trailing end of the actuator chain, the
leading end of the sensor chain) are folded into the same exact
discretization, so a motor lag or a sensor filter costs no accuracy. The
controller is discretized at its own rate (Tustin by default) and its output
held between updates. Signals are in absolute units: the controller's output
is added to the operating-point input, the linear plant model acts on
deviations from the operating point, and its output is added to the
operating-point output.

The loop starts at rest: every state is set to the steady state of the loop
with each nonlinear block replaced by the identity at the initial reference
(give ``settle`` seconds to let the nonlinear loop find its own rest first).

Sampling convention: the output is sampled at ``k dt`` just before the
controller's new value takes effect (a biproper plant's direct feedthrough
therefore sees the previous input; there is no algebraic loop).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.plant import Plant
from synth.sim.blocks import Block
from synth.sim.loops import NonlinearLoop, OpenLoop, OperatingPoint
from synth.sim.results import BatchResult, SimResult
from synth.sim.signals import Reference
from synth.sim.variants import run_variants

__all__ = ["simulate", "simulate_batch", "simulate_open_loop", "simulate_open_loop_batch", "simulate_step"]


def simulate(loop: NonlinearLoop, reference: Reference, t_end: float, disturbances: Sequence[Any] = (),
             seed: int = 0, settle: float = 0.0) -> SimResult:
    """Simulate the sampled closed loop from 0 to ``t_end`` seconds.

    Parameters
    ----------
    loop : NonlinearLoop
    reference : float, array or callable
        Reference in absolute output units: a constant, one value per step
        (``round(t_end/dt) + 1`` values) or a function of the time array.
    t_end : float
        Simulated time (s).
    disturbances : sequence
        :class:`~synth.sim.signals.PsdDisturbance`, :class:`~synth.sim.signals.RecordDisturbance`
        or :class:`~synth.sim.signals.StepDisturbance` objects (at the plant input or output).
    seed : int
        Seed of every random signal (noise blocks, PSD disturbances).
    settle : float
        Seconds simulated before ``t = 0`` at the initial reference and dropped.

    Returns
    -------
    SimResult

    Examples
    --------
    >>> from synth.controllers import Controller
    >>> from synth.sim.blocks import RateLimit, Saturation
    >>> from synth.sim.signals import step_reference
    >>> loop = NonlinearLoop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 3}),
    ...                      actuator=[RateLimit(10000), Saturation(0, 255)],
    ...                      operating_point=OperatingPoint(200, 870))
    >>> r = simulate(loop, step_reference(820, 920), 0.5)
    >>> round(float(r.output[0]), 2), round(float(r.output[-1]), 2)  # P control: steady-state error
    (827.44, 914.64)
    >>> round(r.time_active("saturated"), 3)  # the step asks for 477 PWM; 255 is the top
    0.05
    """
    return run_variants([loop], 0, [reference], t_end, disturbances, seed, settle)[0]


def simulate_step(loop: NonlinearLoop, start: float, end: float, t_end: float, t_step: float = 0.0,
                  disturbances: Sequence[Any] = (), seed: int = 0, settle: float = 0.0) -> SimResult:
    """Response to a reference step from ``start`` to ``end`` (absolute output units) at ``t_step``,
    starting at rest at ``start``.

    Examples
    --------
    >>> from synth.controllers import Controller
    >>> loop = NonlinearLoop(Plant.from_string("10/(s+10)"), Controller.from_string("PI(1, 10)"))
    >>> r = simulate_step(loop, 0.0, 2.0, 1.0, t_step=0.1)
    >>> float(r.output[100]), round(float(r.output[-1]), 4)
    (0.0, 2.0)
    """
    from synth.sim.signals import step_reference

    return simulate(loop, step_reference(start, end, t_step), t_end, disturbances, seed, settle)


def simulate_batch(loops: Sequence[NonlinearLoop], reference: Reference | Sequence[Reference], t_end: float,
                   disturbances: Sequence[Any] = (), seed: int = 0, settle: float = 0.0) -> BatchResult:
    """Simulate many variants at once (sweeps, Monte Carlo): one compiled call for the batch.

    Variants may differ in anything (plant, controller, blocks, delay) except ``dt``. Random
    signals of variant ``i`` use the seed ``[seed, i]``: reproducible and independent.

    Parameters
    ----------
    loops : sequence of NonlinearLoop
    reference : reference, list of references or 2-D array
        One reference for all (a constant, a 1-D array of samples or a callable), or one per
        variant (a list, or one row per variant).

    Examples
    --------
    >>> from synth.controllers import Controller
    >>> base = NonlinearLoop(Plant.from_string("10/(s+10)"), Controller("P", {"kp": 1}))
    >>> batch = simulate_batch([base.with_gain("kp", k) for k in (1, 4, 9)], 1.0, 1.0)
    >>> batch.output[:, -1].round(3).tolist()  # K G0/(1 + K G0)
    [0.5, 0.8, 0.9]
    """
    loops = list(loops)
    if isinstance(reference, list | tuple):
        refs = list(reference)
        if len(refs) != len(loops):
            raise ModelError(f"{len(refs)} references for {len(loops)} variants")
    elif isinstance(reference, np.ndarray) and reference.ndim == 2:
        refs = list(reference)
        if len(refs) != len(loops):
            raise ModelError(f"{len(refs)} references for {len(loops)} variants")
    else:
        refs = [reference] * len(loops)
    return run_variants(loops, 0, refs, t_end, disturbances, seed, settle)


def simulate_open_loop(plant: Plant, u: Any, dt: float, actuator: Sequence[Block] = (),
                       sensor: Sequence[Block] = (), operating_point: OperatingPoint | None = None,
                       delay: float = 0.0, disturbances: Sequence[Any] = (), seed: int = 0) -> SimResult:
    """Drive ``u -> actuator blocks -> plant -> sensor blocks -> y`` with a sampled input record.

    The input is absolute (e.g. PWM) and held constant over each step ``dt``; the plant model
    acts on its deviation from ``operating_point.input`` and its output is added to
    ``operating_point.output``. The chain starts at rest at the first input value. This is the
    model a measured input record is pushed through to compare with the measured output.

    Parameters
    ----------
    plant : Plant
    u : array_like
        Input samples, one per step.
    dt : float
        Sample time (s).
    actuator, sensor : sequence of Block
    operating_point : OperatingPoint, optional
    delay : float
        Extra delay (s) besides the plant's.
    disturbances, seed
        As in :func:`simulate`.

    Examples
    --------
    >>> from synth.sim.blocks import RateLimit
    >>> G = Plant.from_string("1/(0.01*s+1)")
    >>> r = simulate_open_loop(G, [0.0] + [1.0] * 200, 0.001, actuator=[RateLimit(50.0)])
    >>> r.actuator[:4].tolist(), round(float(r.output[-1]), 3)
    ([0.0, 0.05, 0.1, 0.15], 1.0)
    """
    u = np.asarray(u, float).ravel()
    if u.size < 2:
        raise ModelError("the input record needs at least 2 samples")
    loop = OpenLoop(plant, tuple(actuator), tuple(sensor), float(dt), float(delay),
                    operating_point or OperatingPoint())
    if not (np.isfinite(loop.dt) and loop.dt > 0):
        raise ModelError(f"dt must be > 0 s, got {dt!r}")
    return run_variants([loop], 1, [u], (u.size - 1) * loop.dt, disturbances, seed, 0.0)[0]


def simulate_open_loop_batch(loops: Sequence[OpenLoop], u: Any, disturbances: Sequence[Any] = (),
                             seed: int = 0) -> BatchResult:
    """:func:`simulate_open_loop` for many variants (e.g. candidate augmentations) at once.

    ``u`` is one input record for all variants, or one per variant (same length).

    Examples
    --------
    >>> from synth.sim.blocks import Saturation
    >>> G = Plant.from_string("1/(0.01*s+1)")
    >>> loops = [OpenLoop(G, (Saturation(-a, a),), dt=0.001) for a in (0.5, 2.0)]
    >>> simulate_open_loop_batch(loops, [0.0] + [1.0] * 200).output[:, -1].round(3).tolist()
    [0.5, 1.0]
    """
    loops = list(loops)
    arr = np.asarray(u, float)
    records = [arr] * len(loops) if arr.ndim == 1 else list(arr)
    if len(records) != len(loops):
        raise ModelError(f"{len(records)} input records for {len(loops)} variants")
    n = records[0].size
    return run_variants(loops, 1, records, (n - 1) * loops[0].dt, disturbances, seed, 0.0)
