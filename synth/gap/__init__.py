"""Sim-to-real gap: where a model and the measured hardware disagree, and which effect explains it.

The model is driven by the measured command and compared with the measured output; the residual
``e = y_measured - y_model`` goes through three wings, in the order of the data flow
(model + record -> where -> effects -> attribution -> verdict):

- :mod:`synth.gap.where`: localization, in time (:mod:`~synth.gap.where.steps`,
  :mod:`~synth.gap.where.drift`, :mod:`~synth.gap.where.time`), in frequency
  (:mod:`~synth.gap.where.xcorr`, :mod:`~synth.gap.where.coherence`, :mod:`~synth.gap.where.error_model`,
  :mod:`~synth.gap.where.frequency`), by regime (:mod:`~synth.gap.where.regime`), clipping seen in the
  record (:mod:`~synth.gap.where.clipping`); :func:`synth.gap.where.localize.localize_gap` runs them
  and :mod:`~synth.gap.where.gapmap` draws the gap map;
- :mod:`synth.gap.effects`: the library of nested augmentations, one family per module (delay, lag,
  resonance, rate limit, saturation, dead zone, backlash, quantization, friction, supply sag, static
  nonlinearity, drift), each effect one self-describing class, listed by
  :mod:`synth.gap.effects.registry`;
- :mod:`synth.gap.attribution`: which effect closes the gap and how far (screen, joint re-fit,
  calibration, parsimony, verdict; :func:`synth.gap.attribution.heldout.diagnose_effects`), several runs
  (:mod:`~synth.gap.attribution.stitch`, :mod:`~synth.gap.attribution.roundrobin`).

:func:`synth.gap.diagnose.diagnose` is the whole diagnosis in one call (it takes arrays, columns, a
DataFrame, a path or a Record); :mod:`synth.gap.overlay` draws the before/after figure,
:mod:`synth.gap.report` and :mod:`synth.gap.roundrobin_report` write the reports,
:mod:`synth.gap.x4_case` is the X-4 rotor's worked case. The modules are imported by their full path
(this package imports nothing).
"""

__all__: list[str] = []
