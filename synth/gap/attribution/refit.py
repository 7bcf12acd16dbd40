"""Joint re-fit of the nominal model and one effect's parameters by simulation error.

The nominal linear model is written as a structure in its own nonzero
coefficients, ``(n_1 s + n_0)/(s^2 + d_1 s + d_0)`` (monic denominator;
coefficients that are zero in the nominal, such as an integrator's, stay zero)
and every coefficient is re-fitted together with the effect, so an effect is
never credited with what a parameter re-fit alone would do. The fit minimizes
the simulation error ``sum_k (y_k - yhat_k)^2`` with
``yhat = c + G_aug (N(u) + sum_j a_j phi_j(u)) + sum_j d_j psi_j(t)``:

- the linear part ``G_aug`` (nominal coefficients, effect factor parameters
  such as a lag's ``tau``, a resonance's ``wn, zeta``, and the delay for the
  ``delay`` effect) by :func:`synth.ident.timefit.fit_structure` with its
  convolution solver (exact zero-order-hold discretization with fractional
  delay, Levenberg-Marquardt on exact sensitivities), started at the nominal
  coefficients;
- the input block ``N`` (rate limit, saturation, dead zone, backlash,
  quantizer: not smooth in their parameter) by the effect's deterministic grid
  and then a search in the log of the parameter between the best grid point's
  neighbours (parabolic interpolation through the three when the best is inside
  the grid, golden section otherwise), every point a full casadi fit of the rest;
- the *basis* parameters ``a_j, d_j`` and the output constant ``c`` (linear in
  the output for a given ``G_aug``) by linear least squares, alternating with
  the casadi fit (until the SSR settles, at most twelve rounds);
- an output map ``M`` (clipping: ``yhat = M(c + G_aug N(u))``) by censoring: the
  linear part is fitted to ``y + yhat_lin - M(yhat_lin)``, so a clipped sample
  keeps the residual it has in the clipped model, alternating as above;
- an input side that depends on the linear model (Coulomb friction, driven by
  the model's own velocity) by alternating the friction signal of the current
  linear model with the casadi fit, as above.

Intervals: casadi-fitted parameters carry the Jacobian intervals of :class:`synth.ident.timefit.TimeFitResult`
(of the final point, not the grid point it was refined from); grid parameters a profile interval (the parameter
values whose training SSR is within ``chi2_1(0.95) s^2`` of the best, ``s^2 = SSR/N``, interpolated in log between
grid points); basis parameters their least-squares interval. All assume white residuals and are too narrow otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from synth.data.record import record_from_arrays
from synth.errors import DataError, ModelError
from synth.gap.attribution.convergence import cannot_reach
from synth.gap.attribution.golden import golden_section, log_bracket, parabolic_section
from synth.gap.attribution.joint_search import fewest_limits, ranges_within, search_from_points
from synth.gap.attribution.nested import fit_nested
from synth.gap.attribution.nominal import monomial, nominal_structure, plant_from_values
from synth.gap.attribution.profile import profile_interval, profile_level
from synth.gap.effects.base import Effect, Params
from synth.ident.simulate import simulate_plant
from synth.ident.timefit import fit_structure
from synth.plant import Plant

__all__ = ["AugmentedFit", "fit_augmented", "monomial", "nominal_structure"]

_ROUNDS = 12  # most alternations of the casadi fit and the least-squares basis step
_ROUNDS_TOL = 1e-6  # ... stopped when the training SSR changes less than this (relative)
_GOLDEN = 12  # most golden-section evaluations after the grid
_GOLDEN_TOL = 0.002  # ... or until the bracket is this narrow in log (0.2 %: finer than a long record's profile interval)


@dataclass(frozen=True)
class _NoEffect(Effect):
    """The re-fit alone (an effect with nothing to add)."""

    name: ClassVar[str] = "parameter_mismatch"


@dataclass(frozen=True, eq=False)
class AugmentedFit:
    """The re-fitted nominal model with one effect (``effect=None``: the re-fit alone).

    Attributes
    ----------
    effect : Effect or None
    plant : Plant
        Re-fitted nominal linear model (without the effect's factor).
    params : dict
        Effect parameters (the effect's "off" values filled in).
    offset : float
        Output constant ``c``.
    nominal : dict
        Re-fitted nominal coefficients (and ``delay``).
    parameter_ci : dict
        Approximate 95 % interval of each fitted effect parameter (see the module text).
    ssr : float
        Training sum of squared simulation errors.
    samples : int
        Training samples.
    profile : list of (dict, float)
        Every grid / search point tried and its training SSR.
    solver : dict
        IPOPT status of the best point.
    """

    effect: Effect | None
    plant: Plant
    params: Params
    offset: float
    nominal: dict[str, float]
    parameter_ci: dict[str, tuple[float, float]]
    ssr: float
    samples: int
    profile: list[tuple[Params, float]] = field(repr=False, default_factory=list)
    solver: dict[str, Any] = field(default_factory=dict)

    def predict(self, t: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Model output on a command (the record simulated from rest at its first sample).

        Examples
        --------
        >>> import numpy as np
        >>> t = np.arange(0, 3, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
        >>> y = simulate_plant(Plant.from_string("2/(s+2)"), t, u) + 1.0
        >>> f = fit_augmented(Plant.from_string("2.1/(s+2)"), t, u, y)
        >>> round(float(np.max(np.abs(f.predict(t, u) - y))), 6)
        0.0
        """
        eff = self.effect if self.effect is not None else _NoEffect()
        return eff.apply(self.plant, t, u, self.params, offset=self.offset)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary.

        Examples
        --------
        >>> import numpy as np
        >>> t = np.arange(0, 3, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
        >>> G = Plant.from_string("2/(s+2)")
        >>> d = fit_augmented(G, t, u, simulate_plant(G, t, u)).to_dict()
        >>> d["effect"], d["tf"]
        (None, '2/(s+2)')
        """
        eff = self.effect
        return {
            "effect": eff.label if eff is not None else None,
            "parameters": {k: float(self.params[k]) for k in (eff.parameter_names if eff else ())},
            "parameter_ci": {k: [float(a), float(b)] for k, (a, b) in self.parameter_ci.items()},
            "nominal": dict(self.nominal),
            "tf": self.plant.to_string(6),
            "offset": self.offset,
            "ssr": self.ssr,
            "samples": self.samples,
            "solver": dict(self.solver),
        }


@dataclass
class _Point:
    params: Params
    ssr: float
    plant: Plant
    offset: float
    nominal: dict[str, float]
    ci: dict[str, tuple[float, float]]
    solver: dict[str, Any]
    key: str | None = None


def _linear_fit(plant: Plant, effect: Effect, params: Params, t: np.ndarray, v: np.ndarray, y: np.ndarray,
                formula: str, start: dict[str, float], weights: np.ndarray | None = None,
                ) -> tuple[Plant, Params, dict[str, float], dict[str, tuple[float, float]], dict[str, Any]]:
    """casadi fit of the nominal coefficients and the effect's factor parameters on the plant input ``v``."""
    factor = effect.factor(params)
    full = f"({formula})*{factor}" if factor else formula
    init = {**start, **effect.to_factor(params)}
    fit_delay = "delay" in effect.factor_names
    if fit_delay:
        init["delay"] = plant.delay + float(params.get("delay", 0.0))
    rec = record_from_arrays(t, v, y)
    # the re-fits are many and share a structure: the convolution solver builds no symbolic graph per fit
    res = fit_structure(rec, full, delay="fit" if fit_delay else plant.delay, initial=init, weights=weights,
                        solver="convolution", rtol=0.1 * _ROUNDS_TOL)  # finer than the alternation needs
    bounds = _stable_bounds(plant, start)
    if bounds and any(res.parameters[k] < 0.0 for k in bounds):  # rare: again with the bounds (IPOPT is slower)
        res = fit_structure(rec, full, delay="fit" if fit_delay else plant.delay, initial=init, weights=weights,
                            lower=bounds)  # IPOPT: an interior point never lands on the bound (an integrator)
    new = dict(params)
    ci: dict[str, tuple[float, float]] = {}
    names = [k for k in effect.factor_names if k != "delay"]
    new.update(effect.from_factor({k: res.parameters[k] for k in names}))
    for k in names:  # the structure holds the square root: map the interval's ends (0 if it spans zero)
        lo, hi = res.ci95[k]
        ends = sorted(effect.from_factor({k: x})[k] for x in (lo, hi))
        ci[k] = (0.0 if lo < 0 < hi else ends[0], ends[1])
    if "delay" in effect.factor_names:
        new["delay"] = res.delay - plant.delay
        lo, hi = res.ci95.get("delay", (res.delay, res.delay))
        ci["delay"] = (lo - plant.delay, hi - plant.delay)
    nominal = {k: float(res.parameters[k]) for k in start}
    nominal["delay"] = plant.delay  # an extra delay is the effect's parameter, not the nominal's
    return plant_from_values(plant, nominal, plant.delay), new, nominal, ci, dict(res.solver)


def _stable_bounds(plant: Plant, start: dict[str, float]) -> dict[str, float] | None:
    """Lower bound 0 on the denominator coefficients of a stable nominal model.

    Positive coefficients are necessary for a Hurwitz polynomial (and sufficient up to second order):
    a re-fit of a few-% mismatch has no business moving a stable plant's pole into the right half-plane,
    where a short training record can hide an exponential that ruins every held-out prediction.

    Examples
    --------
    >>> _stable_bounds(Plant.from_string("2/(s^2+3*s+2)"), {"n0": 2.0, "d1": 3.0, "d0": 2.0})
    {'d1': 0.0, 'd0': 0.0}
    >>> _stable_bounds(Plant.from_string("2/(s^2-1)"), {"n0": 2.0, "d0": -1.0}) is None
    True
    """
    poles = plant.poles()
    if poles.size == 0 or np.max(poles.real) >= 0.0:
        return None
    return {k: 0.0 for k in start if k.startswith("d") and k != "delay"} or None


def _basis_step(effect: Effect, G: Plant, params: Params, t: np.ndarray, u: np.ndarray, y: np.ndarray,
                dt: float, mask: np.ndarray | None = None) -> tuple[Params, float, dict[str, tuple[float, float]],
                                                                    float]:
    """Least squares for the output constant and the basis parameters, the linear model fixed."""
    Gaug = effect.augment_plant(G, params)
    v0 = effect.base_input(Gaug, u, dt, params) if effect.needs_plant else effect.input_map(u, dt, params)
    cols = [np.ones_like(y)]
    phis = effect.input_basis(u, dt, params)
    cols += [simulate_plant(Gaug, t, phi) for phi in phis]
    cols += list(effect.output_basis(t))
    y0 = simulate_plant(Gaug, t, v0)
    if phis:  # the gain of G moves with the input basis (a ridge that alternation alone climbs slowly)
        cols.append(y0)
        target = y.copy()
    else:
        target = y - y0
    X = np.column_stack(cols)
    if mask is not None:  # only the fitted samples
        X, target = X[mask], target[mask]
    scale = np.maximum(np.sqrt(np.sum(X**2, axis=0)), 1e-300)
    Xs = X / scale
    coef, *_ = np.linalg.lstsq(Xs, target, rcond=None)
    r = target - Xs @ coef
    dof = max(1, target.size - X.shape[1])
    s2 = float(r @ r) / dof
    try:
        cov = s2 * np.linalg.inv(Xs.T @ Xs)
    except np.linalg.LinAlgError:
        cov = s2 * np.linalg.pinv(Xs.T @ Xs)
    coef = coef / scale
    sd = np.sqrt(np.clip(np.diag(cov), 0, None)) / scale
    gain = float(coef[-1]) if phis else 1.0
    if phis and not (np.isfinite(gain) and gain > 0):
        raise ModelError("the input basis step lost the plant's gain", where=f"effect {effect.label}")
    new = dict(params)
    ci = {}
    for j, name in enumerate(effect.basis_names):
        g = gain if j < len(phis) else 1.0
        new[name] = float(coef[j + 1]) / g
        ci[name] = (float(coef[j + 1] - 1.96 * sd[j + 1]) / g, float(coef[j + 1] + 1.96 * sd[j + 1]) / g)
    return new, float(coef[0]), ci, gain


def _fit_point(plant: Plant, effect: Effect, params: Params, t: np.ndarray, u: np.ndarray, y: np.ndarray,
               formula: str, start: dict[str, float], weights: np.ndarray | None = None,
               warm: bool = False, early_stop: bool = True) -> _Point:
    """One point of the effect's search: the alternation below from both block orders when the effect has basis
    parameters, the lower training SSR kept.

    The alternation of the casadi fit and the basis least squares is block-coordinate descent. Started with the
    basis at its grid value (the plant first), a re-fit can bend a pole towards zero and absorb most of a drift
    or of an input basis term in the linear part; the two blocks then trade along a ridge and twelve rounds move
    little (a drift fitted at a quarter of its slope, its training error above the truth's). Started with the
    basis' least squares against the nominal model (the basis first), the effect takes its own signal before the
    plant can. Neither order is better on every record, and the effect's parameters are nested, so both are
    fitted and the lower training SSR wins. The second stops early once its SSR is heading
    (:func:`synth.gap.attribution.convergence.cannot_reach`) to within one noise variance ``SSR/N`` of the
    first's or above: mostly the two orders end at the same point, the second after a longer climb. A ``warm``
    start (``params`` and ``start`` from a fitted point, basis parameters included) is past that choice: the
    plant-first order alone continues from it.
    """
    first = _alternate(plant, effect, params, t, u, y, formula, start, weights, basis_first=False)
    if not effect.basis_names or warm:
        return first
    n = y.size if weights is None else int(np.sum(np.asarray(weights) > 0))
    beat = first.ssr * (1.0 - 1.0 / max(n, 1)) if np.isfinite(first.ssr) and early_stop else None
    second = _alternate(plant, effect, params, t, u, y, formula, start, weights, basis_first=True, beat=beat)
    return second if second.ssr < first.ssr else first


def _alternate(plant: Plant, effect: Effect, params: Params, t: np.ndarray, u: np.ndarray, y: np.ndarray,
               formula: str, start: dict[str, float], weights: np.ndarray | None, basis_first: bool,
               beat: float | None = None) -> _Point:
    dt = float((t[-1] - t[0]) / (t.size - 1))
    p = {**effect.off(), **params}
    G, nominal, ci, solver, offset = plant, dict(start), {}, {}, 0.0
    mask = None if weights is None else np.asarray(weights) > 0
    # alternate when a step depends on the others: basis terms, an output map (censoring), a plant-dependent input
    output_side = type(effect).output_map is not Effect.output_map
    iterate = bool(effect.basis_names) or output_side or effect.needs_plant
    rounds = _ROUNDS if iterate else 1
    costs: list[float] = []
    target = y
    try:
        if basis_first:  # the basis' least squares against the nominal model, before any casadi fit
            p = _basis_step(effect, plant, p, t, u, y, dt, mask)[0]
        for _ in range(rounds):
            v = effect.plant_input(u, dt, p, plant=effect.augment_plant(G, p))
            drift = sum((p[n] * psi for n, psi in zip(effect.basis_names, effect.output_basis(t))), np.zeros_like(y))
            G, p, nominal, ci_f, solver = _linear_fit(plant, effect, p, t, v, target - drift, formula,
                                                      {k: v_ for k, v_ in nominal.items() if k != "delay"}, weights)
            p, offset, ci_b, gain = _basis_step(effect, G, p, t, u, target, dt, mask)
            if gain != 1.0:
                G = G.scaled(gain, label=G.label)
                nominal = {k: (v_ * gain if k.startswith("n") else v_) for k, v_ in nominal.items()}
            ci = {**ci_f, **ci_b}
            if iterate:
                if output_side:
                    y_lin = _Linear(effect).apply(G, t, u, p, offset=offset)
                    target = effect.censor(y, y_lin, p)
                ssr = _ssr(y, effect.apply(G, t, u, p, offset=offset), mask)
                if costs and abs(costs[-1] - ssr) <= _ROUNDS_TOL * max(ssr, 1e-300):
                    break
                costs.append(ssr)
                if beat is not None and cannot_reach(costs, beat):  # no better than the other order's point
                    break
    except (DataError, ModelError, np.linalg.LinAlgError, RuntimeError) as exc:
        return _Point(p, np.inf, plant, 0.0, dict(start), {}, {"status": f"failed: {exc}"})
    ssr = _ssr(y, effect.apply(G, t, u, p, offset=offset), mask)
    return _Point(p, ssr if np.isfinite(ssr) else np.inf, G, offset, nominal, ci, solver)


def _ssr(y: np.ndarray, yhat: np.ndarray, mask: np.ndarray | None) -> float:
    r = y - yhat
    return float(np.sum((r if mask is None else r[mask]) ** 2))


class _Linear:
    """An effect's model without its output map (the linear part's output, for censoring)."""

    def __init__(self, effect: Effect) -> None:
        self.effect = effect

    def apply(self, G: Plant, t: np.ndarray, u: np.ndarray, params: Params, offset: float) -> np.ndarray:
        eff = self.effect
        dt = float((t[-1] - t[0]) / (t.size - 1))
        Ga = eff.augment_plant(G, params)
        y = simulate_plant(Ga, t, eff.plant_input(u, dt, params, plant=Ga)) + offset
        for name, psi in zip(eff.basis_names, eff.output_basis(t)):
            y = y + params.get(name, 0.0) * psi
        return y


def fit_augmented(plant: Plant, t: np.ndarray, u: np.ndarray, y: np.ndarray, effect: Effect | None = None,
                  refine: bool = True, start: Plant | None = None,
                  weights: np.ndarray | None = None, grid: list[Params] | None = None,
                  early_stop: bool = True) -> AugmentedFit:
    """Re-fit the nominal coefficients jointly with one effect's parameters on a (training) record.

    Parameters
    ----------
    plant : Plant
        Nominal model; its nonzero coefficients and delay are the starting point.
    t, u, y : numpy.ndarray
        Uniform time [s], command and measured output (the plant at rest at the start).
    effect : Effect, optional
        The augmentation; ``None`` re-fits the nominal coefficients alone (``parameter_mismatch``).
    refine : bool
        Golden-section search of a grid parameter after the grid.
    start : Plant, optional
        Starting coefficients for the casadi fits (same structure as ``plant``, e.g. the
        re-fit alone); default ``plant``'s.
    weights : numpy.ndarray, optional
        0/1 per sample: which samples the cost counts (the model is simulated over all of them
        from rest); default all.
    grid : list of dict, optional
        Starting points of the effect's search (e.g. around a screened point) instead of its
        own grid (:meth:`synth.gap.effects.Effect.data_grid`).
    early_stop : bool
        Stop an effect's second block order (basis first) once its extrapolated training SSR cannot come
        within one noise variance below the first's; ``False`` runs both to convergence (for checking).

    Returns
    -------
    AugmentedFit

    Raises
    ------
    ModelError
        No grid point could be fitted.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.gap.effects import RateLimitEffect
    >>> t = np.arange(0, 6, 0.01); u = np.where((t % 3) >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> y = RateLimitEffect().apply(G, t, u, {"rate": 4.0})
    >>> f = fit_augmented(Plant.from_string("2.1/(0.21*s+1)"), t, u, y, RateLimitEffect())
    >>> round(f.params["rate"], 1), f.plant.to_string(2)
    (4.0, '10/(s+5)')
    """
    variants = effect.nested_variants() if effect is not None and refine else None
    if variants is not None:  # e.g. a dead zone around the command at rest, or with a center of its own
        return fit_nested(fit_augmented, *variants, plant, t, u, y, grid, start=start, weights=weights,
                          early_stop=early_stop)
    t = np.asarray(t, float)
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    formula, start_values = nominal_structure(plant)
    if start is not None:  # it may hold a coefficient at exactly 0 (a re-fit stopped at its bound): a start of 0
        formula_s, values_s = nominal_structure(start)
        if (start.num.size, start.den.size) != (plant.num.size, plant.den.size) or not set(values_s) <= set(start_values):
            raise ModelError(f"start {formula_s} does not have the structure {formula}", where="start")
        start_values = {k: values_s.get(k, 0.0) for k in start_values}
    eff = effect if effect is not None else _NoEffect()
    grid = eff.data_grid(t, u, y, plant) if grid is None else [dict(g) for g in grid]
    if weights is not None:
        weights = np.asarray(weights, float)
        if weights.shape != y.shape or not np.all((weights == 0) | (weights == 1)):
            raise ModelError(f"weights must be {y.size} values of 0 or 1", where="weights")
    n_fit = int(y.size if weights is None else np.sum(weights > 0))
    points = [_fit_point(plant, eff, g, t, u, y, formula, start_values, weights, early_stop=early_stop)
              for g in grid]
    for g, p in zip(grid, points):
        p.key = next((k for k in eff.grid_names if k in g), None)
    best = min(points, key=lambda p: p.ssr)
    if not np.isfinite(best.ssr):
        raise ModelError(f"no fit succeeded ({best.solver.get('status')})", where=f"effect {eff.label}")
    ci = dict(best.ci)
    key = best.key
    if key is not None:
        same = [p for p in points if p.key == key]
        if refine:
            extra = _golden(plant, eff, best, same, key, t, u, y, formula, start_values, n_fit, weights)
            for p in extra:
                p.key = key
            points += extra
            same += extra
            best = min(points, key=lambda p: p.ssr)
        if refine and eff.joint_search:
            signal = y if getattr(eff, "placement", eff.side) == "output" else u
            extra = search_from_points(lambda prm, w: _fit_point(plant, eff, prm, t, u, y, formula, w, weights, warm=True),
                                       list(eff.grid_names), points, start_values, 0.05 * float(np.ptp(signal)),
                                       n_fit)
            for p in extra:
                p.key = key
            points += extra
            same += extra
            best = fewest_limits(points, list(eff.grid_names), n_fit)
        ci = dict(best.ci)  # the final point's own intervals (the grid's best gave a damping's that missed its value)
        ci[key] = profile_interval([(p.params.get(key, np.nan), p.ssr) for p in same],
                                       (best.params[key], best.ssr), n_fit)
        if eff.joint_search:
            ci.update(ranges_within(list(eff.grid_names), points, best, profile_level(best.ssr, n_fit)))
    return AugmentedFit(effect, best.plant, best.params, best.offset, best.nominal, ci, best.ssr, n_fit,
                        [(p.params, p.ssr) for p in points], best.solver)


def _golden(plant: Plant, eff: Effect, best: _Point, same: list[_Point], key: str, t: np.ndarray, u: np.ndarray,
            y: np.ndarray, formula: str, start: dict[str, float], n: int,
            weights: np.ndarray | None = None) -> list[_Point]:
    """Search in log(key) between the best grid point's neighbours (one grid step beyond an end).

    Parabolic interpolation through the best point and its neighbours
    (:func:`synth.gap.attribution.golden.parabolic_section`, a few fits instead of ten); at an end of the
    grid the step beyond is fitted first (if it is better still, the search stops there, the end of
    the range); golden section when a neighbour's fit failed."""
    vals = sorted({p.params[key] for p in same if np.isfinite(p.params.get(key, np.nan)) and p.params[key] > 0})
    bracket = log_bracket(vals, best.params.get(key, np.nan))
    if bracket is None:
        return []
    # warm start at the best point: its basis parameters and nominal coefficients (the alternation of a basis
    # effect then needs a round or two instead of up to _ROUNDS)
    base = dict(best.params)
    warm_start = {k: v for k, v in best.nominal.items() if k in start}
    out: list[_Point] = []

    def f(x: float) -> float:
        pt = _fit_point(plant, eff, {**base, key: float(np.exp(x))}, t, u, y, formula, warm_start, weights,
                        warm=True)
        out.append(pt)
        return pt.ssr

    x0 = float(np.log(best.params[key]))
    ssr = {float(np.log(p.params[key])): p.ssr for p in same if np.isfinite(p.params.get(key, np.nan))
           and p.params[key] > 0}
    a, b = bracket
    level = profile_level(best.ssr, n)
    if all(x in ssr and ssr[x] <= level for x in (a, b)):  # flat at the noise between the neighbours
        return []
    missing = [x for x in (a, b) if x not in ssr]
    if len(missing) == 1 and a < x0 < b:  # the best is at an end of the grid: fit the step beyond it first
        ssr[missing[0]] = f(missing[0])
        if ssr[missing[0]] < best.ssr:  # still going down at the end of the searched range
            return out
    if a in ssr and b in ssr and np.isfinite(ssr[a]) and np.isfinite(ssr[b]) and a < x0 < b:
        parabolic_section(f, a, x0, b, ssr[a], best.ssr, ssr[b], _GOLDEN - 2 - len(missing), _GOLDEN_TOL)
    else:
        golden_section(f, *bracket, _GOLDEN - 2 - len(out), tol=_GOLDEN_TOL)
    return out
