"""The library of effects a linear model may be missing, each a nested augmentation of it.

An effect adds one mechanism to the nominal linear model ``G`` (rational
transfer function times an exact delay) and is switched off by a parameter
value, so the nominal model is nested in every augmented one:

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
=====================  ========  ===========================================================  ==============

The input-side blocks run on the measured command with the block equations of
:mod:`synth.sim.blocks` (supply sag is that block with a 1 V battery, a 1 ohm
internal resistance and no static current, so ``sag`` is the relative voltage
drop per input unit of the command's fast part). How each parameter is fitted
is part of the effect's description: *grid* parameters (non-smooth in the
output: a rate, a limit, a width, a step) are searched on the deterministic
grid :meth:`Effect.grid` built from the record; *factor* parameters (``tau``,
``wn``, ``zeta``, the delay) join the nominal coefficients in the casadi fit,
the grid only giving starting values; *basis* parameters (``a2``, ``a3``,
``sag``, ``slope``, ``curvature``) enter the output linearly for a given
linear model and are solved by least squares (:mod:`synth.gap.refit`).

``Effect.apply(plant, t, u, params)`` is the augmented model's output; the
nominal model is ``Effect.apply`` with the effect switched off. Two effects
need more than the command: output clipping is fitted on the output's scale
(its grid comes from the measured output, :meth:`Effect.data_grid`, and the
linear part is fitted to the data with the clipped samples censored,
:meth:`Effect.censor`), and Coulomb friction depends on the model's own
velocity (:meth:`Effect.base_input` gets the linear model; the re-fit
alternates the friction signal and the linear fit until the error settles).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.ident.simulate import simulate_plant
from synth.plant import Plant
from synth.sim.blocks import Backlash, DeadZone, Quantizer, RateLimit, Saturation, SupplySag

Params = dict[str, float]


def _span(u: np.ndarray) -> float:
    span = float(np.max(u) - np.min(u))
    if span <= 0:
        raise ModelError("the input is constant; no effect can be fitted", where="record.u")
    return span


def _slowest_pole(plant: Plant) -> float:
    """Magnitude of the slowest nonzero pole [rad/s] (1 rad/s for a static gain)."""
    p = np.abs(plant.poles())
    p = p[p > 0]
    return float(np.min(p)) if p.size else 1.0


def _fastest_pole(plant: Plant) -> float:
    p = np.abs(plant.poles())
    p = p[p > 0]
    return float(np.max(p)) if p.size else 1.0


@dataclass(frozen=True)
class Effect:
    """One mechanism the nominal model may be missing (base class).

    Attributes
    ----------
    name : str
        Effect name as it appears in the verdict.
    side : str
        ``"input"`` (acts on the command before the plant), ``"output"`` (after it) or
        ``"linear"`` (changes the linear model).
    parameter_names : tuple of str
        The effect's parameters, as keys of ``params``.
    grid_names, factor_names, basis_names : tuple of str
        How each parameter is fitted (see the module text).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 2, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
    >>> G = Plant.from_string("1/(0.1*s+1)")
    >>> y = RateLimitEffect().apply(G, t, u, {"rate": 2.0})
    >>> round(float(y[100]), 3), round(float(simulate_plant(G, t, u)[100]), 3)  # slower than the nominal
    (0.811, 0.993)
    """

    name: ClassVar[str] = ""
    side: ClassVar[str] = "input"
    parameter_names: ClassVar[tuple[str, ...]] = ()
    grid_names: ClassVar[tuple[str, ...]] = ()
    factor_names: ClassVar[tuple[str, ...]] = ()
    basis_names: ClassVar[tuple[str, ...]] = ()

    @property
    def label(self) -> str:
        """Name used in results and verdicts (placement included where it matters)."""
        return self.name

    # -- description -------------------------------------------------------------------------------------------
    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        """Physical bounds of each parameter for this record (the grid lies inside them)."""
        return {}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        """Deterministic grid (or starting values) of the non-basis parameters, built from the record."""
        return [{}]

    def off(self) -> Params:
        """Parameter values that switch the effect off (the nominal model)."""
        return {}

    # -- model -------------------------------------------------------------------------------------------------
    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        """Input-side block applied to the command (identity for other sides)."""
        return u

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        """Signals added to the plant input, one per basis parameter (input side)."""
        return []

    def output_basis(self, t: np.ndarray) -> list[np.ndarray]:
        """Signals added to the plant output, one per basis parameter (output side)."""
        return []

    def factor(self, params: Params | None = None) -> str | None:
        """Transfer-function factor (in the factor parameters; grid parameters as numbers) times the nominal."""
        return None

    def augment_plant(self, plant: Plant, params: Params) -> Plant:
        """The linear part of the augmented model."""
        return plant

    def to_factor(self, params: Params) -> dict[str, float]:
        """Values of the factor's structure parameters (square roots keep ``tau``, ``zeta`` >= 0 in the fit)."""
        return {name: float(np.sqrt(max(params[name], 0.0))) for name in self.factor_names if name != "delay"}

    def from_factor(self, values: dict[str, float]) -> Params:
        """Effect parameters from the factor's structure parameters (inverse of :meth:`to_factor`)."""
        return {name: float(values[name]) ** 2 for name in self.factor_names if name in values and name != "delay"}

    #: the input side depends on the linear model (re-fit alternates it with the linear fit)
    needs_plant: ClassVar[bool] = False

    @property
    def screenable(self) -> bool:
        """Whether :mod:`synth.gap.screen` can fit it (an input-side block on a fixed input, no output map)."""
        return not self.needs_plant

    def data_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant) -> list[Params]:
        """Grid built from the record's output as well (default: :meth:`grid`)."""
        return self.grid(t, u, plant)

    def output_map(self, y: np.ndarray, params: Params) -> np.ndarray:
        """Output-side static map applied last (identity for other sides)."""
        return y

    def censor(self, y: np.ndarray, y_linear: np.ndarray, params: Params) -> np.ndarray:
        """Data for the linear part's fit given its current output ``y_linear`` (default: ``y``).

        For an output map ``N``, ``y + y_linear - N(y_linear)``: a sample the map
        clips keeps the residual ``y - N(y_linear)`` it has in the augmented model.
        """
        return y + y_linear - self.output_map(y_linear, params)

    def base_input(self, plant: Plant, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        """Input block applied to the command, given the linear model (default: :meth:`input_map`)."""
        return self.input_map(u, dt, params)

    def plant_input(self, u: np.ndarray, dt: float, params: Params, plant: Plant | None = None) -> np.ndarray:
        """What drives the linear part: the input block plus the basis terms."""
        u = np.asarray(u, float)
        if self.needs_plant:
            if plant is None:
                raise ModelError("needs the linear model", where=f"effect {self.label}")
            v = self.base_input(plant, u, dt, params)
        else:
            v = self.input_map(u, dt, params)
        for name, phi in zip(self.basis_names, self.input_basis(u, dt, params)):
            v = v + params.get(name, 0.0) * phi
        return v

    def apply(self, plant: Plant, t: np.ndarray, u: np.ndarray, params: Params, offset: float = 0.0,
              initial: str = "steady") -> np.ndarray:
        """Output of the augmented model on the command ``u`` sampled at ``t``.

        Parameters
        ----------
        plant : Plant
            The (re-fitted) nominal linear model.
        t, u : numpy.ndarray
            Uniform sample times [s] and the measured command.
        params : dict
            The effect's parameters (missing ones: the effect's "off" values).
        offset : float
            Output operating-point constant added to the simulated output.
        initial : {"steady", "zero"}
            Initial state, see :func:`synth.ident.simulate.simulate_plant`.

        Returns
        -------
        numpy.ndarray

        Examples
        --------
        >>> import numpy as np
        >>> t = np.arange(0, 1, 0.1); u = np.where(t >= 0.2, 1.0, 0.0)
        >>> y = SaturationEffect().apply(Plant.from_string("2"), t, u, {"upper": 0.5})
        >>> y.tolist()[:4]
        [0.0, 0.0, 1.0, 1.0]
        """
        t = np.asarray(t, float)
        dt = float((t[-1] - t[0]) / (t.size - 1))
        p = {**self.off(), **params}
        G = self.augment_plant(plant, p)
        v = self.plant_input(np.asarray(u, float), dt, p, plant=G)
        y = simulate_plant(G, t, v, initial=initial) + offset
        for name, psi in zip(self.basis_names, self.output_basis(t)):
            y = y + p.get(name, 0.0) * psi
        return self.output_map(y, p)

    def to_dict(self) -> dict[str, Any]:
        """``{"effect", "side", "parameters"}``.

        Examples
        --------
        >>> LagEffect("sensor").to_dict()
        {'effect': 'lag(sensor)', 'side': 'output', 'parameters': ['tau']}
        """
        return {"effect": self.label, "side": self.side, "parameters": list(self.parameter_names)}


# ------------------------------------------------------------------------------------------------ linear
@dataclass(frozen=True)
class DelayEffect(Effect):
    """Extra pure delay ``d`` [s] (fitted jointly with the nominal coefficients, exact fractional delay).

    Examples
    --------
    >>> DelayEffect().augment_plant(Plant.from_string("1/(s+1)", delay=0.01), {"delay": 0.02}).delay
    0.03
    """

    name: ClassVar[str] = "delay"
    side: ClassVar[str] = "linear"
    parameter_names: ClassVar[tuple[str, ...]] = ("delay",)
    factor_names: ClassVar[tuple[str, ...]] = ("delay",)

    def off(self) -> Params:
        return {"delay": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"delay": (-plant.delay, 0.25 * float(t[-1] - t[0]))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        dt = float(t[1] - t[0])
        return [{"delay": 2.0 * dt}]

    def augment_plant(self, plant: Plant, params: Params) -> Plant:
        return plant.with_delay(max(0.0, plant.delay + params.get("delay", 0.0)))


@dataclass(frozen=True)
class LagEffect(Effect):
    """Extra first-order lag ``1/(tau s + 1)`` at the actuator or at the sensor (exact, in series with ``G``).

    On a linear model both placements give the same output; only a record with
    the actuator output logged (or a known excitation entering at the output)
    tells them apart. ``tau`` is searched on a grid (then golden section) with
    the nominal coefficients fitted by casadi at each point, which keeps the
    fit away from the stiff ``tau -> 0`` end.

    Examples
    --------
    >>> LagEffect().augment_plant(Plant.from_string("1/(s+1)"), {"tau": 0.5}).den.tolist()
    [1.0, 3.0, 2.0]
    """

    placement: str = "actuator"
    name: ClassVar[str] = "lag"
    side: ClassVar[str] = "linear"
    parameter_names: ClassVar[tuple[str, ...]] = ("tau",)
    grid_names: ClassVar[tuple[str, ...]] = ("tau",)

    def __post_init__(self) -> None:
        if self.placement not in ("actuator", "sensor"):
            raise ModelError(f"must be 'actuator' or 'sensor', got {self.placement!r}", where="lag.placement")

    @property
    def label(self) -> str:
        return "lag" if self.placement == "actuator" else "lag(sensor)"

    def to_dict(self) -> dict[str, Any]:
        return {"effect": self.label, "side": "input" if self.placement == "actuator" else "output",
                "parameters": list(self.parameter_names)}

    def off(self) -> Params:
        return {"tau": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"tau": (0.0, 1.0 / _fastest_pole(plant))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        dt = float(t[1] - t[0])
        top = 1.0 / _fastest_pole(plant)  # an actuator or sensor lag is faster than the plant it is added to
        # from a quarter sample, as the extra delay's search: the exact discretization sees a sub-sample lag
        return [{"tau": float(x)} for x in np.geomspace(0.25 * dt, max(2 * dt, top), 8)]

    def factor(self, params: Params | None = None) -> str | None:
        tau = float((params or {}).get("tau", 0.0))
        return f"{1.0 / tau!r}/(s+{1.0 / tau!r})" if tau > 0 else None  # monic: better scaled for the fit

    def augment_plant(self, plant: Plant, params: Params) -> Plant:
        tau = params.get("tau", 0.0)
        return Plant(plant.num, np.polymul(plant.den, [tau, 1.0]), plant.delay, plant.input, plant.output,
                     plant.label)


@dataclass(frozen=True)
class ResonanceEffect(Effect):
    """A lightly damped mode ``wn^2/(s^2 + 2 zeta wn s + wn^2)`` in series (unit DC gain).

    ``wn`` is searched on a grid (then golden section); ``zeta`` joins the nominal
    coefficients in the casadi fit as ``z`` with ``zeta = z^2 / (1 + z^2)``, so the
    fitted damping stays in ``[0, 1)``: a lightly damped mode, never an overdamped
    pair of real poles (which the lag effect, or the re-fit's own poles, describe).

    Examples
    --------
    >>> G = ResonanceEffect().augment_plant(Plant.from_string("1/(s+1)"), {"wn": 10.0, "zeta": 0.1})
    >>> round(float(abs(G.freqresp([10.0])[0]) * abs(1 + 10j)), 3)  # peak 1/(2 zeta) at wn
    5.0
    """

    name: ClassVar[str] = "resonance"
    side: ClassVar[str] = "linear"
    parameter_names: ClassVar[tuple[str, ...]] = ("wn", "zeta")
    grid_names: ClassVar[tuple[str, ...]] = ("wn",)
    factor_names: ClassVar[tuple[str, ...]] = ("zeta",)

    def off(self) -> Params:
        return {"wn": np.inf, "zeta": 1.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"wn": (0.0, np.pi / float(t[1] - t[0])), "zeta": (0.0, 1.0)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        nyquist = np.pi / float(t[1] - t[0])
        lo = min(2.0 * _fastest_pole(plant), nyquist / 20)
        hi = 0.9 * nyquist  # a mode can sit anywhere below the Nyquist frequency the record resolves
        count = max(6, int(np.ceil(np.log(hi / lo) / np.log(1.32))) + 1)  # neighbours at most 32 % apart
        return [{"wn": float(w), "zeta": 0.2} for w in np.geomspace(lo, hi, count)]

    #: largest damping handed to the fit (``z`` finite)
    zeta_max: ClassVar[float] = 1.0 - 1e-6

    def factor(self, params: Params | None = None) -> str:
        wn = float((params or {}).get("wn", 1.0))
        return f"{wn**2!r}/(s^2+2*(zeta^2/(1+zeta^2))*{wn!r}*s+{wn**2!r})"

    def to_factor(self, params: Params) -> dict[str, float]:
        """``z = sqrt(zeta / (1 - zeta))`` (``zeta`` clamped to ``[0, 1)``).

        Examples
        --------
        >>> e = ResonanceEffect()
        >>> round(e.to_factor({"zeta": 0.5})["zeta"], 6), round(e.from_factor({"zeta": 1.0})["zeta"], 6)
        (1.0, 0.5)
        >>> e.from_factor({"zeta": 1e3})["zeta"] <= 1.0  # never overdamped, whatever the solver returns
        True
        """
        zeta = float(np.clip(params.get("zeta", 0.2), 0.0, self.zeta_max))
        return {"zeta": float(np.sqrt(zeta / (1.0 - zeta)))}

    def from_factor(self, values: dict[str, float]) -> Params:
        """``zeta = z^2 / (1 + z^2)`` (inverse of :meth:`to_factor`)."""
        if "zeta" not in values:
            return {}
        z2 = float(values["zeta"]) ** 2
        return {"zeta": z2 / (1.0 + z2) if np.isfinite(z2) else 1.0}

    def augment_plant(self, plant: Plant, params: Params) -> Plant:
        wn, zeta = params.get("wn", np.inf), float(np.clip(params.get("zeta", 1.0), 0.0, 1.0))
        if not np.isfinite(wn):
            return plant
        return Plant(plant.num * wn**2, np.polymul(plant.den, [1.0, 2 * zeta * wn, wn**2]), plant.delay,
                     plant.input, plant.output, plant.label)


# ------------------------------------------------------------------------------------------------ input side
def _log_grid(lo: float, hi: float, n: int, name: str) -> list[Params]:
    return [{name: float(x)} for x in np.geomspace(lo, hi, n)]


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

    def off(self) -> Params:
        return {"rate": np.inf}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        dt = float(t[1] - t[0])
        top = float(np.max(np.abs(np.diff(u)))) / dt
        return {"rate": (0.05 * _span(u) * _slowest_pole(plant), top)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        lo, hi = self.bounds(t, u, plant)["rate"]
        return _log_grid(lo, hi, 12, "rate")

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        rate = params.get("rate", np.inf)
        return u if not np.isfinite(rate) else RateLimit(rate).apply(u, dt)


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
    parameter_names: ClassVar[tuple[str, ...]] = ("lower", "upper")
    grid_names: ClassVar[tuple[str, ...]] = ("lower", "upper")

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
        span, lo, hi = _span(u), float(np.min(u)), float(np.max(u))
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
        return [{"upper": x} for x in sorted(uppers, reverse=True)] + [{"lower": x} for x in sorted(lowers)]

    def data_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant) -> list[Params]:
        if self.placement == "input" or type(self).grid is not SaturationEffect.grid:  # a subclass's own grid wins
            return self.grid(t, u, plant)
        y = np.asarray(y, float)
        span, lo, hi = _span(y), float(np.min(y)), float(np.max(y))
        fractions = (0.0, 0.01, 0.03, 0.1, 0.2)
        return [{"upper": hi - f * span} for f in fractions] + [{"lower": lo + f * span} for f in fractions]

    def _clip(self, x: np.ndarray, params: Params) -> np.ndarray:
        lo, hi = params.get("lower", -np.inf), params.get("upper", np.inf)
        if not (np.isfinite(lo) or np.isfinite(hi)):
            return x
        big = 1e30
        return Saturation(max(lo, -big), min(hi, big)).apply(x, 1.0)

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        return self._clip(u, params) if self.placement == "input" else u

    def output_map(self, y: np.ndarray, params: Params) -> np.ndarray:
        return self._clip(y, params) if self.placement == "output" else y

    @property
    def screenable(self) -> bool:
        return self.placement == "input"


@dataclass(frozen=True)
class FrictionEffect(Effect):
    """Coulomb friction of a drive: the force ``fc`` [input units] against the motion, with sticking.

    The linear model ``G`` (output a position if ``G`` has a pole at the
    origin, else a velocity) is driven by ``u + f``, ``f = -fc sign(v)`` while
    the model's own velocity ``v`` (``s G`` or ``G``, simulated sample by sample) is
    nonzero; at rest the drive sticks while ``|u| <= fc`` (``f = -u``) and
    breaks away with ``f = -fc sign(u)`` otherwise; a velocity that changes
    sign within a sample stops there. The viscous part stays in ``G``. Exact
    for a first-order velocity model (mass and viscous friction,
    ``G = b/(s (s + a))``); for higher orders, stopping resets the velocity
    model's state. A delay of ``G`` acts on the command before the friction
    (whole samples). ``fc`` times the drive gain is the Coulomb force.

    A dead zone on the command is the same only while the force and the
    velocity have the same sign (steady motion); when a drive brakes they do
    not, and the dead zone then pushes where friction holds back.

    Examples
    --------
    >>> import numpy as np
    >>> G = Plant.from_string("1/(s*(s+1))")  # unit mass, unit viscous friction
    >>> t = np.arange(0, 6, 0.01); u = np.where((t >= 0.5) & (t < 3), 1.5, 0.0)
    >>> v = np.gradient(FrictionEffect().apply(G, t, u, {"fc": 1.0}), t)
    >>> round(float(v[290]), 3), round(abs(float(v[-1])), 3)  # 1.5 - 1 drives it; friction stops it after the push
    (0.455, 0.0)
    """

    name: ClassVar[str] = "friction"
    parameter_names: ClassVar[tuple[str, ...]] = ("fc",)
    grid_names: ClassVar[tuple[str, ...]] = ("fc",)
    needs_plant: ClassVar[bool] = True

    def off(self) -> Params:
        return {"fc": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"fc": (0.0, float(np.max(np.abs(u))))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        top = float(np.max(np.abs(u)))
        if top <= 0:
            raise ModelError("the input is zero; no friction can be fitted", where="record.u")
        return _log_grid(0.01 * top, 0.5 * top, 8, "fc")

    def base_input(self, plant: Plant, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        fc = float(params.get("fc", 0.0))
        if fc <= 0:
            return u
        return u + coulomb_force(plant, u, dt, fc)


def _velocity_model(plant: Plant) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of the velocity model: ``s G`` for a position output, else ``G``."""
    den = np.asarray(plant.den, float)
    if den[-1] == 0.0:
        den = den[:-1]
        if den.size < 2 or den[-1] == 0.0:
            raise ModelError("friction needs a drive with at most one pole at the origin", where="plant")
    num = np.asarray(plant.num, float)
    if num.size >= den.size:
        raise ModelError("friction needs a strictly proper velocity model s*G", where="plant")
    return num, den


def coulomb_force(plant: Plant, u: np.ndarray, dt: float, fc: float) -> np.ndarray:
    """Friction term ``f`` (input units) that makes ``G (u + f)`` a drive with Coulomb friction ``fc``.

    Parameters
    ----------
    plant : Plant
        Position model (one pole at the origin) or velocity model of the drive.
    u : numpy.ndarray
        Command samples (held), the drive at rest before the first one.
    dt : float
        Sample time [s].
    fc : float
        Coulomb friction in input units.

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> import numpy as np
    >>> coulomb_force(Plant.from_string("1/(s*(s+1))"), np.array([0.5, 2.0, 2.0, -0.5]), 0.1, 1.0).round(3).tolist()
    [-0.5, -1.0, -1.0, -1.0]
    """
    from scipy.linalg import expm

    from synth.sim.discretize import tf_to_ss

    num, den = _velocity_model(plant)
    A, B, C, _D = tf_to_ss(num, den)
    n = A.shape[0]
    M = expm(np.block([[A, B[:, None]], [np.zeros((1, n + 1))]]) * dt)
    Ad, Bd = M[:n, :n], M[:n, n]
    u = np.asarray(u, float)
    k = round(plant.delay / dt)
    ud = np.r_[np.full(k, 0.0), u[:u.size - k]] if k > 0 else u
    w = np.empty_like(ud)
    x = np.zeros(n)
    stuck = True
    for i in range(ud.size):
        ui = ud[i]
        if stuck:
            if abs(ui) <= fc:
                w[i] = 0.0
                continue
            w[i] = ui - fc * np.sign(ui)
            stuck = False
            direction = np.sign(ui)
        else:
            w[i] = ui - fc * direction
        x = Ad @ x + Bd * w[i]
        v = float(C @ x)
        if v * direction <= 0.0:  # the velocity reached zero within the sample: stop there
            x = np.zeros(n)
            stuck = True
    f = w - ud
    return np.r_[f[k:], np.full(k, f[-1])] if k > 0 else f


@dataclass(frozen=True)
class DeadzoneEffect(Effect):
    """Dead zone of half-width ``width`` around ``center`` (:class:`synth.sim.blocks.DeadZone`).

    The center is the command at rest (the first sample) unless given: the
    drive does not move until the command leaves the band around where it rests.

    Examples
    --------
    >>> import numpy as np
    >>> DeadzoneEffect().input_map(np.array([0.0, 0.5, 3.0]), 1.0, {"width": 1.0, "center": 0.0}).tolist()
    [0.0, 0.0, 2.0]
    """

    name: ClassVar[str] = "deadzone"
    parameter_names: ClassVar[tuple[str, ...]] = ("width", "center")
    grid_names: ClassVar[tuple[str, ...]] = ("width",)

    def off(self) -> Params:
        return {"width": 0.0, "center": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"width": (0.0, _span(u))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        span, c = _span(u), float(u[0])
        return [{"width": float(f * span), "center": c} for f in (0.02, 0.05, 0.1, 0.2, 0.35, 0.5)]

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        w = params.get("width", 0.0)
        return u if w <= 0 else DeadZone(w, params.get("center", 0.0)).apply(u, dt)


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

    def off(self) -> Params:
        return {"width": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"width": (0.0, _span(u))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        return [{"width": float(f * _span(u))} for f in (0.02, 0.05, 0.1, 0.2, 0.35, 0.5)]

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        w = params.get("width", 0.0)
        return u if w <= 0 else Backlash(w).apply(u, dt)


@dataclass(frozen=True)
class QuantizationEffect(Effect):
    """Command resolution ``step`` with the lattice at ``offset + k step`` (:class:`synth.sim.blocks.Quantizer`).

    ``offset`` in ``[0, step)`` places the lattice relative to the signal (a converter's zero, a
    PWM's bias). For a fixed linear model the output depends on ``(step, offset)`` only through which
    level each sample rounds to, so the error is piecewise constant in both: they are searched densely
    and jointly on the record with the linear model's denominator fixed
    (:func:`synth.gap.screen.quantizer_grid`, :meth:`data_grid`), never by a one-dimensional golden search.
    :meth:`grid` (no output data) is a coarse joint grid.

    Examples
    --------
    >>> import numpy as np
    >>> QuantizationEffect().input_map(np.array([0.4, 0.6, 1.7]), 1.0, {"step": 1.0}).tolist()
    [0.0, 1.0, 2.0]
    >>> QuantizationEffect().input_map(np.array([0.4, 0.6, 1.7]), 1.0, {"step": 1.0, "offset": 0.5}).tolist()
    [0.5, 0.5, 1.5]
    """

    name: ClassVar[str] = "quantization"
    parameter_names: ClassVar[tuple[str, ...]] = ("step", "offset")
    grid_names: ClassVar[tuple[str, ...]] = ("step", "offset")

    def off(self) -> Params:
        return {"step": 0.0, "offset": 0.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"step": (0.0, 0.5 * _span(u)), "offset": (0.0, 0.5 * _span(u))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        return [{**g, "offset": float(f * g["step"])} for g in _log_grid(0.005 * _span(u), 0.3 * _span(u), 8, "step")
                for f in (0.0, 0.25, 0.5, 0.75)]

    def data_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant) -> list[Params]:
        """The best point of the dense joint search of :func:`synth.gap.screen.quantizer_grid` on ``plant``.

        A subclass's own :meth:`grid` (a seeded search) wins.

        Examples
        --------
        >>> import numpy as np
        >>> t = np.arange(0, 8, 0.01); u = 1.0 + 0.8 * np.sin(2.3 * t) * np.sin(0.37 * t)
        >>> G = Plant.from_string("2/(0.2*s+1)")
        >>> y = QuantizationEffect().apply(G, t, u, {"step": 0.25, "offset": 0.07})
        >>> g = QuantizationEffect().data_grid(t, u, y, G)[0]
        >>> round(g["step"], 2), round(g["offset"], 2)
        (0.25, 0.07)
        """
        if type(self).grid is not QuantizationEffect.grid:
            return self.grid(t, u, plant)
        from synth.gap.screen import quantizer_grid  # the screen imports this module

        return quantizer_grid(plant, t, u, y, keep=1)

    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        q = params.get("step", 0.0)
        return u if q <= 0 else Quantizer(q, float(params.get("offset", 0.0)) % q).apply(u, dt)


@dataclass(frozen=True)
class SupplySagEffect(Effect):
    """Battery sag on fast command increases (:class:`synth.sim.blocks.SupplySag`, normalized).

    With a 1 V battery, 1 ohm, no static current and no brown-out the block is
    ``v = u (1 - sag max(0, u - u_f))``, ``tau u_f' + u_f = u``: linear in
    ``sag`` (a basis parameter), ``tau`` on a grid.

    Examples
    --------
    >>> import numpy as np
    >>> phi = SupplySagEffect().input_basis(np.array([1.0, 1.0, 2.0, 2.0]), 0.01, {"tau": 1.0})[0]
    >>> phi.round(4).tolist()  # -u (u - u_f) once the command steps up
    [0.0, 0.0, -2.0, -1.9801]
    """

    name: ClassVar[str] = "supply_sag"
    parameter_names: ClassVar[tuple[str, ...]] = ("sag", "tau")
    grid_names: ClassVar[tuple[str, ...]] = ("tau",)
    basis_names: ClassVar[tuple[str, ...]] = ("sag",)

    def off(self) -> Params:
        return {"sag": 0.0, "tau": 0.1}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"sag": (0.0, 1.0 / max(_span(u), 1e-12)), "tau": (float(t[1] - t[0]), float(t[-1] - t[0]))}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        slow = 1.0 / _slowest_pole(plant)
        return [{"tau": float(x)} for x in np.geomspace(0.05 * slow, 2.0 * slow, 5)]

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        eps = 1e-9 / max(float(np.max(np.abs(u))), 1.0) ** 2  # keeps the normalized voltage near 1: exact linearity
        block = SupplySag(v_open=1.0, r_internal=1.0, i_dynamic=eps, tau=params.get("tau", 0.1), v_reset=0.0)
        return [(block.apply(u, dt) - u) / eps]


@dataclass(frozen=True)
class StaticNonlinearityEffect(Effect):
    """Smooth static input map ``u + h (a2 x^2 + a3 x^3)``, ``x = (u - c)/h`` (c the center, h half the span).

    Examples
    --------
    >>> import numpy as np
    >>> e = StaticNonlinearityEffect()
    >>> e.plant_input(np.array([0.0, 1.0, 2.0]), 1.0, {"a2": 0.1, "a3": 0.0, "center": 1.0, "scale": 1.0}).tolist()
    [0.1, 1.0, 2.1]
    """

    name: ClassVar[str] = "static_nonlinearity"
    parameter_names: ClassVar[tuple[str, ...]] = ("a2", "a3", "center", "scale")
    basis_names: ClassVar[tuple[str, ...]] = ("a2", "a3")

    def off(self) -> Params:
        return {"a2": 0.0, "a3": 0.0, "center": 0.0, "scale": 1.0}

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        return {"a2": (-1.0, 1.0), "a3": (-1.0, 1.0)}

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        return [{"center": float(0.5 * (np.max(u) + np.min(u))), "scale": 0.5 * _span(u)}]

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        h = params.get("scale", 1.0)
        x = (np.asarray(u, float) - params.get("center", 0.0)) / h
        return [h * x**2, h * x**3]


# ------------------------------------------------------------------------------------------------ output side
@dataclass(frozen=True)
class DriftEffect(Effect):
    """Slow output drift: ``slope (t - t0)``, and ``+ curvature (t - t0)^2`` for ``order="quadratic"``.

    ``t0`` is the record's start. The default is the straight line: a curvature fitted on
    the training part of a record and carried over the held-out part grows quadratically
    beyond the data it was fitted on, so it is asked for explicitly
    (``make_effect("drift(quadratic)")``).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 3, 1.0)
    >>> DriftEffect().apply(Plant.from_string("1"), t, np.zeros(3), {"slope": 0.5}).tolist()
    [0.0, 0.5, 1.0]
    >>> DriftEffect("quadratic").basis_names, DriftEffect("quadratic").label
    (('slope', 'curvature'), 'drift(quadratic)')
    """

    order: str = "linear"
    t0: float = 0.0
    name: ClassVar[str] = "drift"
    side: ClassVar[str] = "output"

    def __post_init__(self) -> None:
        if self.order not in ("linear", "quadratic"):
            raise ModelError(f"drift order must be 'linear' or 'quadratic', got {self.order!r}", where="candidates")

    @property
    def parameter_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return ("slope", "curvature") if self.order == "quadratic" else ("slope",)

    @property
    def basis_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return self.parameter_names

    @property
    def label(self) -> str:
        return "drift" if self.order == "linear" else "drift(quadratic)"

    def off(self) -> Params:
        return {name: 0.0 for name in self.parameter_names}

    def output_basis(self, t: np.ndarray) -> list[np.ndarray]:
        tau = np.asarray(t, float) - self.t0
        return [tau, tau**2][: len(self.parameter_names)]


EFFECTS: dict[str, type[Effect]] = {
    "delay": DelayEffect, "lag": LagEffect, "resonance": ResonanceEffect, "rate_limit": RateLimitEffect,
    "saturation": SaturationEffect, "friction": FrictionEffect, "deadzone": DeadzoneEffect, "backlash": BacklashEffect,
    "quantization": QuantizationEffect, "supply_sag": SupplySagEffect,
    "static_nonlinearity": StaticNonlinearityEffect, "drift": DriftEffect,
}
"""Every effect class by name."""


def make_effect(spec: str | Effect) -> Effect:
    """An effect from its name (``"lag(sensor)"``: the lag at the sensor; ``"saturation(output)"``: clipping).

    Examples
    --------
    >>> make_effect("rate_limit").name, make_effect("lag(sensor)").label
    ('rate_limit', 'lag(sensor)')
    """
    if isinstance(spec, Effect):
        return spec
    text = str(spec).strip()
    if text in ("lag(sensor)", "sensor_lag"):
        return LagEffect("sensor")
    if text in ("lag(actuator)", "actuator_lag"):
        return LagEffect("actuator")
    if text in ("saturation(output)", "clipping"):
        return SaturationEffect("output")
    if text == "saturation(input)":
        return SaturationEffect("input")
    if text == "drift(quadratic)":
        return DriftEffect("quadratic")
    if text not in EFFECTS:
        raise ModelError(f"unknown effect {text!r}; known: {', '.join(EFFECTS)}", where="candidates")
    return EFFECTS[text]()
