"""The controller gain at which a sustained oscillation starts, against in-loop delay and rate limit.

For each in-loop delay and each variant of the actuator chain (as specified,
other rate limits, no rate limit, every nonlinear block off), the step
response is simulated on a geometric grid of gains (one batch), each run is
classified (a sustained or growing oscillation at its end, see
:func:`synth.sim.limitcycle.detect_oscillation`), and the first change from
"settles" to "oscillates" is refined by bisection (again one batch per round).
The result is the onset gain: below it every gain of the grid settles.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.sim.blocks import RateLimit
from synth.sim.limitcycle import Oscillation, detect_oscillation
from synth.sim.loops import NonlinearLoop
from synth.sim.signals import step_reference
from synth.sim.simulator import simulate_batch

__all__ = ["OnsetResult", "OnsetRow", "oscillation_onset", "rate_variants"]


@dataclass(frozen=True)
class OnsetRow:
    """Onset of oscillation for one in-loop delay and one actuator variant.

    Attributes
    ----------
    delay : float
        In-loop delay (s), added to the loop's own.
    variant : str
        ``"as specified"``, ``"rate limit R"``, ``"no rate limit"`` or ``"linear"``.
    onset_gain : float or None
        Smallest gain that ends in a sustained or growing oscillation (None: none up to the top
        of the range).
    settled_gain : float or None
        Largest gain below the onset that settles (the bracket's lower end).
    amplitude, period : float or None
        Output oscillation just above the onset (output units, s); None when it diverges.
    diverges : bool
        Just above the onset the output grows without bound (a linear instability).
    settles_again_at : list of float
        Grid gains above the onset that settle again (the onset is not a clean threshold).
    """

    delay: float
    variant: str
    onset_gain: float | None
    settled_gain: float | None
    amplitude: float | None
    period: float | None
    diverges: bool
    settles_again_at: list[float] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return asdict(self)


@dataclass
class OnsetResult:
    """Onset gains for every delay and variant.

    Attributes
    ----------
    parameter : str
        The swept controller parameter.
    gains : (float, float)
        Range searched.
    rows : list of OnsetRow
    grid_points, refinements : int
        Grid size and bisection rounds (resolution: the bracket's width).
    horizon : float
        Simulated seconds per run; the last half is examined.
    step : (float, float)
        Reference step of every run.
    min_amplitude : float
        Smallest oscillation counted (output units).
    """

    parameter: str
    gains: tuple[float, float]
    rows: list[OnsetRow]
    grid_points: int
    refinements: int
    horizon: float
    step: tuple[float, float]
    min_amplitude: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        out = asdict(self)
        out["rows"] = [r.to_dict() for r in self.rows]
        return out

    def onset(self, variant: str, delay: float) -> float | None:
        """Onset gain of ``variant`` at ``delay`` (None if none in range).

        Examples
        --------
        >>> r = OnsetResult("kp", (1, 10), [OnsetRow(0.01, "linear", 7.0, 6.9, 1.0, 0.05, True)], 8, 2, 2.0,
        ...                 (0, 1), 0.0)
        >>> r.onset("linear", 0.01)
        7.0
        """
        for row in self.rows:
            if row.variant == variant and abs(row.delay - delay) < 1e-12:
                return row.onset_gain
        raise KeyError(f"no row for {variant!r} at {delay:g} s")


def rate_variants(loop: NonlinearLoop, rate_limits: Sequence[float]) -> dict[str, NonlinearLoop]:
    """The loop as given, with each other rate limit, without rate limit, and with every
    nonlinear block off.

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> from synth.sim.blocks import Saturation
    >>> loop = NonlinearLoop(Plant.from_string("1/(s+1)"), Controller("P", {"kp": 1}),
    ...                      actuator=[RateLimit(10.0), Saturation(-1, 1)])
    >>> list(rate_variants(loop, [20.0]))
    ['as specified', 'rate limit 20', 'no rate limit', 'linear']
    """
    out = {"as specified": loop}
    has_rate = any(isinstance(b, RateLimit) for b in loop.actuator)
    for rate in rate_limits:
        chain = tuple(RateLimit(rate, b.falling and b.falling * rate / b.rate) if isinstance(b, RateLimit) else b
                      for b in loop.actuator)
        if not has_rate:
            chain = (RateLimit(rate), *chain)
        out[f"rate limit {rate:g}"] = loop.replace(actuator=chain)
    if has_rate:
        out["no rate limit"] = loop.without("rate_limit")
    out["linear"] = loop.linear()
    return out


def _classify(batch: Any, min_amplitude: float) -> list[Oscillation]:
    half = (batch.t[-1] - batch.t[0]) / 2
    return [detect_oscillation(batch.t, batch.output[i], window=half, min_amplitude=min_amplitude)
            for i in range(len(batch))]


def _oscillates(osc: Oscillation) -> bool:
    return osc.present or osc.diverging


def oscillation_onset(loop: NonlinearLoop, step: tuple[float, float], delays: Sequence[float],
                      rate_limits: Sequence[float] = (), gains: tuple[float, float] = (0.5, 20.0),
                      parameter: str = "kp", horizon: float = 3.0, min_amplitude: float = 0.0,
                      grid_points: int = 40, refinements: int = 7,
                      progress: Callable[[int, int], None] | None = None) -> OnsetResult:
    """Onset gain of oscillation for every in-loop delay and actuator variant.

    Parameters
    ----------
    loop : NonlinearLoop
        The loop; its controller's ``parameter`` is swept.
    step : (float, float)
        Reference step of every run (absolute output units).
    delays : sequence of float
        In-loop delays (s) added to the loop's own.
    rate_limits : sequence of float
        Other rate limits to try (input units/s).
    gains : (float, float)
        Range of the swept parameter.
    horizon : float
        Seconds simulated per run; the last half is examined for an oscillation.
    min_amplitude : float
        Smallest half peak-to-peak output oscillation that counts (e.g. one sensor quantum).
    grid_points, refinements : int
        Geometric grid size and bisection rounds.
    progress : callable, optional
        Called as ``progress(done, total)`` after each batch.

    Returns
    -------
    OnsetResult

    Examples
    --------
    >>> from synth.plant import Plant; from synth.controllers import Controller
    >>> loop = NonlinearLoop(Plant.from_string("23*(s+0.43)/((s+9.6)*(s+0.54))"), Controller("P", {"kp": 1}))
    >>> res = oscillation_onset(loop, (0.0, 1.0), [0.02], gains=(1, 10), horizon=2.0, grid_points=10,
    ...                         refinements=8)
    >>> round(res.onset("linear", 0.02), 1)  # sampled loop; 3.69 with a continuous controller
    3.6
    """
    lo, hi = float(gains[0]), float(gains[1])
    if not 0 < lo < hi:
        raise ModelError(f"gain range must be 0 < low < high, got [{lo:g}, {hi:g}]")
    if parameter not in loop.controller.parameters:
        raise ModelError(f"{loop.controller.type} has no parameter {parameter!r}")
    variants = rate_variants(loop, rate_limits)
    cases = [(d, name, v.replace(loop_delay=v.loop_delay + d)) for d in delays for name, v in variants.items()]
    grid = np.geomspace(lo, hi, grid_points)
    reference = step_reference(*step)
    total = 1 + refinements
    runs = [case[2].with_gain(parameter, float(g)) for case in cases for g in grid]
    oscs = _classify(simulate_batch(runs, reference, horizon), min_amplitude)
    if progress:
        progress(1, total)
    flags = np.array([_oscillates(o) for o in oscs]).reshape(len(cases), grid_points)
    brackets: list[list[float] | None] = []
    above: list[Oscillation | None] = []
    again: list[list[float]] = []
    for c in range(len(cases)):
        hits = np.flatnonzero(flags[c])
        if hits.size == 0:
            brackets.append(None)
            above.append(None)
            again.append([])
            continue
        i = int(hits[0])
        brackets.append([float(grid[i - 1]) if i > 0 else None, float(grid[i])])  # type: ignore[list-item]
        above.append(oscs[c * grid_points + i])
        again.append([float(grid[j]) for j in range(i + 1, grid_points) if not flags[c, j]])
    for r in range(refinements):
        todo = [c for c, b in enumerate(brackets) if b is not None and b[0] is not None]
        if todo:
            mids = [float(np.sqrt(brackets[c][0] * brackets[c][1])) for c in todo]  # type: ignore[index]
            runs = [cases[c][2].with_gain(parameter, m) for c, m in zip(todo, mids)]
            for c, m, o in zip(todo, mids, _classify(simulate_batch(runs, reference, horizon), min_amplitude)):
                if _oscillates(o):
                    brackets[c][1] = m  # type: ignore[index]
                    above[c] = o
                else:
                    brackets[c][0] = m  # type: ignore[index]
        if progress:
            progress(2 + r, total)
    rows = []
    for c, (d, name, _) in enumerate(cases):
        b, o = brackets[c], above[c]
        if b is None or o is None:
            rows.append(OnsetRow(float(d), name, None, None, None, None, False, []))
            continue
        rows.append(OnsetRow(float(d), name, b[1], b[0], None if o.diverging else o.amplitude,
                             None if o.diverging else o.period, bool(o.diverging), again[c]))
    return OnsetResult(parameter, (lo, hi), rows, grid_points, refinements, float(horizon),
                       (float(step[0]), float(step[1])), float(min_amplitude))
