"""Identification of plant models from measured records.

Step trains (seed 1, section 4B) and frequency sweeps (seed 2), handling-qualities
metrics (bandwidth, phase delay) and disturbance spectra. Modules:

- :mod:`synth.ident.simulate`: a plant driven by a sampled input, exact delay.
"""
