"""Deterministic start of the simulation-error fit: an SRIVC linear model mapped onto a structure.

1. A linear continuous-time model of the structure's orders is fitted by the
   simplified refined instrumental-variable method (SRIVC: the
   Sanathanan-Koerner / Steiglitz-McBride iteration with the prefilter
   ``1/A(s)`` and instruments from the simulated noise-free output), first
   with the state-variable filter ``1/(s + lambda)^n`` for a few ``lambda``,
   then on a grid of delays up to the first visible response
   (:func:`linear_initial_model`).
2. That model is mapped onto the structure's parameters by a least-squares
   fit of the frequency responses (relative error on a log grid around its
   poles and zeros), from a fixed list of starting points (:func:`map_to_structure`).

:func:`synth.ident.timefit.fit_structure` hands the result to IPOPT.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from synth.distributions import chi2_ppf
from synth.errors import ModelError
from synth.ident.filter_bank import filter_bank
from synth.ident.structure import Structure
from synth.plant import Plant

__all__ = ["linear_initial_model", "map_to_structure", "srivc_with_root"]


def _bank(den: np.ndarray, t: np.ndarray, x: np.ndarray, count: int, delay: float, periodic: bool,
          reps: int) -> list[np.ndarray]:
    dt = float(t[1] - t[0])
    if not periodic:
        return filter_bank(den, dt, x, count, delay)
    n = x.size
    return [v[-n:] for v in filter_bank(den, dt, np.tile(x, reps), count, delay)]


def _tile_filter(plant: Plant, t: np.ndarray, x: np.ndarray, periodic: bool, reps: int) -> np.ndarray:
    """``plant`` applied to ``x`` from zero state (or its periodic response), through :func:`filter_bank`."""
    num = plant.num[::-1]
    bank = _bank(plant.den, t, x, num.size, plant.delay, periodic, reps)
    return sum(c * b for c, b in zip(num, bank))


def _reps(den: np.ndarray, duration: float) -> int:
    """Periods to simulate so the transient of ``1/den`` has decayed below 1e-6."""
    slowest = float(np.min(np.abs(np.real(np.roots(den))))) if den.size > 1 else 1e9
    if slowest <= 0:
        return 10
    return int(min(20, max(2, np.ceil(14.0 / (slowest * duration)) + 1)))


def _stable(den: np.ndarray) -> np.ndarray:
    roots = np.roots(den)
    if roots.size == 0:
        return den
    roots = np.where(roots.real > 0, -roots.real + 1j * roots.imag, roots)
    roots = np.where(np.abs(roots.real) < 1e-9, roots - 1e-6, roots)
    return np.real(np.poly(roots)) * den[0]


WANDERED = 1.01
""":func:`_srivc` returns an earlier iterate instead of its last when the last one's simulation error (SSR) is
more than this factor above the earlier one's: a converged iteration's iterates differ in rounding only."""


def _srivc(t: np.ndarray, v: np.ndarray, y: np.ndarray, na: int, nb: int, delay: float, lam: float,
           periodic: bool, iterations: int = 8, offset: bool = False) -> tuple[np.ndarray, np.ndarray, float, float]:
    """SRIVC estimate of ``B(s)/A(s) exp(-delay s)`` from ``v`` to ``y`` (deviation signals): ``num, den``, the
    SSR of its simulation and its output offset (with ``offset``, a record from rest plus a free offset: the
    offset is estimated and the SSR is that of the best offset; without, 0).

    The last iterate is returned unless an earlier one simulates the record clearly better (:data:`WANDERED`):
    with more poles and zeros than the record resolves, the instruments are nearly collinear and the iteration
    can leave a fit at the noise for one far off and oscillate there (a first-order plant fitted with a pole and
    a zero too many: SSR 0.82 at the first iterate, 7,710 at the eighth)."""
    duration = t[-1] - t[0] + (t[1] - t[0])
    den = np.poly(-lam * np.ones(na)) if na else np.array([1.0])
    num = None
    best: tuple[np.ndarray, np.ndarray, float, float] | None = None  # the iterate that simulated best so far
    for it in range(iterations + 1):
        try:  # an iterate far off (e.g. poles far beyond the sampling rate) may overflow the filters
            with np.errstate(over="ignore", invalid="ignore"):
                new_num, new_den, sim = _srivc_step(t, v, y, na, nb, delay, periodic, duration, num, den, offset)
        except (np.linalg.LinAlgError, ValueError, FloatingPointError):
            break
        if sim is not None:  # the simulation of the iterate (num, den) the step started from
            fitted = _simulation_fit(y, sim, offset)
            if best is None or fitted[0] < best[2]:
                best = (num, den, *fitted)
        if not (np.all(np.isfinite(new_num)) and np.all(np.isfinite(new_den))):
            break
        converged = num is not None and np.allclose(new_den, den, rtol=1e-7) and np.allclose(new_num, num, rtol=1e-7)
        den, num = new_den, new_num
        if converged and it > 0:
            break
    if num is None:
        return np.array([0.0]), den, float("inf"), 0.0
    reps = _reps(den, duration) if periodic else 1
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            sim = _tile_filter(Plant(num, den, delay), t, v, periodic, reps)
    except (np.linalg.LinAlgError, ValueError, FloatingPointError):
        sim = None
    ssr, level = _simulation_fit(y, sim, offset) if sim is not None else (float("inf"), 0.0)
    if best is not None and not ssr <= WANDERED * best[2]:
        return best
    return num, den, ssr, level


def _simulation_fit(y: np.ndarray, sim: np.ndarray, offset: bool) -> tuple[float, float]:
    """The SSR of ``y`` against the simulation ``sim`` (plus the best output offset with ``offset``) and that
    offset; an SSR that is not finite is infinite."""
    level = float(np.mean(y - sim)) if offset else 0.0
    ssr = float(np.sum((y - sim - level) ** 2))
    return (ssr, level) if np.isfinite(ssr) else (float("inf"), 0.0)


def _srivc_step(t: np.ndarray, v: np.ndarray, y: np.ndarray, na: int, nb: int, delay: float, periodic: bool,
                duration: float, num: np.ndarray | None, den: np.ndarray,
                offset: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """One SRIVC iteration: the instrumental-variable estimate with the prefilter ``1/den`` (with ``offset``, a
    free output offset as one more regressor), and the simulated output of ``num/den`` that gave its instruments
    (None at the first iteration, whose instruments are the regressors)."""
    reps = _reps(den, duration) if periodic else 1
    yf = _bank(den, t, y, na + 1, 0.0, periodic, reps)
    vf = _bank(den, t, v, nb + 1, delay, periodic, reps)
    # from rest with a free output offset b (the model class of the fit that follows): y = B/A v + b, so
    # A(p) y_f = B(p) v_f + b (A/den) 1, which is b 1 where the iteration converges (den = A)
    extra = [np.ones_like(y)] if offset else []
    phi = np.column_stack([-yf[k] for k in range(na)] + vf + extra)
    xhat = None
    if num is None:
        zeta = phi
    else:
        xhat = _tile_filter(Plant(num, den, delay), t, v, periodic, reps)
        xf = _bank(den, t, xhat, na, 0.0, periodic, reps)
        zeta = np.column_stack([-xf[k] for k in range(na)] + vf + extra)
    try:
        est = np.linalg.solve(zeta.T @ phi, zeta.T @ yf[na])
    except np.linalg.LinAlgError:
        est = np.linalg.lstsq(phi, yf[na], rcond=None)[0]
    a = est[:na][::-1]
    return est[na:na + nb + 1][::-1], (_stable(np.r_[1.0, a]) if na else np.array([1.0])), xhat


def srivc_with_root(t: np.ndarray, v: np.ndarray, y: np.ndarray, den: np.ndarray, nb: int, delay: float, root: float,
                    iterations: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """SRIVC estimate of ``B(s)/A(s) exp(-delay s)`` from ``v`` to ``y`` with ``A(s)`` holding the factor ``s + root``.

    The other factor ``A'(s)`` (monic) and ``B(s)`` (degree ``nb``) are estimated: ``(s + root) A'(s) y_f =
    B(s) v_f`` is linear in both, with the prefilter ``1/A(s)`` of the previous iterate; ``den`` (which holds
    ``s + root``) is the first prefilter. Non-periodic records from rest. What
    :mod:`synth.ident.pair_relocation` profiles a nearly cancelling pair's location with.

    Returns
    -------
    num, den : numpy.ndarray
        ``B`` and ``A`` (highest power first; ``A`` monic, its other factor made stable).

    Examples
    --------
    >>> from synth.ident.simulate import simulate_plant
    >>> t = np.arange(0, 6, 0.01); u = np.where((t % 2) >= 1, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("6/((s+2)*(s+3))"), t, u)
    >>> num, den = srivc_with_root(t, u, y, np.poly([-3.0, -1.0]), 0, 0.0, 3.0)
    >>> num.round(4).tolist(), (-np.roots(den)).round(4).tolist()
    ([6.0], [3.0, 2.0])
    """
    na = np.asarray(den).size - 1
    m = na - 1
    den = np.asarray(den, float) / den[0]
    num: np.ndarray | None = None
    for _ in range(iterations):
        with np.errstate(over="ignore", invalid="ignore"):
            yf = _bank(den, t, y, na + 1, 0.0, False, 1)
            vf = _bank(den, t, v, nb + 1, delay, False, 1)
            source = yf if num is None else _bank(den, t, _tile_filter(Plant(num, den, delay), t, v, False, 1),
                                                  na + 1, 0.0, False, 1)
        phi = np.column_stack([-(yf[i + 1] + root * yf[i]) for i in range(m)] + vf)
        zeta = np.column_stack([-(source[i + 1] + root * source[i]) for i in range(m)] + vf)
        try:
            est = np.linalg.solve(zeta.T @ phi, zeta.T @ (yf[m + 1] + root * yf[m]))
        except np.linalg.LinAlgError:
            break
        if not np.all(np.isfinite(est)):
            break
        new_num, new_den = est[m:][::-1], np.polymul(_stable(np.r_[1.0, est[:m][::-1]]), [1.0, root])
        done = num is not None and np.allclose(new_den, den, rtol=1e-7) and np.allclose(new_num, num, rtol=1e-7)
        num, den = new_num, new_den
        if done:
            break
    if num is None:
        raise ModelError(f"SRIVC with a root at {-root:g} found no estimate")
    return num, den


def _first_response(t: np.ndarray, w: np.ndarray, y: np.ndarray) -> float:
    """Time from the first input change to the first output change above the noise."""
    k0 = int(np.flatnonzero(np.abs(np.diff(w)) > 0)[0]) + 1 if np.any(np.diff(w)) else 0
    sigma = float(np.std(np.diff(y)) / np.sqrt(2.0)) + 1e-12 * (np.ptp(y) + 1.0)
    base = float(np.mean(y[max(0, k0 - 20):k0 + 1]))
    after = np.flatnonzero(np.abs(y[k0:] - base) > max(5 * sigma, 0.05 * np.ptp(y)))
    return float(after[0] * (t[1] - t[0])) if after.size else 0.1 * float(t[-1] - t[0])


def linear_initial_model(t: np.ndarray, w: np.ndarray, yd: np.ndarray, st: Structure, sensor: Plant | None, periodic: bool,
                 delay: float | None) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Deterministic linear model (num, den of ``F``), delay and output offset from SRIVC on a delay grid.

    A record that is not periodic is modelled as the fit that follows models it: ``F`` from rest at the first
    sample plus an output offset. The offset is 0 (the reference levels, the output's mean before the first input
    change, a steady state) unless the input moves from its first sample on and a free offset, one more regressor
    of the instrumental-variable estimate, lowers the simulation error significantly (:func:`_needs_offset`): a
    record cut out of a running excitation, whose first samples are no steady state, gets its offset estimated.

    Parameters
    ----------
    t : numpy.ndarray
        Uniform sample times [s].
    w, yd : numpy.ndarray
        Input and output as deviations from their reference levels.
    st : Structure
        Gives the orders of the linear model.
    sensor : Plant or None
        Known sensor in series (the input is filtered by it first).
    periodic : bool
        The record is one period of a periodic response.
    delay : float or None
        A fixed delay [s]; ``None`` searches a grid up to the first visible response.

    Returns
    -------
    num, den : numpy.ndarray
        Coefficients of ``F`` (highest power first).
    delay : float
    offset : float
        Output level at zero input deviation, relative to ``yd``'s reference (0 unless estimated).

    Examples
    --------
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.ident.structure import parse_structure
    >>> t = np.arange(0, 3, 0.01); u = np.where(t >= 0.5, 1.0, 0.0)
    >>> y = simulate_plant(Plant.from_string("2/(s+3)"), t, u)
    >>> num, den, d, b = linear_initial_model(t, u, y, parse_structure("k/(s+p)"), None, False, 0.0)
    >>> (num / den[0]).round(4).tolist(), (den / den[0]).round(4).tolist(), d, round(b, 6)
    ([2.0], [1.0, 3.0], 0.0, 0.0)

    The same plant under two sines that began 1 s before the record, its output shifted by -0.5: the first
    samples are no steady state. The start is the plant (a few per cent off: the state at the first sample,
    which the model from rest leaves out, decays within the record) and the output level ``G(0) u - 0.5``
    (without the offset, SRIVC gives a pole at 5.3 rad/s and a static gain of 0.30).

    >>> tl = np.arange(0, 21, 0.01); ul = 0.3 + np.sin(1.3 * tl) + np.sin(7.1 * tl)
    >>> yl = simulate_plant(Plant.from_string("2/(s+3)"), tl, ul) - 0.5
    >>> t, u, y = tl[100:] - tl[100], ul[100:], yl[100:]
    >>> num, den, d, b = linear_initial_model(t, u - u[0], y - y[0], parse_structure("k/(s+p)"), None, False, 0.0)
    >>> (num / den[0]).round(2).tolist(), (den / den[0]).round(2).tolist(), round(float(y[0] + b - 2 / 3 * u[0]), 2)
    ([2.01], [1.0, 3.21], -0.58)
    """
    dt = t[1] - t[0]
    duration = t[-1] - t[0] + dt
    reps = _reps(sensor.den, duration) if (periodic and sensor is not None) else 1
    v = _tile_filter(sensor.with_delay(0.0), t, w, periodic, reps) if sensor is not None else w
    na, nb = st.den_degree, st.num_degree
    if delay is None:
        d_vis = max(_first_response(t, w, yd), 2 * dt)
        grid = np.linspace(0.0, d_vis, 9)
    else:
        grid = np.array([delay])
    lams = np.geomspace(20.0 / duration, 0.05 / dt, 5)
    mid = grid[len(grid) // 2]
    screen = [_srivc(t, v, yd, na, nb, mid, lam, periodic, 4)[2] for lam in lams]
    free = False
    if not periodic and w.size > 1 and w[1] != w[0]:  # the input moves from its first sample on
        free, screen = _needs_offset(t, v, yd, na, nb, mid, lams, screen)
    best_lam = lams[int(np.argmin(screen))]
    fits = [(_srivc(t, v, yd, na, nb, d, best_lam, periodic, offset=free), d) for d in grid]
    (num, den, ssr, offset), d0 = min(fits, key=lambda f: f[0][2])
    if grid.size > 1:  # refine the delay between the neighbouring grid points
        from scipy.optimize import minimize_scalar

        step = grid[1] - grid[0]
        sol = minimize_scalar(lambda d: _srivc(t, v, yd, na, nb, d, best_lam, periodic, 4, free)[2],
                              bounds=(max(0.0, d0 - step), d0 + step), method="bounded",
                              options={"xatol": 0.1 * dt})
        if sol.fun < ssr:
            d0 = float(sol.x)
            num, den, _, offset = _srivc(t, v, yd, na, nb, d0, best_lam, periodic, offset=free)
    return num, den, float(d0), offset


def _needs_offset(t: np.ndarray, v: np.ndarray, y: np.ndarray, na: int, nb: int, delay: float,
                  lams: np.ndarray, fixed: list[float]) -> tuple[bool, list[float]]:
    """Whether a record shows an output offset against its reference level: the SRIVC screen (4 iterations per
    ``lambda``) with a free offset lowers the simulation error significantly (an F-test of the one more
    parameter at 0.1 %) below the screen with the offset at 0 (its SSRs ``fixed``). Returns the answer and the
    screen to pick ``lambda`` from.

    Asked only where the input moves from its first sample on: the reference levels are then single samples of a
    response in progress (a record cut out of a running excitation), whose level the SRIVC estimate without an
    offset explains by a slow pole pair. An input that holds its first value a while gives the record's rest
    before it (the fit's own assumption), and the output's mean over it is the reference."""
    free = [_srivc(t, v, y, na, nb, delay, lam, False, 4, True)[2] for lam in lams]
    best_fixed, best_free, dof = min(fixed), min(free), y.size - na - nb - 2
    if dof > 0 and np.isfinite(best_free) and best_fixed - best_free > float(chi2_ppf(0.999, 1)) * best_free / dof:
        return True, free
    return False, fixed


def map_to_structure(st: Structure, num: np.ndarray, den: np.ndarray) -> np.ndarray:
    """Structure parameters whose frequency response best matches ``num/den`` (relative error).

    Coefficient matching first (polynomial equations, few local minima), then the relative
    frequency-response error on a log grid around the poles and zeros, from a fixed list of starts.

    Raises
    ------
    ModelError
        No start gives a finite fit.

    Examples
    --------
    >>> from synth.ident.structure import parse_structure
    >>> map_to_structure(parse_structure("k/(T*s+1)"), np.array([2.0]), np.array([1.0, 4.0])).round(4).tolist()
    [0.5, 0.25]
    """
    roots = np.r_[np.roots(den), np.roots(num) if num.size > 1 else []]
    mags = np.abs(roots[np.abs(roots) > 1e-9])
    lo, hi = (float(mags.min()) / 10, float(mags.max()) * 10) if mags.size else (0.01, 100.0)
    w = np.geomspace(lo, hi, 80)
    s = 1j * w
    target = np.polyval(num, s) / np.polyval(den, s)
    weight = 1.0 / np.maximum(np.abs(target), 1e-300)

    def resid(theta: np.ndarray) -> np.ndarray:
        n_, d_ = st.coefficients(theta)
        with np.errstate(all="ignore"):
            g = np.polyval(n_, s) / np.polyval(d_, s)
        r = (g - target) * weight
        r = np.r_[r.real, r.imag]
        return np.where(np.isfinite(r), r, 1e6)

    num_t = np.r_[np.zeros(st.num_degree + 1 - num.size), num] / den[0]
    den_t = den / den[0]
    target_c = np.r_[num_t, den_t]
    cscale = np.maximum(np.abs(target_c), 1e-9 * np.max(np.abs(target_c)))

    def resid_coef(theta: np.ndarray) -> np.ndarray:
        n_, d_ = st.coefficients(theta)
        with np.errstate(all="ignore"):
            r = (np.r_[n_, d_] / d_[0] - target_c) / cscale
        return np.where(np.isfinite(r), r, 1e6)

    p = len(st.parameters)
    best: tuple[float, np.ndarray] | None = None
    for c in (1.0, 0.1, 10.0, 0.01, 100.0, 1000.0):
        x0 = c * (1.0 + 0.15 * np.arange(p))
        try:  # coefficient matching first (polynomial equations, few local minima), then the frequency fit
            sol = least_squares(resid_coef, x0, method="lm", max_nfev=400 * (p + 1))
            sol = least_squares(resid, sol.x, method="lm", max_nfev=400 * (p + 1))
        except (ValueError, np.linalg.LinAlgError):
            continue
        cost = float(np.sum(sol.fun**2))
        if best is None or cost < best[0]:
            best = (cost, sol.x)
        if cost < 1e-16 * w.size:
            break
    if best is None:
        raise ModelError(f"structure {st.formula!r}: could not map an initial linear model onto its parameters")
    return best[1]
