"""What every effect is: the :class:`Effect` base class and the helpers its families share.

An effect adds one mechanism to the nominal linear model ``G`` (rational transfer function times an
exact delay) and is switched off by a parameter value, so the nominal model is nested in every
augmented one. Each effect describes itself on its class (see :class:`Effect`): where it acts
(``side``), how each parameter is fitted (grid, factor or basis parameters), its search grids for the
screen (:meth:`Effect.screen_grid`) and for the joint re-fit seeded by the screen
(:meth:`Effect.seed_grid`), and whether it is a default candidate (``default_candidates``, or the
reason it is not, ``excluded_because``). The families live one per module of
:mod:`synth.gap.effects`; :mod:`synth.gap.effects.registry` lists them.

How each parameter is fitted is part of the effect's description: *grid* parameters (non-smooth in
the output: a rate, a limit, a width, a step) are searched on the deterministic grid
:meth:`Effect.grid` built from the record; *factor* parameters (``tau``, ``wn``, ``zeta``, the delay)
join the nominal coefficients in the casadi fit, the grid only giving starting values; *basis*
parameters (``a2``, ``a3``, ``sag``, ``slope``, ``curvature``) enter the output linearly for a given
linear model and are solved by least squares (:mod:`synth.gap.attribution.refit`).

``Effect.apply(plant, t, u, params)`` is the augmented model's output; the nominal model is
``Effect.apply`` with the effect switched off. Two effects need more than the command: output
clipping is fitted on the output's scale (its grid comes from the measured output,
:meth:`Effect.data_grid`, and the linear part is fitted to the data with the clipped samples
censored, :meth:`Effect.censor`), and Coulomb friction depends on the model's own velocity
(:meth:`Effect.base_input` gets the linear model; the re-fit alternates the friction signal and the
linear fit until the error settles).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from synth.errors import ModelError
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["NESTED_CRITICAL", "Effect", "Params", "command_span", "fastest_pole", "log_grid", "slowest_pole",
           "unit_numerators"]

Params = dict[str, float]
"""An effect's parameter values by name."""

NESTED_CRITICAL = 3.84  # noise variances of SSR a richer nested form must gain (one parameter's LR test at 95 %)


def command_span(u: np.ndarray) -> float:
    """Span ``max(u) - min(u)`` of a command, which must not be constant.

    Parameters
    ----------
    u : numpy.ndarray
        Command samples.

    Returns
    -------
    float

    Raises
    ------
    ModelError
        The command is constant (no effect can be fitted on it).

    Examples
    --------
    >>> command_span(np.array([0.0, 2.0, 1.0]))
    2.0
    """
    span = float(np.max(u) - np.min(u))
    if span <= 0:
        raise ModelError("the input is constant; no effect can be fitted", where="record.u")
    return span


def slowest_pole(plant: Plant) -> float:
    """Magnitude of the slowest nonzero pole [rad/s] (1 rad/s for a static gain).

    Examples
    --------
    >>> slowest_pole(Plant.from_string("1/((s+2)*(s+10))")), slowest_pole(Plant.from_string("3"))
    (2.0, 1.0)
    """
    p = np.abs(plant.poles())
    p = p[p > 0]
    return float(np.min(p)) if p.size else 1.0


def fastest_pole(plant: Plant) -> float:
    """Magnitude of the fastest nonzero pole [rad/s] (1 rad/s for a static gain).

    Examples
    --------
    >>> fastest_pole(Plant.from_string("1/((s+2)*(s+10))"))
    10.0
    """
    p = np.abs(plant.poles())
    p = p[p > 0]
    return float(np.max(p)) if p.size else 1.0


def log_grid(lo: float, hi: float, n: int, name: str) -> list[Params]:
    """``n`` points of parameter ``name`` spaced evenly in log from ``lo`` to ``hi``.

    Examples
    --------
    >>> log_grid(1.0, 100.0, 3, "rate")
    [{'rate': 1.0}, {'rate': 10.0}, {'rate': 100.0}]
    """
    return [{name: float(x)} for x in np.geomspace(lo, hi, n)]


def unit_numerators(plant: Plant) -> list[Plant]:
    """One plant per nonzero numerator coefficient of ``plant`` (that coefficient 1, the others 0).

    The output of ``plant`` is linear in its numerator: the screen and the quantizer's dense search fit
    the numerator by least squares on these plants' outputs.

    Examples
    --------
    >>> [g.num.tolist() for g in unit_numerators(Plant.from_string("(2*s+3)/(s^2+s+1)"))]
    [[1.0, 0.0], [1.0]]
    """
    out = []
    for i, c in enumerate(plant.num):
        if c != 0.0:
            e = np.zeros_like(plant.num, dtype=float)
            e[i] = 1.0
            out.append(Plant(e, plant.den, plant.delay, plant.input, plant.output, plant.label))
    return out


