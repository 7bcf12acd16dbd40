"""The library of effects a linear model may be missing, each a nested augmentation of it.

An effect adds one mechanism to the nominal linear model ``G`` (rational transfer function times an
exact delay) and is switched off by a parameter value, so the nominal model is nested in every
augmented one. One family per module, each effect one class that describes itself
(:class:`synth.gap.effects.base.Effect`):

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``delay``              linear    ``G exp(-d s)``                                             ``delay``
``lag``                linear    ``G / (tau s + 1)``, actuator or sensor placement            ``tau``
``resonance``          linear    ``G wn^2 / (s^2 + 2 zeta wn s + wn^2)``                      ``wn, zeta``
``rate_limit``         input     :class:`synth.sim.blocks.RateLimit` before ``G``             ``rate``
``saturation``         input     :class:`synth.sim.blocks.Saturation` before ``G``            ``lower, upper``
``saturation(output)`` output    ``min(upper, max(lower, y))`` after ``G`` (clipping, overflow) ``lower, upper``
``friction``           input     Coulomb force ``-fc sign(velocity)``, stick-slip; ``G`` to     ``fc``
                                 a position (pole at the origin) or a velocity
``deadzone``           input     :class:`synth.sim.blocks.DeadZone` before ``G``              ``width``
``backlash``           input     :class:`synth.sim.blocks.Backlash` before ``G``              ``width``
``quantization``       input     :class:`synth.sim.blocks.Quantizer` before ``G``             ``step, offset``
``supply_sag``         input     ``u - a u max(0, u - u_f)``, ``tau u_f' + u_f = u``          ``sag, tau``
``static_nonlinearity``input     ``u + a2 x^2 + a3 x^3``, ``x = (u - c)/h``                   ``a2, a3``
``drift``              output    ``y + d1 (t - t0) + d2 (t - t0)^2``                          ``slope, curvature``
``direction``          input     up/down latency, time constant and gain                      ``gain_down, tau_up,
                                                                                              tau_down, delay_up,
                                                                                              delay_down``
``duffing``            input     cubic spring ``-cubic y^3 / G(0)`` in feedback              ``cubic``
``amplitude_damping``  input     quadratic damping ``-drag y' |y'| / G(0)`` in feedback       ``drag``
``measured_sag(V)``    input     ``u + sag (u - u_rest) (V / V_nom - 1)``, ``V`` measured     ``sag``
``aux_input(d)``       input     ``u + gain (d - d_0)``, ``d`` measured                       ``gain``
=====================  ========  ===========================================================  ==============


Modules: :mod:`~synth.gap.effects.base` (the base class and shared helpers),
:mod:`~synth.gap.effects.timing` (delay, lag), :mod:`~synth.gap.effects.dynamics` (resonance),
:mod:`~synth.gap.effects.actuator` (rate limit, saturation and output clipping, dead zone, backlash),
:mod:`~synth.gap.effects.quantization`, :mod:`~synth.gap.effects.friction`,
:mod:`~synth.gap.effects.supply` (supply sag), :mod:`~synth.gap.effects.static_map` (static
nonlinearity), :mod:`~synth.gap.effects.drift`, :mod:`~synth.gap.effects.direction` (direction-dependent dynamics),
:mod:`~synth.gap.effects.amplitude` (cubic spring),
:mod:`~synth.gap.effects.damping` (amplitude-dependent damping), :mod:`~synth.gap.effects.auxiliary` (driven by a measured
channel); :mod:`~synth.gap.effects.registry` lists them
(``EFFECTS``, ``DEFAULT_CANDIDATES``, ``make_effect``). This package re-exports those names.
"""

from synth.gap.effects.actuator import BacklashEffect, DeadzoneEffect, RateLimitEffect, SaturationEffect
from synth.gap.effects.amplitude import DuffingEffect
from synth.gap.effects.auxiliary import AuxEffect, AuxInputEffect, MeasuredSagEffect
from synth.gap.effects.base import Effect, Params
from synth.gap.effects.damping import AmplitudeDampingEffect, drag_feedback
from synth.gap.effects.direction import DirectionEffect
from synth.gap.effects.drift import DriftEffect
from synth.gap.effects.dynamics import ResonanceEffect
from synth.gap.effects.friction import FrictionEffect, coulomb_force
from synth.gap.effects.quantization import QuantizationEffect, quantizer_grid
from synth.gap.effects.registry import DEFAULT_CANDIDATES, EFFECT_CLASSES, EFFECTS, aux_candidates, make_effect
from synth.gap.effects.static_map import StaticNonlinearityEffect
from synth.gap.effects.supply import SupplySagEffect
from synth.gap.effects.timing import DelayEffect, LagEffect

__all__ = [
    "DEFAULT_CANDIDATES",
    "EFFECTS",
    "EFFECT_CLASSES",
    "AmplitudeDampingEffect",
    "AuxEffect",
    "AuxInputEffect",
    "BacklashEffect",
    "DeadzoneEffect",
    "DelayEffect",
    "DirectionEffect",
    "DriftEffect",
    "DuffingEffect",
    "Effect",
    "FrictionEffect",
    "LagEffect",
    "MeasuredSagEffect",
    "Params",
    "QuantizationEffect",
    "RateLimitEffect",
    "ResonanceEffect",
    "SaturationEffect",
    "StaticNonlinearityEffect",
    "SupplySagEffect",
    "aux_candidates",
    "coulomb_force",
    "drag_feedback",
    "make_effect",
    "quantizer_grid",
]
