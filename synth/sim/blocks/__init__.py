"""Composable actuator and sensor blocks for the sampled simulation.

Every block is a small frozen dataclass with documented parameters and one
equation, applied once per simulation step ``dt`` to a signal in **absolute**
units (the operating point added: PWM, rad/s), so limits such as 0-255 PWM
apply as written. Blocks chain in lists: an actuator chain between the
controller and the plant, a sensor chain between the plant and the
controller; the same chains serve the closed loop
(:func:`synth.sim.simulate`) and the open loop
(:func:`synth.sim.simulate_open_loop`), one variant or a batch of them.

Each block compiles to an integer code, a parameter vector and a state
vector; the step equations below are the numba functions in
:mod:`synth.sim._steps` that the simulation kernel calls. ``block.apply(x, dt)``
runs a block (or ``apply_chain`` a list) on a signal by itself.

=============  ===================================================================
type           equation per step (input ``x_k``, output ``y_k``)
=============  ===================================================================
rate_limit     ``y_k = y_{k-1} + clip(x_k - y_{k-1}, -F dt, R dt)``
saturation     ``y_k = clip(x_k, min, max)``
dead_zone      ``y_k = c`` inside ``|x_k - c| <= w``, else ``x_k -+ w``
quantizer      ``y_k = o + q round((x_k - o)/q)`` (or ``floor``)
backlash       ``y_k = clip(y_{k-1}, x_k - w, x_k + w)`` (play of total width ``2w``)
static         piecewise-linear table ``y = f(x)``, ends extrapolated
lag            ``tau y' + y = k x`` (exact zero-order-hold discretization)
dynamics       any proper ``N(s)/D(s)`` (zero-order-hold discretization)
supply_sag     ``y = x V/V_n``, ``V = V_oc - R_i I``; brown-out below ``V_reset``
sample_hold    ``y_k = x_j`` at the last sample instant ``j T <= k dt``
noise          ``y_k = x_k + n_k`` (white Gaussian or from a PSD, seeded)
delay          pure delay; pooled with the loop delay (it commutes with every
               time-invariant block)
=============  ===================================================================

The blocks live by family: :mod:`~synth.sim.blocks.chain` (the :class:`Block` interface,
:class:`Noise`, :class:`Delay`, running a chain), :mod:`~synth.sim.blocks.nonlinear`,
:mod:`~synth.sim.blocks.linear` and :mod:`~synth.sim.blocks.hardware`; their kernel layout is
:mod:`synth.sim.layout`.
"""

from __future__ import annotations

from synth.sim.blocks.chain import Block, ChainArrays, Delay, Noise, apply_chain, chain_arrays
from synth.sim.blocks.hardware import SampleHold, SupplySag
from synth.sim.blocks.linear import Dynamics, Lag
from synth.sim.blocks.nonlinear import Backlash, DeadZone, Quantizer, RateLimit, Saturation, Static

__all__ = [
    "BLOCK_TYPES", "Backlash", "Block", "ChainArrays", "DeadZone", "Delay", "Dynamics", "Lag", "Noise", "Quantizer",
    "RateLimit", "SampleHold", "Saturation", "Static", "SupplySag", "apply_chain", "chain_arrays",
]

BLOCK_TYPES: dict[str, type[Block]] = {
    cls.kind: cls
    for cls in (RateLimit, Saturation, DeadZone, Quantizer, Backlash, Static, Lag, Dynamics, SupplySag,
                SampleHold, Noise, Delay)
}
"""Every block class by its ``type:`` name."""
