"""A nearly cancelling zero-pole pair moved across the band: the fit's way out of the pair's other minima.

Where a zero lies near a pole (within a factor :data:`NEAR_CANCELLATION`), the record says little about where the
pair sits: the pair adds one mode of small amplitude, and the simulation error has several minima along its
location (the Cramer-Rao benchmark's near cancellations, ``benchmarks/ident_crb.py``: the pair at two equal poles
beside a zero, or cancelled exactly far from the truth's pair, each a local minimum that one deterministic start
lands in). The truth's basin had the lower residual there (3 to 107 noise variances), so the residual can tell
the minima apart; a local fit cannot get from one to the other.

:func:`relocate_pair` profiles the residual along the pair's location. The pair's pole is held at each of
:data:`LOCATIONS` points spread logarithmically from a tenth of the fit's smallest root to a hundred times its
largest (at most half the Nyquist frequency). At each, the other poles are estimated by SRIVC with that root
held (:func:`synth.ident.srivc.srivc_with_root`: deterministic, and it does not fall into the valleys a local
search along the other poles does), the numerator (its zeros and gain) and the output offset by linear least
squares (they enter the output linearly), and then the other poles, and the delay where the fit estimated it,
are polished by Gauss-Newton (variable projection; a known sensor is held). A point whose residual is below
the fit's by more than :data:`REFIT_DROP` noise variances is a better model in another basin, found without
guessing: the structure is fitted again from the best one, and that fit replaces the first when its own
residual is lower. Otherwise the fit stays as it was. Either way the profile's evidence (the band, the lowest
point against the fit, the refit's outcome and a sentence saying what happened) is in ``solver["pair_profile"]``.

:func:`synth.ident.identification.identify` runs it on fits of the whole record from rest that have a weakly
identifiable parameter (a pair the record pins down is not profiled: on the X-4 record's 420,000 samples the
profile costs 26 s). ``benchmarks/pair_relocation.py`` measures it on randomized problems.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from synth.data.record import Record
from synth.errors import DataError, FitError, ModelError
from synth.ident.filter_bank import filter_bank
from synth.ident.simulate import simulate_plant
from synth.ident.srivc import map_to_structure, srivc_with_root
from synth.ident.structure import Structure
from synth.ident.timefit import TimeFitResult, fit_structure
from synth.plant import Plant

__all__ = ["LOCATIONS", "NEAR_CANCELLATION", "REFIT_DROP", "PairProfile", "pair_profile", "relocate_pair"]

#: a zero within this factor of a pole is a near cancellation whose location is profiled (only fits with a weak
#: parameter are profiled; CRB case 6, seed 1 ended with its weak pair spread to 20/41 rad/s, the truth's at 7.3/7.9)
NEAR_CANCELLATION = 4.0
#: profile points over the band (logarithmic)
LOCATIONS = 24
#: a profile point this many noise variances of SSR below the fit starts a refit
REFIT_DROP = 1.0
#: Gauss-Newton evaluations per other-pole coefficient in a polish
_EVALUATIONS = 12


@dataclass(frozen=True)
class PairProfile:
    """The residual along a nearly cancelling pair's location.

    Attributes
    ----------
    zero, pole : float
        The fit's pair (``s = -zero``, ``s = -pole``) [rad/s].
    locations : numpy.ndarray
        The pair's pole at each profile point [rad/s].
    drop : numpy.ndarray
        The fit's SSR minus each point's, in noise variances (positive: better than the fit).
    best : tuple of (numpy.ndarray, numpy.ndarray)
        Numerator and denominator of the structure's plant at the lowest point.
    delay : float
        The delay there [s] (the fit's, or polished with the other poles when the fit estimated it).
    """

    zero: float
    pole: float
    locations: np.ndarray
    drop: np.ndarray
    best: tuple[np.ndarray, np.ndarray]
    delay: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the pair, the band profiled and the largest drop.

        Examples
        --------
        >>> p = PairProfile(1.0, 1.2, np.array([0.1, 10.0]), np.array([-3.0, 0.5]), (np.ones(1), np.ones(2)))
        >>> p.to_dict()["largest_drop_noise_variances"]
        0.5
        """
        i = int(np.argmax(self.drop))
        return {"zero": self.zero, "pole": self.pole, "points": int(self.locations.size),
                "band": [float(self.locations[0]), float(self.locations[-1])],
                "largest_drop_noise_variances": float(self.drop[i]), "at": float(self.locations[i])}


def _near_pairs(plant: Plant) -> list[tuple[float, float]]:
    """Each real zero with its nearest real pole on the same side of the imaginary axis, when within
    :data:`NEAR_CANCELLATION` of it, as ``(zero, pole)`` with the roots at ``s = -zero`` and ``s = -pole``
    (a pair cancelled in the right half-plane is another of the pair's minima: it is profiled too)."""
    num = np.trim_zeros(np.asarray(plant.num, float), "f")
    zeros = np.roots(num) if num.size > 1 else np.array([])
    poles = np.roots(np.asarray(plant.den, float))
    real_poles = [-float(p.real) for p in poles if abs(p.imag) <= 1e-9 * abs(p) and p.real != 0]
    pairs = []
    for z in zeros:
        zr = -float(z.real)
        same_side = [q for q in real_poles if q * zr > 0]
        if abs(z.imag) > 1e-9 * abs(z) or not same_side:
            continue
        p = min(same_side, key=lambda q: abs(np.log(q / zr)))
        if abs(np.log(p / zr)) <= np.log(NEAR_CANCELLATION):
            pairs.append((zr, p))
    return pairs


def _remove_root(poly: np.ndarray, root: float) -> np.ndarray:
    """``poly / (s + root)``, the remainder dropped (the root is one of its roots)."""
    return np.polydiv(np.asarray(poly, float), np.array([1.0, root]))[0]


class _Projection:
    """The output's best fit for a given denominator: numerator and offset by linear least squares."""

    def __init__(self, t: np.ndarray, w: np.ndarray, y: np.ndarray, mask: np.ndarray, nb: int,
                 sensor: Plant | None, delay: float) -> None:
        self.dt = float(t[1] - t[0])
        self.w, self.y, self.mask, self.nb, self.delay = w, y[mask], mask, nb, delay
        self.h_num = np.asarray(sensor.num, float) if sensor is not None else np.ones(1)
        self.h_den = np.asarray(sensor.den, float) if sensor is not None else np.ones(1)

    def solve(self, den: np.ndarray, delay: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Residual on the fitted samples and the numerator coefficients (highest power first), at ``delay``
        (default: the fit's)."""
        full = np.polymul(den, self.h_den)
        hn = np.trim_zeros(self.h_num, "f")
        bank = filter_bank(full, self.dt, self.w, self.nb + hn.size, self.delay if delay is None else delay)
        cols = []
        for k in range(self.nb + 1):  # s^k Hn(s) / (den Hd)
            cols.append(sum(c * bank[k + j] for j, c in enumerate(hn[::-1])))
        A = np.column_stack([*cols, np.ones(self.w.size)])[self.mask]
        coef, *_ = np.linalg.lstsq(A, self.y, rcond=None)
        return self.y - A @ coef, coef[:self.nb + 1][::-1]


def _factors(poly: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Monic ``poly`` as stable first- and second-order factors (profiled) and the rest (held)."""
    free, held = [], []
    roots = np.roots(poly) if poly.size > 1 else np.array([])
    for r in roots[roots.imag >= 0]:
        if abs(r.imag) <= 1e-9 * abs(r):
            (free if r.real < 0 else held).append(np.array([1.0, -r.real]))
        else:
            (free if r.real < 0 else held).append(np.array([1.0, -2.0 * r.real, abs(r) ** 2]))
    return free, held


def _polish(proj: _Projection, den: np.ndarray, root: float,
            fit_delay: bool) -> tuple[float, np.ndarray, np.ndarray, float]:
    """Gauss-Newton on the other poles (and the delay, where the fit estimated it), the root held: SSR,
    numerator, denominator and delay.

    The other poles are moved as factors (a real pole's log, a stable pair's log coefficients): their
    polynomial's coefficients make a narrow curved valley where a well-identified pole sits beside a weak one.
    A delay trades off with a fast pair (both shift the phase): with the fit's delay held, a pair moved from
    a cancellation far below the band gained 0.9 noise variances where 6.6 were there.
    """
    free, held = _factors(_remove_root(den, root))
    base = np.concatenate([f[1:] for f in free]) if free else np.zeros(0)
    fixed = np.array([1.0, root])
    for f in held:
        fixed = np.polymul(fixed, f)
    m = base.size

    def full(x: np.ndarray) -> np.ndarray:
        c, out, i = np.exp(x[:m]), fixed, 0
        for f in free:
            out = np.polymul(out, np.r_[1.0, c[i:i + f.size - 1]])
            i += f.size - 1
        return out

    def delay_of(x: np.ndarray) -> float:
        return float(x[m]) if fit_delay else proj.delay

    x = np.r_[np.log(base), [proj.delay] if fit_delay else []]
    if x.size:  # steps of 1e-4 in the logs: the filters' rounding swamps the default's 1e-8
        lower = np.r_[np.full(m, -np.inf), [0.0] if fit_delay else []]
        x = least_squares(lambda xv: proj.solve(full(xv), delay_of(xv))[0], x, method="trf", diff_step=1e-4,
                          bounds=(lower, np.inf), max_nfev=_EVALUATIONS * (x.size + 1)).x
    r, num = proj.solve(full(x), delay_of(x))
    return float(r @ r), num, full(x), delay_of(x)


def pair_profile(record: Record, fit: TimeFitResult) -> list[PairProfile]:
    """The residual along each nearly cancelling pair's location of ``fit`` (a fit of ``record`` from rest).

    At each of :data:`LOCATIONS` points the pair's pole is held and the other poles estimated by SRIVC with
    that root (:func:`synth.ident.srivc.srivc_with_root`), the numerator and offset by linear least squares,
    then the other poles (and a fitted delay) polished by Gauss-Newton.

    Parameters
    ----------
    record : Record
        The record the fit was made on (not periodic: the plant at rest at the first input sample); the samples
        the fit weighted 0 (``fit.weights``) are left out here too.
    fit : TimeFitResult

    Returns
    -------
    list of PairProfile
        One per zero within :data:`NEAR_CANCELLATION` of a pole; empty when there is none.

    Examples
    --------
    The truth has a pole at 2 and a pair at 20/22; fitted from a start with the pair near the slow pole, the fit
    ends with a pole pair at 1.75 beside a zero at 1.56. Moved to 20 rad/s, the pair fits 630 noise
    variances better:

    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 40, 0.005); u = np.where((t % 4) < 2, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("8*(s+22)/((s+2)*(s+20))"), t, u)
    >>> rec = record_from_arrays(t, u, y + 0.01 * np.std(y) * np.random.default_rng(0).normal(size=t.size))
    >>> wrong = fit_structure(rec, "k*(s+z)/((s+p1)*(s+p2))", initial={"k": 8, "z": 3, "p1": 2, "p2": 3.3})
    >>> wrong.plant.to_string(3)
    '8.65*(s+1.56)/((s+1.75)*(s+1.75))'
    >>> prof = pair_profile(rec, wrong)[0]
    >>> round(prof.zero, 2), round(prof.pole, 2), round(float(prof.locations[np.argmax(prof.drop)]), 1)
    (1.56, 1.75, 20.7)

    :func:`relocate_pair` refits from there and keeps the better fit:

    >>> from synth.ident.structure import parse_structure
    >>> moved = relocate_pair(rec, wrong, parse_structure("k*(s+z)/((s+p1)*(s+p2))"), None, None)
    >>> moved.plant.to_string(3), moved.solver["pair_profile"][-1]["refit"]
    ('8.04*(s+21.2)/((s+19.4)*(s+2))', 'kept: a lower residual')
    """
    w = record.u - record.u[0]
    mask = np.ones(w.size, bool) if fit.weights is None else fit.weights > 0  # the samples the fit's cost used
    residual = (record.y - fit.yhat)[mask]
    ssr_fit = float(residual @ residual)
    s2 = ssr_fit / max(_dof(fit), 1)
    plant, sensor = fit.plant, fit.sensor
    if not s2 > 0 or fit.periodic:
        return []
    num_f = np.trim_zeros(np.asarray(plant.num, float), "f")
    nb = num_f.size - 1
    v = w if sensor is None else simulate_plant(sensor.with_delay(0.0), record.t, w, initial="zero")
    k0 = int(np.flatnonzero(w != 0)[0]) if np.any(w) else 1
    yd = record.y - float(np.mean(record.y[:max(1, k0)]))
    proj = _Projection(record.t, w, record.y, mask, nb, sensor, plant.delay)
    roots = np.abs(np.r_[np.roots(plant.den), np.roots(num_f) if nb > 0 else []])
    roots = roots[roots > 0]
    out = []
    for zero, pole in _near_pairs(plant):
        others = _remove_root(np.asarray(plant.den, float) / plant.den[0], pole)
        grid = np.geomspace(float(roots.min()) / 10.0, min(float(roots.max()) * 100.0, 0.5 * np.pi / proj.dt),
                            LOCATIONS)
        ssr = np.full(grid.size, np.inf)
        models: list[tuple[np.ndarray, np.ndarray]] = [(np.zeros(1), np.ones(1))] * grid.size
        delays = np.full(grid.size, plant.delay)
        for i, q in enumerate(grid):
            try:
                _, den = srivc_with_root(record.t, v, yd, np.polymul(others, [1.0, q]), nb, plant.delay, q)
            except ModelError:
                continue
            r, num = proj.solve(den)
            ssr[i], models[i] = float(r @ r), (num, den)
            value, num, den, d = _polish(proj, den, q, fit.delay_fitted)
            if value < ssr[i]:
                ssr[i], models[i], delays[i] = value, (num, den), d
        k = int(np.argmin(ssr))
        out.append(PairProfile(zero, pole, grid, (ssr_fit - ssr) / s2, models[k], float(delays[k])))
    return out


def _dof(fit: TimeFitResult) -> int:
    """Fitted samples minus estimated parameters: ``SSR = residual_std^2 dof``."""
    samples = fit.y.size if fit.weights is None else int(np.count_nonzero(fit.weights))
    return samples - len(fit.names)


def relocate_pair(record: Record, fit: TimeFitResult, structure: Structure, delay: str | float | None,
                  sensor: Plant | str | None) -> TimeFitResult:
    """``fit``, or the structure fitted again from a better point on a nearly cancelling pair's profile.

    The refit replaces ``fit`` when its residual is lower; the profile's evidence is added to the kept fit's
    ``solver["pair_profile"]`` either way.

    Examples
    --------
    A relocation from a wrong basin ends :func:`pair_profile`'s example. A fit without a pole and a zero near
    each other has no pair to profile and is returned as it is:

    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.ident.structure import parse_structure
    >>> t = np.arange(0, 8, 0.01); u = np.where((t % 4) < 2, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2*(s+20)/((s+2)*(s+5))"), t, u)
    >>> st = parse_structure("k*(s+z)/((s+p1)*(s+p2))")
    >>> fit = fit_structure(record_from_arrays(t, u, y), st)
    >>> relocate_pair(record_from_arrays(t, u, y), fit, st, None, None) is fit
    True
    """
    profiles = pair_profile(record, fit)
    if not profiles:
        return fit
    evidence: list[dict[str, Any]] = [p.to_dict() for p in profiles]
    best = max(profiles, key=lambda p: float(np.max(p.drop)))
    kept = fit
    at = float(best.locations[int(np.argmax(best.drop))])
    where = (f"the fit ended with a zero at {-best.zero:.4g} beside a pole at {-best.pole:.4g}, one of the minima "
             f"along a nearly cancelling pair's location; with the pair's pole at {-at:.4g} ({LOCATIONS} "
             f"locations profiled over {best.locations[0]:.3g}-{best.locations[-1]:.3g} rad/s) the model fits "
             f"{float(np.max(best.drop)):.3g} noise variances of SSR better")
    if float(np.max(best.drop)) > REFIT_DROP:
        try:
            theta = map_to_structure(structure, *best.best)
            initial = {**dict(zip(structure.parameters, theta.tolist())), "delay": best.delay}
            # Levenberg-Marquardt: IPOPT's simulation-error problem stepped a pole into the right half-plane
            # from such a start and diverged (a 3rd-order plant, 8,000 samples), where LM converged in 0.4 s
            other = fit_structure(record, structure, delay, sensor, False, initial=initial, weights=fit.weights,
                                  check=True, solver="convolution")
        except (DataError, FitError, ModelError) as exc:
            evidence.append({"refit": f"failed: {exc}", "note": f"{where}, but the refit from there failed ({exc}): "
                                                                f"the fit is kept, and may not be the best one"})
        else:
            better = other.residual_std < fit.residual_std
            gain = (fit.residual_std ** 2 - other.residual_std ** 2) / fit.residual_std ** 2 * _dof(fit)
            evidence.append({"refit": "kept: a lower residual" if better else "not kept: no lower residual",
                             "residual_std": other.residual_std, "ssr_drop_noise_variances": gain,
                             "note": f"{where}: refitted from there, " + (
                                 f"{gain:.3g} noise variances of SSR lower, kept" if better
                                 else "no lower residual; the first fit is kept")})
            kept = other if better else fit
    return replace(kept, solver={**kept.solver, "pair_profile": evidence})
