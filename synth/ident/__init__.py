"""Identification of plant models from measured records.

Step trains (seed 1, section 4B) and frequency sweeps (seed 2), handling-qualities
metrics (bandwidth, phase delay) and disturbance spectra. Modules:

- :mod:`synth.ident.simulate`: a plant driven by a sampled input, exact delay.
- :mod:`synth.ident.structure`: parametric transfer-function formulas (numpy and casadi).
- :mod:`synth.ident.steps`: find, align and average the steps of a step train; SNR.
- :mod:`synth.ident.timefit`: simulation-error fit of a structure (casadi + IPOPT), delay, sensor,
  standard errors; :func:`identify` averages a step train first. Its casadi problem is in
  :mod:`synth.ident.sim_error_problem`, its deterministic start (SRIVC) in :mod:`synth.ident.srivc`.
- :mod:`synth.ident.x4_record`: the SYNTHETIC X-4 step-train record from the seed's model.
- :mod:`synth.ident.sweep_design`, :mod:`synth.ident.spectra`, :mod:`synth.ident.freqfit`: sweep
  design, composite multi-window frequency response (windows and averaging in
  :mod:`synth.ident.spectral_windows`, coherence and the coherent band in :mod:`synth.ident.coherence`),
  NAVFIT-cost fit with an exact delay; per-run quality and which runs to keep in
  :mod:`synth.ident.sweep_quality`.
- :mod:`synth.ident.hq_metrics`, :mod:`synth.ident.hq`, :mod:`synth.ident.model_phase`: handling-qualities
  bandwidth and phase delay (definitions; estimation from a model or measurements; a model's exact phase).
- :mod:`synth.ident.psd`: disturbance spectra (:mod:`synth.ident.welch`), noise floor, spikes, trend,
  power-share frequency (:mod:`synth.ident.spectrum_features`), the bandwidth they suggest
  (:mod:`synth.ident.bandwidth_suggestion`).
- :mod:`synth.ident.from_spec`: a spec's ``plant: {identify: ...}`` and its uncertainty plants.

Names are imported on first use (casadi and scipy load only when needed).

Examples
--------
>>> from synth.ident import hq_from_plant
>>> from synth.plant import Plant
>>> round(hq_from_plant(Plant.from_string("1/(s^2+s+1)", delay=0.1)).w180, 3)
3.262
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "simulate_plant": "simulate",
    "parse_structure": "structure", "Structure": "structure",
    "find_steps": "steps", "average_steps": "steps", "StepAverage": "steps",
    "fit_structure": "timefit", "identify": "identification", "TimeFitResult": "timefit", "IdentifyResult": "identification",
    "x4_step_train": "x4_record", "x4_step_train_path": "x4_record",
    "design_sweep": "sweep_design", "SweepDesign": "sweep_design",
    "frequency_response": "spectra", "FrequencyResponse": "spectra", "rate_to_attitude": "spectra",
    "correct_response": "spectra", "run_quality": "sweep_quality", "rank_runs": "sweep_quality",
    "RunQuality": "sweep_quality", "FrequencyFitError": "freqfit",
    "coherent_band": "coherence",
    "fit_frequency_response": "freqfit", "FreqFit": "freqfit", "fit_cost": "freqfit", "verify_step": "step_verification",
    "hq_from_plant": "hq", "hq_from_frd": "hq", "HQMetrics": "hq_metrics",
    "analyze_psd": "psd", "analyze_records": "psd", "PsdAnalysis": "psd", "suggest_bandwidth": "bandwidth_suggestion",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"synth.ident.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module 'synth.ident' has no attribute {name!r}")
