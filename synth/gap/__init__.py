"""Sim-to-real gap: where a model and the measured hardware disagree.

The model is driven by the measured command and compared with the measured
output; the residual ``e = y_measured - y_model`` is then localized

- in time (:mod:`synth.gap.where.steps`, :mod:`synth.gap.where.drift`, :mod:`synth.gap.where.time`):
  which phase of which step, energy windows, slow drift by CUSUM;
- in frequency (:mod:`synth.gap.where.xcorr`, :mod:`synth.gap.where.coherence`,
  :mod:`synth.gap.where.error_model`, :mod:`synth.gap.where.frequency`): prewhitened
  input-residual cross-correlation, coherence, and a model-error model with
  its confidence region;
- by regime (:mod:`synth.gap.where.regime`): residual against amplitude, rate,
  operating point, direction of motion and auxiliary channels.

:func:`synth.gap.where.localize.localize_gap` runs all of them and writes a
one-line headline; :func:`synth.gap.where.gapmap.gap_map_figure` draws the gap map.

Which unmodelled effect causes the gap, and how far it shrinks once added:
:mod:`synth.gap.effects` (the library of nested augmentations: delay, lag,
resonance, rate limit, saturation, dead zone, backlash, quantization, supply
sag, static nonlinearity, drift), :mod:`synth.gap.attribution.refit` (the nominal
parameters re-fitted jointly with an effect), :mod:`synth.gap.attribution.heldout`
(held-out shrinkage with bootstrap intervals, calibrated acceptance, the
verdict) and :mod:`synth.gap.overlay` (the before/after figure). Several runs of
one plant: :mod:`synth.gap.attribution.stitch` (held out together, each from rest with its
own offset) and :mod:`synth.gap.attribution.roundrobin` (each run fitted once, the others
held out, the evidence pooled; report: :mod:`synth.gap.roundrobin_report`).
The modules are imported by their full path (this package imports nothing).
"""
