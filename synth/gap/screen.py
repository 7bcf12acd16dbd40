"""Cheap screening of candidate effects before the joint casadi re-fit.

Every candidate is first fitted with the **denominator of the linear model
held fixed** and everything that enters the output linearly solved by least
squares: the numerator coefficients of the (augmented) linear part, the
output constant, the effect's basis parameters (``a2, a3``, ``sag``, drift
terms). For a fixed denominator and fixed non-smooth parameters the output is
linear in those, so each point of the effect's parameter search costs a few
linear simulations (:func:`synth.ident.simulate.simulate_plant`, milliseconds)
instead of an IPOPT solve on the whole record. The search runs the effect's own
grid (:meth:`synth.gap.effects.Effect.grid`) plus a golden-section search in the
log of the grid parameter between the best point's neighbours; the extra delay
and a resonance's damping, which the joint fit treats as smooth, get a grid of
their own here. The denominator is tried at two places, the nominal model's and
the re-fit's, since the re-fit alone may have moved its poles to mimic the
effect (a slower plant for a rate limit) and the nominal has not.

The screened training SSR ranks the candidates; :func:`synth.gap.attribute.diagnose_effects`
re-fits only the best few jointly (nominal coefficients and effect, casadi),
started at the screened parameters. A screened fit is never better than the joint
fit of the same effect could be (it is the same model with fewer free
coefficients), so the ranking errs against an effect only when a pole shift
the screen cannot make is what the effect needs.

A quantizer is searched differently (:func:`quantizer_grid`): for a fixed
denominator its training SSR depends on ``(step, offset)`` only through which
lattice level each command sample rounds to (the level values themselves are
absorbed by the least-squares gain and constant), so the cost is piecewise
constant and a golden-section search is meaningless. Both parameters are
searched densely and jointly instead, every point by superposition of the
unit numerators' step responses (one FFT convolution per point, batched).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.errors import ModelError
from synth.gap.effects import Effect, Params, QuantizationEffect
from synth.gap.golden import golden_section, log_bracket
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

_GOLDEN_STEPS = 14
_ZETAS = (0.05, 0.1, 0.2, 0.4, 0.7)


@dataclass(frozen=True, eq=False)
class ScreenedFit:
    """One candidate's screened fit (denominator fixed, linear parameters by least squares).

    Attributes
    ----------
    effect : Effect
    params : dict
        Effect parameters at the best screened point (basis parameters included).
    ssr : float
        Training sum of squared errors there.
    plant : Plant
        The linear model with the least-squares numerator (without the effect's factor).
    offset : float
        Output constant.
    base : str
        Which denominator: ``"nominal"`` or ``"refit"``.
    points : int
        Parameter points evaluated.
    yhat_train, yhat_eval : numpy.ndarray
        Screened model output on the training and the evaluated record.
    ssr_held : float
        Lowest training SSR over the points searched with the base denominator held exactly (no
        Gauss-Newton step). The step's linearization can let every candidate reach the same SSR (a
        large pole change is mimicked by the step's columns, effect or no effect), which hides the one
        effect that needs no step; this SSR does not.
    params_held : dict
        The effect's grid parameters at that point.
    """

    effect: Effect
    params: Params
    ssr: float
    plant: Plant
    offset: float
    base: str
    points: int
    yhat_train: np.ndarray = field(repr=False)
    yhat_eval: np.ndarray = field(repr=False)
    ssr_held: float = np.inf
    params_held: dict = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON summary.

        Examples
        --------
        >>> import numpy as np
        >>> from synth.gap.effects import make_effect
        >>> t = np.arange(0, 4, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
        >>> G = Plant.from_string("2/(0.2*s+1)")
        >>> y = simulate_plant(G.with_delay(0.05), t, u)
        >>> d = screen_effect(make_effect("delay"), [("nominal", G)], t, u, y, t, u).to_dict()
        >>> d["effect"], round(d["parameters"]["delay"], 4), d["base"]
        ('delay', 0.05, 'nominal')
        """
        return {"effect": self.effect.label, "parameters": {k: float(v) for k, v in self.params.items()},
                "ssr": self.ssr, "tf": self.plant.to_string(6), "offset": self.offset, "base": self.base,
                "points": self.points}


def _unit_numerators(plant: Plant) -> list[Plant]:
    """One plant per nonzero numerator coefficient of ``plant`` (that coefficient 1, the others 0)."""
    out = []
    for i, c in enumerate(plant.num):
        if c != 0.0:
            e = np.zeros_like(plant.num, dtype=float)
            e[i] = 1.0
            out.append(Plant(e, plant.den, plant.delay, plant.input, plant.output, plant.label))
    return out


def _denominator_directions(plant: Plant) -> list[Plant]:
    """``dG/dd_k = -N s^k / D^2`` for every nonzero non-leading denominator coefficient ``d_k`` of ``G = N/D``.

    With these columns in the least squares, the screen takes one Gauss-Newton step in the
    denominator from the base instead of holding it fixed, so an effect that needs the poles to move
    (a limit that changes how fast the plant looks) is not ranked as if it could not.

    Examples
    --------
    >>> d = _denominator_directions(Plant.from_string("2/(s+3)"))[0]
    >>> d.num.tolist(), d.den.tolist()
    ([-2.0], [1.0, 6.0, 9.0])
    """
    out = []
    deg = plant.den.size - 1
    den2 = np.polymul(plant.den, plant.den)
    for i, c in enumerate(plant.den):
        if i == 0 or c == 0.0:
            continue
        power = np.zeros(deg - i + 1)
        power[0] = 1.0
        out.append(Plant(-np.polymul(plant.num, power), den2, plant.delay, plant.input, plant.output, plant.label))
    return out


class _Design:
    """Least-squares design of one effect on one denominator: columns on the training and evaluated records."""

    def __init__(self, effect: Effect, base: Plant, records: list[tuple[np.ndarray, np.ndarray]],
                 mask: np.ndarray | None = None) -> None:
        self.effect, self.base, self.records, self.mask = effect, base, records, mask
        self.units = _unit_numerators(base)
        self.directions = _denominator_directions(base)

    def columns(self, params: Params, t: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, int]:
        eff = self.effect
        dt = float((t[-1] - t[0]) / (t.size - 1))
        p = {**eff.off(), **params}
        v0 = eff.input_map(u, dt, p)
        cols = [simulate_plant(eff.augment_plant(g, p), t, v0) for g in self.units]
        k_num = len(cols)
        g_aug = eff.augment_plant(self.base, p)
        cols += [simulate_plant(g_aug, t, phi) for phi in eff.input_basis(u, dt, p)]
        cols += list(eff.output_basis(t))
        cols += [simulate_plant(eff.augment_plant(g, p), t, v0) for g in self.directions]
        cols.append(np.ones_like(t))
        return np.column_stack(cols), k_num

    def fit(self, params: Params, y: np.ndarray) -> tuple[float, np.ndarray, int, float]:
        """Training SSR, coefficients, numerator columns, and the SSR with the denominator held (no step)."""
        t_tr, u_tr = self.records[0]
        X, k_num = self.columns(params, t_tr, u_tr)
        if self.mask is not None:  # only the fitted samples count
            X, y = X[self.mask], y[self.mask]
        if not np.all(np.isfinite(X)):
            return np.inf, np.zeros(X.shape[1]), k_num, np.inf
        scale = np.maximum(np.sqrt(np.sum(X**2, axis=0)), 1e-300)
        coef, *_ = np.linalg.lstsq(X / scale, y, rcond=None)
        coef = coef / scale
        r = y - X @ coef
        n_dir = len(self.directions)
        if not n_dir:
            return float(r @ r), coef, k_num, float(r @ r)
        held = np.r_[np.arange(X.shape[1] - 1 - n_dir), X.shape[1] - 1]  # every column but the directions
        Xh = X[:, held] / scale[held]
        coef_h, *_ = np.linalg.lstsq(Xh, y, rcond=None)
        r_h = y - Xh @ coef_h
        return float(r @ r), coef, k_num, float(r_h @ r_h)

    def evaluate(self, params: Params, coef: np.ndarray, t: np.ndarray, u: np.ndarray) -> np.ndarray:
        X, _ = self.columns(params, t, u)
        return X @ coef


def _extra_grid(effect: Effect, t: np.ndarray, u: np.ndarray, plant: Plant) -> list[Params] | None:
    """Screening grids for parameters the joint fit treats as smooth (delay, damping)."""
    dt = float(t[1] - t[0])
    if effect.name == "delay":
        p = np.abs(plant.poles())
        slow = float(np.min(p[p > 0])) if np.any(p > 0) else 1.0
        top = min(0.25 * float(t[-1] - t[0]), 1.0 / slow)
        return [{"delay": float(d)} for d in np.geomspace(0.25 * dt, max(top, dt), 16)]
    if effect.name == "resonance":
        return [{**g, "zeta": z} for g in effect.grid(t, u, plant) for z in _ZETAS]
    return None


def _step_responses(plant: Plant, t: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per unit numerator of ``plant``: the response to a unit step at ``t[0]`` from rest, and to a held 1 (steady).

    (The quantizer's dense search holds the denominator: a Gauss-Newton step in it would double the work of
    every one of its thousands of points; the best points are then screened like every other effect.)"""
    units = _unit_numerators(plant)
    ones = np.ones_like(t)
    return ([simulate_plant(g, t, ones, initial="zero") for g in units],
            [simulate_plant(g, t, ones) for g in units])


def _batch_ssr(v: np.ndarray, y: np.ndarray, steps: list[np.ndarray], consts: list[np.ndarray],
               mask: np.ndarray | None = None) -> np.ndarray:
    """Least-squares SSR of ``y`` on the unit-numerator responses to each column of ``v`` plus a constant.

    ``v`` is ``(N, M)``: M candidate plant inputs. The response of a linear model started at the
    steady state of ``v[0]`` is ``v[0] c + sum_k (v[k] - v[k-1]) s[n - k]`` (``s`` the step response from
    rest, ``c`` the steady response to a held 1), so every column costs one FFT convolution per unit.
    """
    n, m = v.shape
    dv = np.diff(v, axis=0)
    size = 1 << int(np.ceil(np.log2(2 * n)))
    fdv = np.fft.rfft(dv, size, axis=0)
    cols = []
    for s, c in zip(steps, consts):
        conv = np.fft.irfft(fdv * np.fft.rfft(s, size)[:, None], size, axis=0)[: n - 1]
        x = np.empty((n, m))
        x[0] = 0.0
        x[1:] = conv
        cols.append(x + v[0][None, :] * c[:, None])
    cols.append(np.ones((n, m)))
    X = np.stack(cols, axis=2)  # (N, M, k)
    if mask is not None:
        X, y = X[mask], y[mask]
    scale = np.maximum(np.sqrt(np.einsum("nmk,nmk->mk", X, X)), 1e-300)
    X = X / scale[None]
    gram = np.einsum("nmi,nmj->mij", X, X)
    xty = np.einsum("nmi,n->mi", X, y)
    coef = np.einsum("mij,mj->mi", np.linalg.pinv(gram, rcond=1e-10, hermitian=True), xty)
    return np.maximum(float(y @ y) - np.einsum("mi,mi->m", coef, xty), 0.0)


def quantizer_grid(plant: Plant, t: np.ndarray, u: np.ndarray, y: np.ndarray, keep: int = 5,
                   mask: np.ndarray | None = None) -> list[Params]:
    """Dense joint search of a command quantizer's ``step`` and ``offset`` with ``plant``'s denominator fixed.

    The lattice is written as ``c + (phase + k) step`` with ``c`` the command's mid-range, so changing the
    step at a fixed phase scales the lattice about the middle of the data instead of about zero. Steps run
    on a log grid from 0.005 to 0.5 of the command's span, spaced so that the lattice moves by at most an
    eighth of a step at the edges of the data between neighbours (relative spacing ``step / (4 span)``);
    phases on eight points in [0, 1). The best ``keep`` points are then searched again on a grid four times
    finer in both directions around each. Every point's SSR is the least-squares fit of the unit numerators
    and a constant (:func:`_batch_ssr`).

    Parameters
    ----------
    plant : Plant
        Linear model whose denominator and delay are held fixed.
    t, u, y : numpy.ndarray
        Training record.
    keep : int
        Points refined, and returned, best first.
    mask : numpy.ndarray of bool, optional
        Samples that count in the SSR (default all).

    Returns
    -------
    list of dict
        ``{"step", "offset"}`` with ``offset`` in ``[0, step)`` (the :class:`synth.sim.blocks.Quantizer` offset).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 8, 0.01); u = 1.0 + 0.8 * np.sin(2.3 * t) * np.sin(0.37 * t)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> y = QuantizationEffect().apply(G, t, u, {"step": 0.25, "offset": 0.07})
    >>> g = quantizer_grid(G, t, u, y)[0]
    >>> abs(g["step"] / 0.25 - 1) < 0.01, abs(g["offset"] - 0.07) < 0.01
    (True, True)
    """
    t, u, y = (np.asarray(a, float) for a in (t, u, y))
    span = float(np.max(u) - np.min(u))
    if span <= 0:
        raise ModelError("the input is constant; no quantizer can be fitted", where="record.u")
    center = 0.5 * float(np.max(u) + np.min(u))
    steps_r, consts = _step_responses(plant, t)
    q_lo, q_hi = 0.005 * span, 0.5 * span
    steps = [q_lo]
    while steps[-1] < q_hi:
        steps.append(steps[-1] * (1.0 + steps[-1] / (4.0 * span)))
    n_phase = 8

    # the quantized command depends only on the levels the command's distinct values round to: on a step
    # train (few distinct values) many (step, phase) points give the same input, whose SSR is computed once
    u_values, u_index = np.unique(u, return_inverse=True)

    chunk = max(512, int(2e7 // u_values.size))  # points per pass: bounds the (values x points) level table
    # the SSR is unchanged by v -> a v + b when the steady responses are constant (gain in the numerator fit, the
    # offset in the constant column): then only the integer rounding pattern, less its first entry, matters
    affine = all(np.ptp(c) <= 1e-9 * max(np.max(np.abs(c)), 1e-300) for c in consts)

    def ssr(points: np.ndarray) -> np.ndarray:  # points (M, 2): step, phase
        out = np.empty(len(points))
        for start in range(0, len(points), chunk):
            q, ph = points[start:start + chunk, 0], points[start:start + chunk, 1]
            lat = center + ph * q
            k = np.floor((u_values[:, None] - lat[None, :]) / q[None, :] + 0.5)  # as the block rounds, per value
            levels = k - k[:1] if affine else lat[None, :] + q[None, :] * k
            distinct, which = np.unique(levels, axis=1, return_inverse=True)
            cost = np.empty(distinct.shape[1])
            for i in range(0, distinct.shape[1], 512):
                cost[i:i + 512] = _batch_ssr(distinct[:, i:i + 512][u_index], y, steps_r, consts, mask)
            out[start:start + chunk] = cost[np.ravel(which)]
        return out

    coarse = np.array([(q, (j + 0.5) / n_phase) for q in steps for j in range(n_phase)])
    cost = ssr(coarse)
    best = coarse[np.argsort(cost, kind="stable")[:keep]]
    fine = [coarse[np.argsort(cost, kind="stable")[:keep]]]
    for q, ph in best:
        dq = q / (4.0 * span)  # the coarse relative spacing
        fq = q * np.exp(np.linspace(-dq, dq, 9))
        fp = ph + np.linspace(-0.5, 0.5, 9) / n_phase
        fine.append(np.array([(a, b) for a in fq for b in fp]))
    pts = np.vstack(fine)
    cost = ssr(pts)
    order = np.argsort(cost, kind="stable")
    levels = np.unique(u)
    out: list[Params] = []
    for i in order:
        q, ph = pts[i]
        g = _max_margin(levels, float(q), float(center + ph * q))
        if g not in out:
            out.append(g)
        if len(out) == keep:
            break
    return out


def _max_margin(levels: np.ndarray, step: float, lattice: float) -> Params:
    """The point of the quantizer's cell farthest from rounding any of ``levels`` differently.

    Every ``(step, offset)`` that rounds each level to the same lattice index ``n_i`` fits the
    training data equally well; the data do not tell them apart, and the one with the largest margin
    ``m`` (in steps) to the rounding boundaries is the least likely to round unseen levels wrongly. With
    ``a = 1/step``, ``b = offset/step`` the cell is ``n_i - 1/2 + m <= a u_i - b <= n_i + 1/2 - m``: a linear
    program in ``(a, b, m)``. Returns the given point when the program fails.

    Examples
    --------
    >>> g = _max_margin(np.array([0.0, 1.0, 2.0]), 1.1, 0.3)  # rounds to 0, 1, 2: the cell's centre is step 1, offset 0
    >>> round(g["step"], 6), round(g["offset"], 6) % 1.0
    (1.0, 0.0)
    """
    from scipy.optimize import linprog

    n = np.floor((levels - lattice) / step + 0.5)
    ones = np.ones_like(levels)
    # a u - b - m >= n - 1/2  ->  -a u + b + m <= 1/2 - n ;  a u - b + m <= n + 1/2
    a_ub = np.vstack([np.column_stack([-levels, ones, ones]), np.column_stack([levels, -ones, ones])])
    b_ub = np.concatenate([0.5 - n, n + 0.5])
    fallback = {"step": float(step), "offset": float(lattice % step)}
    bounds = [(1e-12 / step, None), (None, None), (0.0, 0.5)]
    try:
        res = linprog([0.0, 0.0, -1.0], A_ub=a_ub, b_ub=b_ub, bounds=bounds, method="highs")
        if not res.success:
            return fallback
        # the largest margin may be reached on a segment: take the middle of its ends in 1/step
        m = float(res.x[2]) * (1.0 - 1e-9)
        ends = [linprog([c, 0.0, 0.0], A_ub=a_ub, b_ub=b_ub, bounds=[*bounds[:2], (m, 0.5)], method="highs")
                for c in (1.0, -1.0)]
    except ValueError:
        return fallback
    x = 0.5 * (ends[0].x + ends[1].x) if all(e.success for e in ends) else res.x
    if x[0] <= 0:
        return fallback
    q = 1.0 / float(x[0])
    return {"step": q, "offset": float((x[1] * q) % q)}


def _search_key(effect: Effect, grid: list[Params]) -> str | None:
    for name in ("delay", *effect.grid_names):
        if any(name in g for g in grid):
            return name
    return None


def screen_effect(effect: Effect, bases: list[tuple[str, Plant]], t_tr: np.ndarray, u_tr: np.ndarray,
                  y_tr: np.ndarray, t_ev: np.ndarray, u_ev: np.ndarray, mask: np.ndarray | None = None) -> ScreenedFit:
    """Screen one effect: its parameter search with each base denominator fixed, the rest by least squares.

    Parameters
    ----------
    effect : Effect
    bases : list of (str, Plant)
        Named linear models whose denominators (and delay) are held fixed.
    t_tr, u_tr, y_tr : numpy.ndarray
        Training record (the model starts at rest at its first sample).
    t_ev, u_ev : numpy.ndarray
        Evaluated record (the training record's continuation, or a validation record).
    mask : numpy.ndarray of bool, optional
        Training samples that count in the SSR (default all; the model runs over all of them).

    Returns
    -------
    ScreenedFit

    Raises
    ------
    ModelError
        No point could be evaluated.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.gap.effects import make_effect
    >>> t = np.arange(0, 6, 0.01); u = np.where((t % 3) >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("2/(0.2*s+1)")
    >>> y = make_effect("rate_limit").apply(G, t, u, {"rate": 4.0})
    >>> s = screen_effect(make_effect("rate_limit"), [("nominal", G)], t, u, y, t, u)
    >>> round(s.params["rate"], 2), s.ssr < 1e-6
    (4.0, True)
    """
    t_tr, u_tr, y_tr = (np.asarray(a, float) for a in (t_tr, u_tr, y_tr))
    best: tuple[float, Params, np.ndarray, int, str, _Design] | None = None
    points = 0
    ssr_held, params_held = np.inf, {}
    for base_name, base in bases:
        design = _Design(effect, base, [(t_tr, u_tr), (t_ev, u_ev)], mask)
        try:
            if isinstance(effect, QuantizationEffect):
                grid = quantizer_grid(base, t_tr, u_tr, y_tr, mask=mask)
            else:
                grid = _extra_grid(effect, t_tr, u_tr, base) or effect.grid(t_tr, u_tr, base)
        except ModelError:
            continue
        tried: dict[tuple[tuple[str, float], ...], tuple[float, np.ndarray, int]] = {}

        def run(g: Params, design: _Design = design, tried: dict = tried) -> float:
            nonlocal ssr_held, params_held
            key = tuple(sorted(g.items()))
            if key not in tried:
                ssr, coef, k_num, held = design.fit(g, y_tr)
                tried[key] = (ssr if np.isfinite(ssr) else np.inf, coef, k_num)
                if np.isfinite(held) and held < ssr_held:
                    ssr_held, params_held = held, {**effect.off(), **g}
            return tried[key][0]

        for g in grid:
            run(g)
        key_name = None if isinstance(effect, QuantizationEffect) else _search_key(effect, grid)
        g_best = min(grid, key=lambda g: run(g))
        if key_name is not None:
            g_best = _golden(run, grid, g_best, key_name)
        points += len(tried)
        ssr = run(g_best)
        if best is None or ssr < best[0]:
            _, coef, k_num = tried[tuple(sorted(g_best.items()))]
            best = (ssr, g_best, coef, k_num, base_name, design)
    if best is None or not np.isfinite(best[0]):
        raise ModelError("no screening point could be evaluated", where=f"effect {effect.label}")
    ssr, g, coef, k_num, base_name, design = best
    base = design.base
    params = {**effect.off(), **g}
    n_basis_in = len(effect.input_basis(u_tr, float(t_tr[1] - t_tr[0]), params))
    for j, name in enumerate(effect.basis_names):
        params[name] = float(coef[k_num + j])
    num = np.zeros_like(base.num, dtype=float)
    num[np.flatnonzero(base.num != 0.0)] = coef[:k_num]
    n_dir = len(design.directions)
    den = base.den.astype(float).copy()
    if n_dir:  # the Gauss-Newton step (one direction per nonzero non-leading coefficient)
        den[[i for i, c in enumerate(base.den) if i > 0 and c != 0.0]] += coef[-1 - n_dir:-1]
    plant = Plant(num, den, base.delay, base.input, base.output, "screened")
    if n_basis_in:  # the basis columns ran through the base numerator: express them per unit of the new gain
        gain = float(num @ base.num) / float(base.num @ base.num)  # least-squares ratio of the numerators
        for name in effect.basis_names[:n_basis_in]:
            params[name] = params[name] / gain if gain != 0 else params[name]
    y_train = design.evaluate(g, coef, t_tr, u_tr)
    y_eval = design.evaluate(g, coef, np.asarray(t_ev, float), np.asarray(u_ev, float))
    return ScreenedFit(effect, params, float(ssr), plant, float(coef[-1]), base_name, points, y_train, y_eval,
                       float(ssr_held), params_held)


def _golden(run: Any, grid: list[Params], g_best: Params, key: str) -> Params:
    """Golden-section search in log(key) between the best grid point's neighbours (the other keys fixed)."""
    rest = {k: v for k, v in g_best.items() if k != key}
    vals = sorted({g[key] for g in grid if key in g and np.isfinite(g[key]) and g[key] > 0
                   and {k: v for k, v in g.items() if k != key} == rest})
    bracket = log_bracket(vals, g_best.get(key, np.nan))
    if bracket is None:
        return g_best
    c, d = golden_section(lambda x: run({**rest, key: float(np.exp(x))}), *bracket, _GOLDEN_STEPS)
    cands = [g_best, {**rest, key: float(np.exp(c))}, {**rest, key: float(np.exp(d))}]
    return min(cands, key=run)