@dataclass(frozen=True)
class Effect:
    """One mechanism the nominal model may be missing (base class).

    Attributes
    ----------
    name : str
        Effect name as it appears in the verdict.
    side : str
        Where it acts: ``"input"`` (on the command before the plant), ``"output"`` (after it) or
        ``"linear"`` (in the plant: changes the linear model).
    parameter_names : tuple of str
        The effect's parameters, as keys of ``params``.
    grid_names, factor_names, basis_names : tuple of str
        How each parameter is fitted (see the module text).
    spellings : dict
        Names :func:`synth.gap.effects.registry.make_effect` builds this class from besides ``name``,
        each with its constructor arguments (``"lag(sensor)"``: ``{"placement": "sensor"}``).
    default_candidates : tuple of str
        Its labels in :data:`synth.gap.effects.registry.DEFAULT_CANDIDATES`, in order (``()``: not a
        default candidate, and ``excluded_because`` says why).
    excluded_because : str
        Why the class is not a default candidate (empty when it is).
    golden_search : bool
        The screen refines the best grid point by a golden-section search in its first grid
        parameter (false for a piecewise-constant cost).
    folds_into_plant : bool
        Once accepted, the effect is folded into the linear model and a further effect is fitted
        alone on top of it (an extra delay) instead of nested with it.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.gap.effects.actuator import RateLimitEffect
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
    spellings: ClassVar[dict[str, dict[str, str]]] = {}
    default_candidates: ClassVar[tuple[str, ...]] = ()
    excluded_because: ClassVar[str] = ""
    golden_search: ClassVar[bool] = True
    folds_into_plant: ClassVar[bool] = False
    #: grid parameters a fit also searches together from its best point (:mod:`synth.gap.attribution.joint_search`)
    joint_search: ClassVar[bool] = False

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

    # -- search grids ------------------------------------------------------------------------------------------
    def screen_points(self, grid: list[Params], t: np.ndarray, plant: Plant) -> list[Params]:
        """The screen's search points given the effect's own :meth:`grid` (default: that grid).

        The screen holds the denominator fixed and has no smooth search of its own: an effect whose
        joint fit treats a parameter as smooth (the extra delay, a resonance's damping) gives it a
        grid here.

        Examples
        --------
        >>> from synth.gap.effects.dynamics import ResonanceEffect
        >>> g = ResonanceEffect().screen_points([{"wn": 20.0, "zeta": 0.2}], np.arange(3.0), Plant.from_string("1"))
        >>> [p["zeta"] for p in g]
        [0.05, 0.1, 0.2, 0.4, 0.7]
        """
        return grid

    def screen_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant,
                    mask: np.ndarray | None = None) -> list[Params]:
        """Search points of :func:`synth.gap.attribution.screen.screen_effect` on the training record.

        Parameters
        ----------
        t, u, y : numpy.ndarray
            Training record.
        plant : Plant
            The linear model whose denominator the screen holds.
        mask : numpy.ndarray of bool, optional
            Training samples that count in the cost.

        Returns
        -------
        list of dict
            Default: :meth:`screen_points` of :meth:`grid`.

        Examples
        --------
        >>> import numpy as np
        >>> from synth.gap.effects.actuator import BacklashEffect
        >>> t = np.arange(0, 1, 0.1); u = np.linspace(0, 2, 10)
        >>> BacklashEffect().screen_grid(t, u, u, Plant.from_string("1/(s+1)"))[0]
        {'width': 0.04}
        """
        return self.screen_points(self.grid(t, u, plant), t, plant)

    def refine_screen(self, cost: Callable[[Params], float], best: Params, t: np.ndarray, u: np.ndarray,
                      plant: Plant) -> Params:
        """A local search of the screen from its best point so far (default: none, the point itself).

        The screen's golden-section search moves one grid parameter; an effect whose grid parameters
        act together (several of them nonzero at once) searches them here.

        Parameters
        ----------
        cost : callable
            The screen's training SSR of a parameter point (cached, milliseconds per new point).
        best : dict
            The best point of the grid and the golden-section search.
        t, u : numpy.ndarray
            Training record's time [s] and command.
        plant : Plant
            The linear model whose denominator the screen holds.

        Returns
        -------
        dict
            The point to keep (never worse than ``best``).

        Examples
        --------
        >>> from synth.gap.effects.actuator import RateLimitEffect
        >>> RateLimitEffect().refine_screen(lambda p: 0.0, {"rate": 2.0}, np.arange(3.0), np.zeros(3),
        ...                                 Plant.from_string("1"))
        {'rate': 2.0}
        """
        return best

    def seed_grid(self, point: Params, u_train: np.ndarray | None = None) -> list[Params]:
        """The joint re-fit's grid started at the screened ``point``: it and its neighbours (+-15 % in the key).

        Parameters
        ----------
        point : dict
            The screened parameters (basis parameters left out).
        u_train : numpy.ndarray, optional
            Training command (an effect whose bracket scales with it).

        Returns
        -------
        list of dict

        Examples
        --------
        >>> from synth.gap.effects.actuator import RateLimitEffect
        >>> [round(g["rate"], 3) for g in RateLimitEffect().seed_grid({"rate": 2.0})]
        [1.739, 2.0, 2.3]
        """
        keys = [k for k in self.grid_names if k in point and np.isfinite(point[k]) and point[k] > 0]
        grid = [point] if not keys else [{**point, keys[0]: point[keys[0]] * f} for f in (1 / 1.15, 1.0, 1.15)]
        return [dict(g) for g in grid]

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
    #: driven by a measured aux channel (spelled ``name(channel)``, bound to the records before fitting)
    aux_driven: ClassVar[bool] = False

    @property
    def aux_channel(self) -> str | None:
        """The measured channel that drives the effect (``None``: the command alone)."""
        return None

    def bind(self, records: Any, plant: Plant | None = None) -> Effect:
        """The effect reading what it needs from the records and the nominal model (default: itself; see the
        aux-driven effects and the cubic spring)."""
        return self

    def required_samples(self, nominal_coefficients: int) -> int:
        """Training samples the joint fit needs: 10 per free parameter (the nominal coefficients, the
        effect's parameters and the output constant).

        Examples
        --------
        >>> from synth.gap.effects import make_effect
        >>> make_effect("delay").required_samples(3), make_effect("saturation").required_samples(3)
        (50, 60)
        """
        return 10 * (nominal_coefficients + len(self.parameter_names) + 1)

    def required_duration(self, plant: Plant) -> float:
        """Shortest record [s] the effect can be judged on: one time constant of the model's slowest mode
        (a record shorter than that holds no settled response to tell a gain from a dynamic effect).

        Examples
        --------
        >>> from synth.gap.effects import make_effect
        >>> make_effect("lag").required_duration(Plant.from_string("1/((s+0.5)*(s+10))"))
        2.0
        """
        return 1.0 / slowest_pole(plant)

    @property
    def screenable(self) -> bool:
        """Whether :mod:`synth.gap.attribution.screen` can fit it (an input-side block on a fixed input, no output map)."""
        return not self.needs_plant

    @property
    def has_output_map(self) -> bool:
        """Whether a static map acts on the output (:meth:`output_map` is not the identity).

        Examples
        --------
        >>> from synth.gap.effects import make_effect
        >>> [make_effect(n).has_output_map for n in ("saturation", "saturation(output)", "drift")]
        [False, True, False]
        >>> [make_effect(n).has_input_side for n in ("saturation", "friction", "lag")]
        [True, True, False]
        >>> [make_effect(n).changes_rational for n in ("lag", "resonance", "delay")]
        [True, True, False]
        """
        return type(self).output_map is not Effect.output_map

    @property
    def has_input_side(self) -> bool:
        """Whether it changes what drives the linear part (an input block, basis terms or a plant-dependent input)."""
        return bool(self.needs_plant or type(self).input_map is not Effect.input_map
                    or type(self).input_basis is not Effect.input_basis)

    @property
    def changes_rational(self) -> bool:
        """Whether it may change the rational part of the linear model (a lag, a resonance; not a delay)."""
        return type(self).augment_plant is not Effect.augment_plant

    def admissible(self, params: Params, u: np.ndarray) -> bool:
        """Whether ``params`` describe this effect on the command ``u`` and not another one (default: always)."""
        return True

    def nested_variants(self) -> tuple[Effect, Effect] | None:
        """A simpler and a richer form the joint fit tries both of (the richer kept only when significantly
        better; :func:`synth.gap.attribution.refit.fit_augmented`), or ``None`` (default): one form."""
        return None

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
        if any(params.get(name, 0.0) != 0.0 for name in self.basis_names):  # switched off: no basis needed
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
        >>> from synth.gap.effects.actuator import SaturationEffect
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
        >>> from synth.gap.effects.timing import LagEffect
        >>> LagEffect("sensor").to_dict()
        {'effect': 'lag(sensor)', 'side': 'output', 'parameters': ['tau']}
        """
        return {"effect": self.label, "side": self.side, "parameters": list(self.parameter_names)}
