"""Nonlinear sampled simulation of the closed loop (and the open loop) with composable blocks.

Public API (imported on first use, so ``import synth`` does not load numba):

``NonlinearLoop``, ``OperatingPoint``, ``OpenLoop``
    What is simulated.
``simulate``, ``simulate_step``, ``simulate_batch``, ``simulate_open_loop``, ``simulate_open_loop_batch``
    Run it (one variant or a batch).
``RateLimit``, ``Saturation``, ``DeadZone``, ``Quantizer``, ``Backlash``, ``Static``, ``Lag``, ``Dynamics``,
``SupplySag``, ``SampleHold``, ``Noise``, ``Delay``, ``apply_chain``
    Blocks (:mod:`synth.sim.blocks`).
``PsdDisturbance``, ``RecordDisturbance``, ``StepDisturbance``, ``step_reference``
    Exogenous signals (:mod:`synth.sim.signals`).
``nonlinear_step_metrics``, ``detect_oscillation``
    Step metrics and limit-cycle detection.
``step_verdict``, ``StepVerdict``, ``Evidence``, ``plan_horizon``, ``HorizonPlan``
    Simulate a step until it is settled, a limit cycle or diverging (else undetermined), with the
    evidence (:mod:`synth.sim.verdict`, :mod:`synth.sim.horizon`).
``saturation_df``, ``rate_limiter_df``, ``dead_zone_df``, ``numeric_df``, ``harmonic_balance``,
``sampled_loop_response``, ``predict_loop_cycles``
    Describing functions and harmonic balance (:mod:`synth.sim.describing`).
``oscillation_onset``, ``rate_variants``
    Onset gain of oscillation against delay and rate limit (:mod:`synth.sim.onset`).

Examples
--------
>>> import synth.sim as sim
>>> from synth import Plant, Controller
>>> loop = sim.NonlinearLoop(Plant.from_string("10/(s+10)"), Controller("P", {"kp": 1}),
...                          actuator=[sim.Saturation(-0.2, 0.2)])
>>> round(float(sim.simulate(loop, 1.0, 1.0).output[-1]), 3)  # the saturation caps the output
0.2
"""

from __future__ import annotations

import importlib
from typing import Any

_WHERE = {
    "synth.sim.loops": ("NonlinearLoop", "OperatingPoint", "OpenLoop"),
    "synth.sim.results": ("SimResult", "BatchResult"),
    "synth.sim.simulator": ("simulate", "simulate_step", "simulate_batch", "simulate_open_loop",
                            "simulate_open_loop_batch"),
    "synth.sim.blocks": ("Block", "RateLimit", "Saturation", "DeadZone", "Quantizer", "Backlash", "Static", "Lag",
                         "Dynamics", "SupplySag", "SampleHold", "Noise", "Delay", "apply_chain", "BLOCK_TYPES"),
    "synth.sim.signals": ("PsdDisturbance", "RecordDisturbance", "StepDisturbance", "step_reference",
                          "psd_signal"),
    "synth.sim.metrics": ("NonlinearStepMetrics", "nonlinear_step_metrics"),
    "synth.sim.limitcycle": ("Oscillation", "detect_oscillation"),
    "synth.sim.verdict": ("step_verdict", "StepVerdict", "Evidence"),
    "synth.sim.horizon": ("plan_horizon", "HorizonPlan"),
    "synth.sim.describing": ("saturation_df", "rate_limiter_df", "dead_zone_df", "numeric_df", "harmonic_balance",
                             "PredictedCycle", "sampled_loop_response", "predict_loop_cycles",
                             "LoopCyclePrediction"),
    "synth.sim.onset": ("oscillation_onset", "rate_variants", "OnsetResult", "OnsetRow"),
}
_INDEX = {name: module for module, names in _WHERE.items() for name in names}

__all__ = sorted(_INDEX)


def __getattr__(name: str) -> Any:
    module = _INDEX.get(name)
    if module is None:
        raise AttributeError(f"module 'synth.sim' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)
