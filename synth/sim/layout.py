"""How a block is laid out for the simulation kernel: its integer code and its padded vectors.

The block classes (:mod:`synth.sim.blocks`) write their parameters and initial state in this
layout; the compiled step equations (``synth.sim._steps``) and the loop kernel
(``synth.sim._kernel``) read it. Both import this module, neither imports the other's side.

Every block is an integer code, a parameter vector of length :data:`P_MAX` and a state vector
of length :data:`S_MAX` (zero-padded). Block activity is recorded per step as bits of an int32:
bit ``i`` for actuator block ``i``, bit :data:`SENSOR_BIT` ``+ i`` for sensor block ``i``.

Examples
--------
>>> from synth.sim.blocks import Saturation
>>> Saturation(0, 255).code == SATURATION, Saturation(0, 255).parameters(0.001).size == P_MAX
(True, True)
"""

from __future__ import annotations

__all__ = [
    "BACKLASH", "DEAD_ZONE", "DYNAMICS", "IDENTITY", "MAX_DYNAMICS_ORDER", "MAX_TABLE", "NOISE", "P_MAX",
    "QUANTIZER", "RATE_LIMIT", "SAMPLE_HOLD", "SATURATION", "SENSOR_BIT", "STATIC", "SUPPLY_SAG", "S_MAX",
]

P_MAX = 34
"""Length of every block's parameter vector (padded)."""
S_MAX = 8
"""Length of every block's state vector (padded; ``dynamics`` uses the upper half as scratch)."""
MAX_TABLE = 16
"""Most points of a ``static`` table."""
MAX_DYNAMICS_ORDER = 4
"""Highest order of a ``dynamics`` block that is not folded into the plant."""
SENSOR_BIT = 16
"""First activity bit of the sensor chain (actuator blocks use bits 0-15)."""

IDENTITY, RATE_LIMIT, SATURATION, DEAD_ZONE, QUANTIZER, DYNAMICS, SUPPLY_SAG, SAMPLE_HOLD, NOISE, BACKLASH, \
    STATIC = range(11)
"""The codes the kernel dispatches on (``IDENTITY`` passes the signal through: a delay block)."""
