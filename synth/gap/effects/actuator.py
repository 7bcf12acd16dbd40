"""Actuator effects on the command before the plant: rate limit, saturation (or output clipping), dead zone, backlash.

=====================  ========  ===========================================================  ==============
effect                 side      augmented model                                             parameters
=====================  ========  ===========================================================  ==============
``rate_limit``         input     :class:`synth.sim.blocks.RateLimit` before ``G``             ``rate``
``saturation``         input     :class:`synth.sim.blocks.Saturation` before ``G``            ``lower, upper``
``saturation(output)`` output    ``min(upper, max(lower, y))`` after ``G`` (clipping, overflow) ``lower, upper``
``deadzone``           input     :class:`synth.sim.blocks.DeadZone` before ``G``              ``width``
``backlash``           input     :class:`synth.sim.blocks.Backlash` before ``G``              ``width``
=====================  ========  ===========================================================  ==============

The blocks run on the measured command with the block equations of :mod:`synth.sim.blocks`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import NESTED_CRITICAL, Effect, Params, command_span, log_grid, slowest_pole
from synth.gap.effects.block_memo import run_block
from synth.plant import Plant
from synth.search import hooke_jeeves
from synth.sim.blocks import Backlash, DeadZone, RateLimit, Saturation

__all__ = ["BacklashEffect", "DeadzoneEffect", "RateLimitEffect", "SaturationEffect"]


@dataclass(frozen=True)
class RateLimitEffect(Effect):
    """Slew-rate limit ``rate`` [input units/s] on the command (:class:`synth.sim.blocks.RateLimit`).

    The grid runs from a ramp lasting twenty slowest plant time constants over the
    input's span up to the fastest rate in the command (inactive).

    Examples
    --------
    >>> import numpy as np
    >>> RateLimitEffect().input_map(np.array([0.0, 0, 5, 5, 5]), 1.0, {"rate": 2.0}).tolist()
    [0.0, 0.0, 2.0, 4.0, 5.0]
    """

    name: ClassVar[str] = "rate_limit"
    parameter_names: ClassVar[tuple[str, ...]] = ("rate",)
    grid_names: ClassVar[tuple[str, ...]] = ("rate",)
    default_candidates: ClassVar[tuple[str, ...]] = ("rate_limit",)

    def off(self) -> Params:
        return {"rate": np.inf}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        dt = float(t[1] - t[0])
        top = float(np.max(np.abs(np.diff(u)))) / dt
        return {"rate": (0.05 * command_span(u) * slowest_pole(plant), top)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        lo, hi = self.bounds(t, u, plant)["rate"]
        return log_grid(lo, hi, 12, "rate")

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        rate = params.get("rate", np.inf)
        return u if not np.isfinite(rate) else run_block(RateLimit(rate), u, dt)


@dataclass(frozen=True)
class SaturationEffect(Effect):
    """Amplitude limits ``lower <= . <= upper`` on the command or on the output.

    ``placement="input"`` (default): the command is limited before ``G``
    (:class:`synth.sim.blocks.Saturation`; an actuator's range). Grid: the upper
    limit alone, then the lower limit alone, at fractions of the input's span.

    ``placement="output"``: the model's output (offset included) is clipped
    after ``G`` (a sensor's range, a tank that overflows). Grid: the upper limit
    at the measured maximum and a little below it, then the lower limit likewise
    (a clipped record rests on its limit). The linear part is fitted with the
    clipped samples censored (:meth:`Effect.censor`).

    Examples
    --------
    >>> import numpy as np
    >>> SaturationEffect().input_map(np.array([0.0, 5, 10]), 1.0, {"upper": 8.0}).tolist()
    [0.0, 5.0, 8.0]
    >>> t = np.arange(4.0); u = np.array([0.0, 1, 2, 3])
    >>> SaturationEffect("output").apply(Plant.from_string("2"), t, u, {"upper": 3.0}).tolist()
    [0.0, 2.0, 3.0, 3.0]
    """

    placement: str = "input"
    name: ClassVar[str] = "saturation"
    joint_search: ClassVar[bool] = True
    parameter_names: ClassVar[tuple[str, ...]] = ("lower", "upper")
    grid_names: ClassVar[tuple[str, ...]] = ("lower", "upper")
    spellings: ClassVar[dict[str, dict[str, str]]] = {
        "saturation(output)": {"placement": "output"}, "clipping": {"placement": "output"},
        "saturation(input)": {"placement": "input"}}
    #: the actuator's limit only: output clipping is seen directly in a record (:mod:`synth.gap.where.clipping`)
    #: and is named with ``candidates`` when it is
    default_candidates: ClassVar[tuple[str, ...]] = ("saturation",)

    def __post_init__(self) -> None:
        if self.placement not in ("input", "output"):
            raise ModelError(f"must be 'input' or 'output', got {self.placement!r}", where="saturation.placement")

    @property
    def label(self) -> str:
        return "saturation" if self.placement == "input" else "saturation(output)"

    def to_dict(self) -> dict[str, Any]:
        return {"effect": self.label, "side": self.placement, "parameters": list(self.parameter_names)}

    def off(self) -> Params:
        return {"lower": -np.inf, "upper": np.inf}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"lower": (float(np.min(u)), float(np.max(u))), "upper": (float(np.min(u)), float(np.max(u)))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        span, lo, hi = command_span(u), float(np.min(u)), float(np.max(u))
        fractions = (0.03, 0.1, 0.2, 0.35, 0.5, 0.7)
        uppers = [hi - f * span for f in fractions]
        lowers = [lo + f * span for f in fractions]
        # limits that clip a few samples of a command with outliers (a derivative kick) lie far inside the
        # span: add the levels above which 0.5 ... 20 % of the samples lie (and below, for the lower limit)
        for share in (0.005, 0.02, 0.05, 0.2):
            up, down = float(np.quantile(u, 1.0 - share)), float(np.quantile(u, share))
            if all(abs(up - x) > 0.01 * span for x in uppers) and lo < up < hi:
                uppers.append(up)
            if all(abs(down - x) > 0.01 * span for x in lowers) and lo < down < hi:
                lowers.append(down)
        # and both limits at once, each at the same fraction of the span from its end: an actuator's range clips
        # both ways, which one limit at a time fits only as a one-sided clip plus a bias
        both = [{"upper": hi - f * span, "lower": lo + f * span} for f in fractions if f < 0.5]
        # ... and around the command's median: a wound-up integrator drives the command past each limit unevenly
        mid = float(np.median(u))
        both += [{"upper": mid + h, "lower": mid - h} for h in np.quantile(np.abs(u - mid), (0.65, 0.8, 0.9, 0.95))
                 if lo < mid - h and mid + h < hi]
        return ([{"upper": x} for x in sorted(uppers, reverse=True)] + [{"lower": x} for x in sorted(lowers)]
                + both)

    def data_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant) -> list[Params]:
        if self.placement == "input" or type(self).grid is not SaturationEffect.grid:  # a subclass's own grid wins
            return self.grid(t, u, plant)
        y = np.asarray(y, float)
        span, lo, hi = command_span(y), float(np.min(y)), float(np.max(y))
        fractions = (0.0, 0.01, 0.03, 0.1, 0.2)
        return [{"upper": hi - f * span} for f in fractions] + [{"lower": lo + f * span} for f in fractions]

    def seed_grid(self, point: Params, u_train: np.ndarray | None = None) -> list[Params]:
        """One limit at a time, as the effect's own grid, bracketed by +-5 % of the command's span, and with the
        other limit added beyond 5, 10 and 20 % of the training command's samples.

        The screen held the denominator fixed, which biases the limit.

        Examples
        --------
        >>> [g["upper"] for g in SaturationEffect().seed_grid({"upper": 5.0, "lower": -np.inf}, np.array([0.0, 10.0]))]
        [4.5, 4.8, 5.0, 5.2, 5.5, 5.0, 5.0, 5.0]
        >>> SaturationEffect().seed_grid({"upper": 5.0}, np.linspace(0.0, 10.0, 101))[5:]
        [{'upper': 5.0, 'lower': 0.5}, {'upper': 5.0, 'lower': 1.0}, {'upper': 5.0, 'lower': 2.0}]
        """
        side = "upper" if np.isfinite(point.get("upper", np.inf)) else "lower"
        other = "lower" if side == "upper" else "upper"
        span = float(np.ptp(u_train)) if u_train is not None and np.ptp(u_train) > 0 else abs(point[side]) or 1.0
        if np.isfinite(point.get("upper", np.inf)) and np.isfinite(point.get("lower", -np.inf)):  # both limits
            return [{"upper": point["upper"] + a * span, "lower": point["lower"] + b * span}
                    for a in (-0.03, 0.0, 0.03) for b in (-0.03, 0.0, 0.03)]
        grid = [{side: point[side] + f * span} for f in (-0.05, -0.02, 0.0, 0.02, 0.05)]
        one_sided = [{k: v for k, v in g.items() if k != other} for g in grid]
        if u_train is None:
            return one_sided
        # the other limit too, beyond 5-20 % of the samples: a one-sided screen may hide a two-sided range, and
        # the joint fit searches both limits together from the best two-sided point
        levels = np.quantile(u_train, (0.05, 0.1, 0.2) if other == "lower" else (0.95, 0.9, 0.8))
        return one_sided + [{side: point[side], other: float(x)} for x in levels
                            if (x < point[side]) == (other == "lower")]

    def clip(self, x: np.ndarray, params: Params) -> np.ndarray:
        """``x`` limited to ``[lower, upper]`` (unchanged when neither limit is finite).

        Examples
        --------
        >>> SaturationEffect("output").clip(np.array([-2.0, 0.5, 3.0]), {"lower": -1.0, "upper": 1.0}).tolist()
        [-1.0, 0.5, 1.0]
        """
        lo, hi = params.get("lower", -np.inf), params.get("upper", np.inf)
        if not (np.isfinite(lo) or np.isfinite(hi)):
            return x
        big = 1e30
        return Saturation(max(lo, -big), min(hi, big)).apply(x, 1.0)

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        return self.clip(u, params) if self.placement == "input" else u

    def output_map(self, y: np.ndarray, params: Params) -> np.ndarray:
        return self.clip(y, params) if self.placement == "output" else y

    @property
    def screenable(self) -> bool:
        return self.placement == "input"

    @property
    def has_output_map(self) -> bool:
        return self.placement == "output"

    @property
    def has_input_side(self) -> bool:
        return self.placement == "input"


@dataclass(frozen=True)
class DeadzoneEffect(Effect):
    """Dead zone of half-width ``width`` around ``center`` (:class:`synth.sim.blocks.DeadZone`).

    Where the band sits is ``center_search``:

    - ``"tested"`` (the candidate ``deadzone``): the fit tries both of the others and keeps the fitted center only
      when its training SSR is lower by more than the 95 % point of chi-square with one degree of freedom, in
      noise variances (:meth:`nested_variants`); a drive that does not move until the command leaves a band
      around where it rests needs no center of its own, a log that starts away from the band does;
    - ``"rest"``: the command at rest (the first sample), not a fitted parameter;
    - ``"fitted"``: searched with the width (then a second free parameter).

    Examples
    --------
    >>> import numpy as np
    >>> DeadzoneEffect().input_map(np.array([0.0, 0.5, 3.0]), 1.0, {"width": 1.0, "center": 0.0}).tolist()
    [0.0, 0.0, 2.0]
    >>> DeadzoneEffect().grid_names, DeadzoneEffect(center_search="fitted").grid_names
    (('width',), ('width', 'center'))
    """

    center_search: str = "tested"

    name: ClassVar[str] = "deadzone"
    parameter_names: ClassVar[tuple[str, ...]] = ("width", "center")
    default_candidates: ClassVar[tuple[str, ...]] = ("deadzone",)

    def __post_init__(self) -> None:
        if self.center_search not in ("tested", "rest", "fitted"):
            raise ModelError(f"center_search must be 'tested', 'rest' or 'fitted', got {self.center_search!r}",
                             where="effect deadzone")

    @property
    def grid_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return ("width", "center") if self.center_search == "fitted" else ("width",)

    @property
    def joint_search(self) -> bool:  # type: ignore[override]
        return self.center_search == "fitted"

    def nested_variants(self) -> tuple[Effect, Effect] | None:
        return (replace(self, center_search="rest"), replace(self, center_search="fitted")) \
            if self.center_search == "tested" else None

    def admissible(self, params: Params, u: np.ndarray) -> bool:
        """Whether the command passes through the band: at least 2 % of its samples on each side of it.

        A band that reaches past the command's end is a saturation and a shift (the fit cannot tell them apart);
        it is not a dead zone of its own center. (The band around the command at rest is not judged so: it is the
        candidate's form that needs no center of its own.)

        Examples
        --------
        >>> u = np.linspace(0.0, 10.0, 101)
        >>> DeadzoneEffect().admissible({"width": 1.0, "center": 5.0}, u)
        True
        >>> DeadzoneEffect().admissible({"width": 2.0, "center": 9.0}, u)
        False
        """
        w, c = params.get("width", 0.0), params.get("center", 0.0)
        if w <= 0.0:
            return True
        return bool(min(np.mean(u < c - w), np.mean(u > c + w)) >= 0.02)

    def off(self) -> Params:
        return {"width": 0.0, "center": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"width": (0.0, command_span(u))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        span = command_span(u)
        if self.center_search != "fitted":
            return [{"width": float(f * span), "center": float(u[0])} for f in _WIDTHS]
        return [g for g in ({"width": float(f * span), "center": c} for c in _inner_quantiles(u) for f in _FITTED_WIDTHS)
                if self.admissible(g, u)]

    def screen_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant,
                    mask: np.ndarray | None = None) -> list[Params]:
        """The widths around the command at rest and, unless the center is held there, around the command's
        deciles 10-90 % (the screen's points cost milliseconds), those the command passes through
        (:meth:`admissible`).

        Examples
        --------
        >>> t = np.arange(0, 1, 0.01); u = np.linspace(0.0, 10.0, t.size)
        >>> len(DeadzoneEffect().screen_grid(t, u, u, Plant.from_string("1/(s+1)")))  # 6 widths at rest, 33 off it
        39
        """
        at_rest = self.grid(t, u, plant) if self.center_search != "fitted" else []
        if self.center_search == "rest":
            return at_rest
        span = command_span(u)
        return at_rest + [g for g in ({"width": float(f * span), "center": c} for c in _inner_quantiles(u)
                                      for f in _WIDTHS) if self.admissible(g, u)]

    def refine_screen(self, cost: Callable[[Params], float], best: Params, t: np.ndarray, u: np.ndarray,
                      plant: Plant) -> Params:
        """From a best point away from the command at rest: a pattern search of width and center together, kept
        only when it beats the best width around the command at rest by the likelihood-ratio test of the joint fit
        (3.84 noise variances ``SSR/N`` of the screen's SSR), so that a second parameter does not win the screen's
        ranking on noise.

        Examples
        --------
        >>> t = np.arange(0, 1, 0.01); u = np.linspace(0.0, 10.0, t.size)
        >>> cost = lambda p: 1.0 + (p["width"] - 0.7) ** 2 + (p["center"] - 3.3) ** 2
        >>> p = DeadzoneEffect().refine_screen(cost, {"width": 0.5, "center": 3.0}, t, u, Plant.from_string("1"))
        >>> round(p["width"], 2), round(p["center"], 2)
        (0.7, 3.3)
        >>> flat = lambda p: 1.0 + 1e-3 * (p["center"] - 3.3) ** 2  # off rest by less than the test asks
        >>> DeadzoneEffect().refine_screen(flat, {"width": 0.5, "center": 3.0}, t, u, Plant.from_string("1"))["center"]
        0.0
        """
        rest = float(u[0])
        if self.center_search == "rest" or best.get("center") == rest:
            return best
        span = command_span(u)

        def located(z: np.ndarray) -> Params:
            return {**best, "width": float(z[0] * span), "center": float(z[1] * span)}

        def located_cost(z: np.ndarray) -> float:
            p = located(z)
            return float(cost(p)) if self.admissible(p, u) else np.inf

        lo, hi = np.array([0.0, float(np.min(u))]) / span, np.array([1.0, float(np.max(u))]) / span
        found = hooke_jeeves(located_cost, np.array([best["width"], best["center"]]) / span,
                             lo, hi, lambda a, b: a < b - 1e-12 * abs(b), 0.02, 2e-4, 80)
        cost_best = cost(best)  # the searches' values are their points' costs: each is evaluated once
        off, cost_off = (located(found.z), found.value) if found.value < cost_best else (best, cost_best)
        at_rest = [{**best, "width": float(f * span), "center": rest} for f in _WIDTHS]
        w0 = min(at_rest, key=cost)["width"] / span
        held = hooke_jeeves(lambda z: float(cost({**best, "width": float(z[0] * span), "center": rest})),
                            np.array([w0]), np.array([0.0]), np.array([1.0]), lambda a, b: a < b - 1e-12 * abs(b),
                            0.25 * w0, 2e-4, 40)
        on = {**best, "width": float(held.z[0] * span), "center": rest}
        return off if cost_off < held.value - NESTED_CRITICAL * cost_off / max(u.size, 1) else on

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        w = params.get("width", 0.0)
        return u if w <= 0 else run_block(DeadZone(w, params.get("center", 0.0)), u, dt)


_WIDTHS = (0.02, 0.05, 0.1, 0.2, 0.35, 0.5)  # dead-zone half-widths, in command spans
_FITTED_WIDTHS = (0.05, 0.2)  # ... at each decile when the center is fitted without a screened start


def _inner_quantiles(u: np.ndarray) -> list[float]:
    return [float(q) for q in np.quantile(u, np.linspace(0.1, 0.9, 9))]


@dataclass(frozen=True)
class BacklashEffect(Effect):
    """Backlash (play) of total ``width`` (:class:`synth.sim.blocks.Backlash`).

    Examples
    --------
    >>> import numpy as np
    >>> BacklashEffect().input_map(np.array([0.0, 0.5, 2, 1.5]), 1.0, {"width": 2.0}).tolist()
    [0.0, 0.0, 1.0, 1.0]
    """

    name: ClassVar[str] = "backlash"
    parameter_names: ClassVar[tuple[str, ...]] = ("width",)
    grid_names: ClassVar[tuple[str, ...]] = ("width",)
    default_candidates: ClassVar[tuple[str, ...]] = ("backlash",)

    def off(self) -> Params:
        return {"width": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"width": (0.0, command_span(u))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        return [{"width": float(f * command_span(u))} for f in (0.02, 0.05, 0.1, 0.2, 0.35, 0.5)]

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        w = params.get("width", 0.0)
        return u if w <= 0 else run_block(Backlash(w), u, dt)
