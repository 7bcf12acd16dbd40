"""How far apart two starts lie in a parameter box: whether a second polish from the screen could reach another
basin than the first.

Each parameter is read on the two scales the screen draws it on (:func:`synth.synthesis.screen.screen_points`):
linear over its bounds, and, for a positive upper bound, logarithmic over the six decades below it. Two
controllers lie **apart** when on some parameter and some scale they differ by at least :data:`APART` of the
box. A lead-lag's lead (zero below the pole) and lag (zero above it) are apart; two leads that differ by a
quarter of the gain range are not.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["APART", "APART_FROM_PARAMETERS", "apart", "box_positions", "near_starts_for"]

APART = 0.5
"""Share of the box (on a linear or logarithmic scale) by which two starts differ on some parameter to count as
apart."""

APART_FROM_PARAMETERS = 3
"""Free parameters from which the design also polishes from a near miss apart from the first
(:func:`near_starts_for`). On the 300 problems of the design benchmark (seeds 24-28) the second start led to the
design four times (a rational, a PID and two lead-lags) and no PI took it; on ``specs/x4_rotor_robust.yaml`` (a
PI over three plants) it cost 0.58 s of the command's 2.55 s and changed nothing."""

LOG_DECADES = 6.0
"""Decades below a positive upper bound that the logarithmic scale spans (as the screen's log-uniform draw)."""


def box_positions(params: dict[str, float], bounds: dict[str, tuple[float, float]]) -> np.ndarray:
    """Positions in ``[0, 1]`` of a controller's parameters in their box: the linear position of each parameter,
    then the logarithmic one (0 for a parameter whose upper bound is not positive), in sorted parameter order.

    Examples
    --------
    >>> box_positions({"k": 1.0, "z": 10.0}, {"k": [0.0, 2.0], "z": [1e-3, 1e3]}).round(3).tolist()
    [0.5, 0.01, 0.95, 0.667]
    """
    names = sorted(bounds)
    linear, log = [], []
    for name in names:
        lo, hi = (float(v) for v in bounds[name])
        value = float(params[name])
        linear.append(0.0 if hi <= lo else (value - lo) / (hi - lo))
        if hi > 0:
            floor = max(lo, hi * 10.0 ** -LOG_DECADES) if lo >= 0 else hi * 10.0 ** -LOG_DECADES
            span = np.log(hi / floor)
            log.append(0.0 if span <= 0 else float(np.log(max(value, floor) / floor) / span))
        else:
            log.append(0.0)
    return np.clip(np.array(linear + log), 0.0, 1.0)


def apart(a: dict[str, float], b: dict[str, float], bounds: dict[str, tuple[float, float]]) -> bool:
    """Whether two controllers' parameters differ by at least :data:`APART` of the box on some parameter, on the
    linear or the logarithmic scale of :func:`box_positions`.

    Examples
    --------
    >>> bounds = {"k": [0.0, 3.0], "z": [0.5, 200.0], "p": [0.5, 500.0]}
    >>> apart({"k": 2.1, "z": 151.0, "p": 308.0}, {"k": 0.7, "z": 3.0, "p": 0.8}, bounds)  # a lead, a lag
    True
    >>> apart({"k": 2.1, "z": 151.0, "p": 308.0}, {"k": 1.2, "z": 197.0, "p": 244.0}, bounds)  # two leads
    False
    """
    return bool(np.max(np.abs(box_positions(a, bounds) - box_positions(b, bounds))) >= APART)


def near_starts_for(spec: Any) -> int:
    """How many near misses the design polishes from: two (the least violating and one apart from it) with at
    least :data:`APART_FROM_PARAMETERS` free parameters, else one.

    Examples
    --------
    >>> from synth.spec import parse_spec
    >>> spec = {"name": "x", "plant": {"tf": "1/(s+1)"}, "requirements": [{"type": "bandwidth", "min": 1.0}]}
    >>> near_starts_for(parse_spec({**spec, "controller": {"type": "PI", "bounds": {"kp": [0, 5], "ki": [0, 5]}}}))
    1
    >>> near_starts_for(parse_spec({**spec, "controller": {"type": "leadlag", "bounds": {"k": [0, 5],
    ...                 "z": [0.1, 10], "p": [0.1, 100]}}}))
    2
    """
    return 2 if len(spec.controller.free_parameters()) >= APART_FROM_PARAMETERS else 1
