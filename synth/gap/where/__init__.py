"""Where the model and the record disagree: the residual localized in time, in frequency and by regime.

:mod:`~synth.gap.where.residual` (the residual and its size), :mod:`~synth.gap.where.steps`,
:mod:`~synth.gap.where.drift` and :mod:`~synth.gap.where.time` (which phase of which step, energy
windows, slow drift by CUSUM); :mod:`~synth.gap.where.xcorr`, :mod:`~synth.gap.where.coherence`,
:mod:`~synth.gap.where.error_model` and :mod:`~synth.gap.where.frequency` (prewhitened input-residual
cross-correlation, coherence, a model-error model with its confidence region);
:mod:`~synth.gap.where.regime` (residual against amplitude, rate, operating point, direction and
auxiliary channels); :mod:`~synth.gap.where.clipping` (clipped signals seen directly in a record).
:func:`synth.gap.where.localize.localize_gap` runs them all; :mod:`~synth.gap.where.gapmap` draws the
gap map. The modules are imported by their full path (this package imports nothing).
"""

__all__: list[str] = []
