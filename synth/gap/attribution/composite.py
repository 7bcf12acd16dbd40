"""Two effects in series: a first one accepted with fixed parameters, a second one fitted on top of it.

A forward selection accepts effect ``A`` with its fitted parameters and then asks
which effect ``B`` the model *augmented by A* still misses. :class:`NestedEffect`
is that augmented model as one :class:`synth.gap.effects.Effect`: its free
parameters are ``B``'s (grid, factor and basis parameters, fitted as ``B``'s own),
``A``'s parameters of every kind are fixed numbers inside it, so
:func:`synth.gap.attribution.refit.fit_augmented` and :func:`synth.gap.attribution.screen.screen_effect`
fit it unchanged, re-fitting the nominal coefficients jointly with ``B``.

The model is the physical chain, each side in the order ``A`` then ``B``::

    v = B.input(A.input(u))                      A's block and fixed basis terms, then B's block and basis terms
    y = B.output(A.output(G_AB v + c))           G_AB = B.augment_plant(A.augment_plant(G, pA), pB)

where ``A.output`` is ``A``'s output map and ``B.output`` adds ``B``'s output basis
terms (drift) before ``B``'s output map. ``A``'s linear factor (a lag, a resonance)
enters the casadi fit as a numeric transfer-function factor, exactly the one
``A.augment_plant`` multiplies ``G`` by, times ``B``'s factor in its own symbols.

Combinations the re-fit's hooks cannot represent exactly raise
:class:`synth.errors.ModelError` (never a silently wrong fit):

- ``A`` adds a delay (``delay`` with a nonzero value): the re-fit's linear fit fixes the
  delay at the nominal's (:func:`synth.gap.attribution.refit.fit_augmented` would fit the wrong
  delay); fold it into the nominal instead (``plant.with_delay(plant.delay + d)``, then
  fit ``B`` alone: the same model);
- ``A`` has output basis terms (``drift``): no hook subtracts a fixed time signal from the
  record; subtract ``A``'s drift from the measured output and fit ``B`` alone (exact
  unless ``B`` has an output map);
- ``A`` has an output map (``saturation(output)``) and ``B`` output basis terms: the drift
  would be added after the clip, and an output map gets no time;
- both need the linear model (``friction`` twice); one needs it (``friction``) and the
  other changes the rational part (``lag``, ``resonance``): the Coulomb force would be
  computed on the wrong velocity model; ``friction`` first and ``B`` with an input side:
  ``B``'s block would act after the force computed without it;
- ``B`` is itself a :class:`NestedEffect` (nest the first effect instead:
  ``NestedEffect(NestedEffect(A, pA, B), pB, C)``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.gap.effects.base import Effect, Params
from synth.gap.effects.registry import make_effect
from synth.plant import Plant

__all__ = ["NestedEffect", "numeric_factor"]

_UNIT = Plant(np.array([1.0]), np.array([1.0]))


def _poly(coeffs: np.ndarray) -> str:
    """A polynomial in ``s`` with numeric coefficients, as the structure parser reads it."""
    from synth.gap.attribution.nominal import monomial

    deg = coeffs.size - 1
    terms = [f"({float(c)!r})" + (f"*{monomial(deg - i)}" if deg - i else "") for i, c in enumerate(coeffs) if c != 0.0]
    return "+".join(terms) if terms else "0"


def numeric_factor(plant: Plant) -> str | None:
    """Transfer-function factor string of ``plant``'s rational part (numbers only); ``None`` for 1.

    Parameters
    ----------
    plant : Plant
        The factor, e.g. ``effect.augment_plant(unit, params)`` (its delay is ignored).

    Returns
    -------
    str or None

    Examples
    --------
    >>> numeric_factor(Plant.from_string("1/(0.5*s+1)"))
    '(((2.0))/((1.0)*s+(2.0)))'
    >>> numeric_factor(Plant.from_string("1")) is None
    True
    """
    num, den = np.asarray(plant.num, float), np.asarray(plant.den, float)
    if num.size == 1 and den.size == 1 and num[0] == den[0]:
        return None
    return f"(({_poly(num)})/({_poly(den)}))"


def _output_basis_count(e: Effect) -> int:
    return len(e.output_basis(np.array([0.0, 1.0])))


@dataclass(frozen=True)
class NestedEffect(Effect):
    """The nominal model augmented by ``first`` at fixed ``first_params``, plus ``second`` with free parameters.

    Parameters
    ----------
    first : Effect or str
        The accepted effect (a name goes through :func:`synth.gap.effects.make_effect`); may
        itself be a :class:`NestedEffect` (three effects and more).
    first_params : dict
        Its parameters, all kinds (grid, factor, basis), fixed; missing ones take
        ``first``'s "off" values.
    second : Effect or str
        The effect fitted on top; its parameters are this effect's parameters.

    Attributes
    ----------
    label : str
        ``"first+second"``, e.g. ``"static_nonlinearity+saturation(output)"``.
    name : str
        ``second``'s name (the screen's and the seeding's per-effect searches key on it).

    Raises
    ------
    ModelError
        A combination the re-fit cannot represent exactly (see the module text), or a
        parameter ``first`` does not have.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.gap.attribution.refit import fit_augmented
    >>> t = np.arange(0, 8, 0.01); u = np.where((t % 2) >= 1, 1.5, 0.0)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> e = NestedEffect("saturation", {"upper": 1.2}, "drift")  # accepted: the actuator's limit
    >>> e.label, e.first_params, e.parameter_names[0]
    ('saturation+drift', {'upper': 1.2}, 'slope')
    >>> y = e.apply(G, t, u, {"slope": 0.05})  # the limited command through G, plus a drift
    >>> round(float(y[150]), 6), round(float(2 * 1.2 * (1 - np.exp(-2.5)) + 0.05 * 1.5), 6)
    (2.277996, 2.277996)
    >>> f = fit_augmented(Plant.from_string("2.1/(0.21*s+1)"), t, u, y, e)  # the drift on top, G re-fitted
    >>> round(f.params["slope"], 6), f.plant.to_string(4)
    (0.05, '10/(s+5)')
    >>> NestedEffect("drift", {"slope": 0.05}, "rate_limit")
    Traceback (most recent call last):
    synth.errors.ModelError: effect drift+rate_limit: not supported as a nested effect: drift's fixed output terms ...
    """

    first: Effect
    first_params: dict[str, float] = field(hash=False)
    second: Effect

    def __new__(cls, *args: Any, **kwargs: Any) -> NestedEffect:
        # the re-fit recognizes an output map by the class overriding ``output_map`` (it then alternates the
        # linear fit with censoring): a pair with an output map is an instance of the subclass that has one
        if cls is NestedEffect and (args or kwargs):
            names = ("first", "first_params", "second")
            given = {**dict(zip(names, args)), **kwargs}
            try:
                parts = [make_effect(given[k]) for k in ("first", "second")]
            except (KeyError, ModelError):
                parts = []  # __init__ reports it
            if any(e.has_output_map for e in parts):
                cls = _OutputMapNestedEffect
        return super().__new__(cls)

    def __post_init__(self) -> None:
        first, second = make_effect(self.first), make_effect(self.second)
        object.__setattr__(self, "first", first)
        object.__setattr__(self, "second", second)
        pair = f"{first.label}+{second.label}"
        known = set(first.parameter_names) | set(first.off())
        unknown = sorted(set(self.first_params) - known)
        if unknown:
            raise ModelError(f"{first.label} has no parameter {', '.join(unknown)}", where=f"effect {pair}")
        p1 = {**first.off(), **{k: float(v) for k, v in self.first_params.items()}}
        object.__setattr__(self, "first_params", {k: float(v) for k, v in self.first_params.items()})
        object.__setattr__(self, "_p1", p1)
        h = first.augment_plant(_UNIT, p1)
        object.__setattr__(self, "_first_factor", numeric_factor(h))
        reason = self._unsupported(first, second, h)
        if reason:
            raise ModelError(f"not supported as a nested effect: {reason}", where=f"effect {pair}")

    @staticmethod
    def _unsupported(first: Effect, second: Effect, h: Plant) -> str | None:
        if isinstance(second, NestedEffect):
            return "the second effect must be a single effect (nest the first one instead)"
        if h.delay > 0.0:
            return (f"{first.label} adds a fixed delay ({h.delay:g} s) that the re-fit's linear fit cannot take "
                    f"(it fixes the nominal's); fit {second.label} on plant.with_delay(plant.delay + {h.delay:g})")
        if _output_basis_count(first):
            return (f"{first.label}'s fixed output terms cannot be held in the re-fit; subtract them from the "
                    f"measured output and fit {second.label} alone")
        if first.has_output_map and _output_basis_count(second):
            return f"{second.label}'s output terms would follow {first.label}'s output map, which gets no time"
        first_rational = numeric_factor(h) is not None
        if first.needs_plant and second.needs_plant:
            return "both need the linear model"
        if first.needs_plant and (second.changes_rational or second.has_input_side):
            return (f"{first.label}'s force would be computed without {second.label}'s "
                    f"{'linear factor' if second.changes_rational else 'input block'}")
        if second.needs_plant and first_rational:
            return f"{second.label}'s force would be computed on a velocity model including {first.label}'s factor"
        return None

    # -- the fixed first effect ------------------------------------------------------------------------------
    @property
    def fixed(self) -> Params:
        """``first``'s parameters as used (its "off" values filled in)."""
        return dict(self._p1)  # type: ignore[attr-defined]

    def _first_input(self, u: np.ndarray, dt: float, plant: Plant | None = None) -> np.ndarray:
        """What ``first`` hands on: its input block plus its fixed basis terms."""
        return self.first.plant_input(np.asarray(u, float), dt, self._p1, plant=plant)  # type: ignore[attr-defined]

    def _first_plant(self, plant: Plant) -> Plant:
        return self.first.augment_plant(plant, self._p1)  # type: ignore[attr-defined]

    # -- description: the second effect's ---------------------------------------------------------------------
    @property
    def name(self) -> str:  # type: ignore[override]
        return self.second.name

    @property
    def side(self) -> str:  # type: ignore[override]
        return str(self.second.to_dict()["side"])  # a placement included (a sensor lag, output clipping)

    @property
    def parameter_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return tuple(self.second.parameter_names)

    @property
    def grid_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return tuple(self.second.grid_names)

    @property
    def factor_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return tuple(self.second.factor_names)

    @property
    def basis_names(self) -> tuple[str, ...]:  # type: ignore[override]
        return tuple(self.second.basis_names)

    @property
    def needs_plant(self) -> bool:  # type: ignore[override]
        return bool(self.first.needs_plant or self.second.needs_plant)

    @property
    def screenable(self) -> bool:
        return bool(self.first.screenable and self.second.screenable and not self.needs_plant)

    @property
    def has_output_map(self) -> bool:
        return bool(self.first.has_output_map or self.second.has_output_map)

    @property
    def has_input_side(self) -> bool:
        return bool(self.first.has_input_side or self.second.has_input_side)

    def screen_points(self, grid: list[Params], t: np.ndarray, plant: Plant) -> list[Params]:
        """``second``'s screen points on this effect's grid."""
        return self.second.screen_points(grid, t, plant)

    def seed_grid(self, point: Params, u_train: np.ndarray | None = None) -> list[Params]:
        """``second``'s seeded grid."""
        return self.second.seed_grid(point, u_train)

    @property
    def label(self) -> str:
        return f"{self.first.label}+{self.second.label}"

    def off(self) -> Params:
        return self.second.off()

    def _dt(self, t: np.ndarray) -> float:
        t = np.asarray(t, float)
        return float((t[-1] - t[0]) / (t.size - 1))

    def bounds(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, tuple[float, float]]:
        """``second``'s bounds on the command it sees (``first``'s input) and the model augmented by ``first``."""
        G1 = self._first_plant(plant)
        return self.second.bounds(t, self._first_input(u, self._dt(t), G1), G1)

    def grid(self, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params]:
        """``second``'s grid on the command it sees and the model augmented by ``first``."""
        G1 = self._first_plant(plant)
        return self.second.grid(t, self._first_input(u, self._dt(t), G1), G1)

    def data_grid(self, t: np.ndarray, u: np.ndarray, y: np.ndarray, plant: Plant) -> list[Params]:
        """``second``'s data grid likewise (a subclass's own :meth:`grid`, e.g. a seeded search, wins)."""
        if type(self).grid is not NestedEffect.grid:
            return self.grid(t, u, plant)
        G1 = self._first_plant(plant)
        return self.second.data_grid(t, self._first_input(u, self._dt(t), G1), y, G1)

    # -- model ----------------------------------------------------------------------------------------------
    def input_map(self, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        """``second``'s block on ``first``'s input (block and fixed basis terms)."""
        return self.second.input_map(self._first_input(u, dt), dt, params)

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        """``second``'s input basis on ``first``'s input (none when ``first`` needs the linear model)."""
        if self.first.needs_plant:  # then second has no input side (checked at construction)
            return []
        return self.second.input_basis(self._first_input(u, dt), dt, params)

    def base_input(self, plant: Plant, u: np.ndarray, dt: float, params: Params) -> np.ndarray:
        """The input blocks given the (augmented) linear model, for a ``first`` or ``second`` that needs it."""
        if self.first.needs_plant:
            return self.second.input_map(self._first_input(u, dt, plant), dt, params)
        v1 = self._first_input(u, dt)
        if self.second.needs_plant:
            return self.second.base_input(plant, v1, dt, params)
        return self.second.input_map(v1, dt, params)

    def output_basis(self, t: np.ndarray) -> list[np.ndarray]:
        return self.second.output_basis(t)

    def factor(self, params: Params | None = None) -> str | None:
        """``first``'s factor with its numbers times ``second``'s factor in its symbols.

        Examples
        --------
        >>> NestedEffect("lag", {"tau": 0.5}, "resonance").factor({"wn": 10.0})
        '(((2.0))/((1.0)*s+(2.0)))*(100.0/(s^2+2*(zeta^2/(1+zeta^2))*10.0*s+100.0))'
        """
        second = self.second.factor(params)
        parts = [f for f in (self._first_factor, None if second is None else f"({second})") if f]  # type: ignore[attr-defined]
        return "*".join(parts) if parts else None

    def augment_plant(self, plant: Plant, params: Params) -> Plant:
        return self.second.augment_plant(self._first_plant(plant), params)

    def to_factor(self, params: Params) -> dict[str, float]:
        return self.second.to_factor(params)

    def from_factor(self, values: dict[str, float]) -> Params:
        return self.second.from_factor(values)

    def to_dict(self) -> dict[str, Any]:
        """``{"effect", "side", "parameters", "first", "first_parameters", "second"}``.

        Examples
        --------
        >>> d = NestedEffect("saturation", {"upper": 0.8}, "rate_limit").to_dict()
        >>> d["effect"], d["parameters"], d["first_parameters"]
        ('saturation+rate_limit', ['rate'], {'lower': -inf, 'upper': 0.8})
        """
        return {"effect": self.label, "side": self.side, "parameters": list(self.parameter_names),
                "first": self.first.to_dict(), "first_parameters": self.fixed, "second": self.second.to_dict()}


@dataclass(frozen=True)
class _OutputMapNestedEffect(NestedEffect):
    """A :class:`NestedEffect` whose first or second effect has an output map (clipping)."""

    def output_map(self, y: np.ndarray, params: Params) -> np.ndarray:
        """``first``'s output map (fixed), then ``second``'s."""
        return self.second.output_map(self.first.output_map(y, self._p1), params)  # type: ignore[attr-defined]
