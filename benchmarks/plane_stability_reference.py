"""Independent brute-force reference: closed-loop stability on a grid of two P/PI/PID parameters, delay exact.

Loop: unity negative feedback, controller ``C`` in series with ``G(s) = num(s)/den(s) exp(-delay s)``;
``C = kp`` ("P"), ``kp + ki/s`` ("PI") or ``kp + ki/s + kd s/(tf s + 1)`` ("PID"). Only numpy is used (nothing
from synth). The controller is written ``num_C/den_C`` with common factors of ``s`` cancelled (a PI with
``ki = 0`` is ``kp``), the loop ``L = Nl/Dl exp(-delay s)`` with ``Nl = num_C num`` and ``Dl = den_C den``.

The margin is ``sigma = 1e-6`` times the plant's smallest nonzero ``|pole or zero|`` (1 if none). A point is
*stable* when every closed-loop root has ``Re s < -sigma``, *marginal* when the rightmost root has
``|Re s| <= sigma`` (or the count is numerically ambiguous there); the comparison ignores marginal points.
Both are read from two counts: ``Z-`` roots with ``Re s > -sigma`` and ``Z+`` roots with ``Re s > +sigma``
(stable: ``Z- = 0``; marginal: ``Z- > 0 = Z+``).

Without delay the counts come from the roots of ``Dl + Nl`` (companion-matrix eigenvalues, numpy.roots' method,
batched over the grid). With a delay they come from the argument principle on ``1 + L`` along the vertical lines
``Re s = -sigma`` and ``Re s = +sigma``: ``Z = P - N``, ``P`` the zeros of ``Dl`` right of the line and ``N``
the counter-clockwise winding number of ``1 + L`` around 0 as ``w`` runs from -inf to +inf. ``N`` is computed
without sampling the spiral of the delay: it is the signed number of crossings of ``L`` over the ray
``(-inf, -1)``, and these happen only where ``|L| > 1``. ``|L(c + jw)| = 1`` is a polynomial equation in ``w^2``
(``e^(-2 delay c) |Nl|^2 = |Dl|^2``; the delay only scales the magnitude), so its roots bound every interval of
``|L| > 1`` (each classified by ``|L|`` at its midpoint, the crossings polished by a Newton step). Along the line
the phase of ``L`` has the closed form ``phi(w) = arg k + sum arg(s - z) - sum arg(s - p) - delay w`` with each
factor's branch continuous (``atan`` of ``(w - Im r)/(c - Re r)``, plus ``pi`` for a root right of the line), so
the net number of upward passes of ``phi`` through odd multiples of ``pi`` over an interval ``(a, b)`` is
``f(phi(b)) - f(phi(a))`` with ``f(x) = floor((x - pi)/(2 pi))``, and ``N`` is the sum over the intervals on both
half-lines. A crossover or ``w = 0`` where the Newton distance ``|1 + L|/|L'|`` to a closed-loop root is below a
quarter of ``sigma``, an open-loop pole on a line, a count below zero, or a coarse magnitude grid disagreeing with
the intervals, makes the point *ambiguous* (marginal). :func:`winding_count_sampled` is the slow, sampled
version of the same count (adaptive subdivision of the phase steps), used by the tests as a cross-check.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

__all__ = ["MARGIN", "classify", "closed_loop_counts", "controller_polynomials", "frequency_scale", "stable_grid",
           "winding_count_sampled"]

MARGIN = 1e-6  # sigma = MARGIN * frequency_scale(num, den)
AMBIGUITY = 0.25  # a Newton distance to a root below AMBIGUITY * sigma from a counting line: ambiguous
PARAMS = ("kp", "ki", "kd", "tf")
_GUARD_POINTS = 96  # coarse log grid on which |L| > 1 is checked against the intervals


def frequency_scale(num, den) -> float:
    """Smallest nonzero ``|pole or zero|`` of the plant, or 1.0 if it has none.

    Parameters
    ----------
    num, den : array_like
        Plant polynomials, highest power first.

    Returns
    -------
    float
        The scale in rad/s.

    Examples
    --------
    >>> frequency_scale([1.0], [1.0, 3.0, 2.0, 0.0])
    1.0
    >>> frequency_scale([1.0], [1.0, 0.0])
    1.0
    """
    roots = np.concatenate([np.roots(np.atleast_1d(np.asarray(num, float))),
                            np.roots(np.atleast_1d(np.asarray(den, float)))])
    mags = np.abs(roots[roots != 0])
    return float(mags.min()) if mags.size else 1.0


def _trim(p) -> np.ndarray:
    p = np.trim_zeros(np.atleast_1d(np.asarray(p, float)), "f")
    if p.size == 0:
        raise ValueError("a plant polynomial is zero")
    return p


def _conv(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise polynomial products of (N, m) and (N, k) (or (k,)) coefficient arrays."""
    b = np.broadcast_to(b, (a.shape[0], b.shape[-1]))
    out = np.zeros((a.shape[0], a.shape[1] + b.shape[1] - 1), np.result_type(a, b))
    for i in range(a.shape[1]):
        out[:, i:i + b.shape[1]] += a[:, i:i + 1] * b
    return out


def _batch_roots(coef: np.ndarray) -> np.ndarray:
    """Roots of each row (highest power first; exact leading zeros skipped, exact trailing zeros give exact zero
    roots), NaN-padded to (N, m - 1). Companion-matrix eigenvalues, as numpy.roots, grouped by degree."""
    coef = np.asarray(coef)
    n_rows, m = coef.shape
    out = np.full((n_rows, max(m - 1, 0)), np.nan + 0j)
    nz = coef != 0
    lead = np.where(nz.any(axis=1), nz.argmax(axis=1), m)
    trail = np.where(nz.any(axis=1), nz[:, ::-1].argmax(axis=1), 0)
    for lo, tr in {(int(a), int(b)) for a, b in zip(lead, trail)}:
        rows = np.flatnonzero((lead == lo) & (trail == tr))
        if lo >= m:
            continue
        deg, zeros = m - 1 - lo - tr, tr
        out[rows, :zeros] = 0.0
        if deg >= 1:
            c = coef[rows, lo:m - tr]
            comp = np.zeros((len(rows), deg, deg), np.result_type(c, float))
            comp[:, 0, :] = -c[:, 1:] / c[:, :1]
            comp[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
            out[rows, zeros:zeros + deg] = np.linalg.eigvals(comp)
    return out


def _lead(coef: np.ndarray) -> np.ndarray:
    """First nonzero coefficient of each row (0 for a zero row)."""
    nz = coef != 0
    return np.where(nz.any(axis=1), coef[np.arange(coef.shape[0]), nz.argmax(axis=1)], 0.0)


def controller_polynomials(ctype: str, params: Mapping[str, object]) -> tuple[np.ndarray, np.ndarray]:
    """Controller numerator and denominator for many parameter sets, common factors of ``s`` cancelled.

    Parameters
    ----------
    ctype : str
        "P", "PI" or "PID".
    params : mapping
        kp, ki, kd (default 0) and, for "PID", tf (> 0): scalars or arrays broadcast together. Names the type
        does not use are ignored.

    Returns
    -------
    num_c, den_c : ndarray
        (N, 3) arrays, highest power first, zero-padded on the left.

    Examples
    --------
    >>> num_c, den_c = controller_polynomials("PI", {"kp": [2.0, 2.0], "ki": [0.0, 1.0]})
    >>> num_c.tolist(), den_c.tolist()
    ([[0.0, 0.0, 2.0], [0.0, 2.0, 1.0]], [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
    """
    unknown = set(params) - set(PARAMS)
    if unknown:
        raise ValueError(f"unknown controller parameter(s) {sorted(unknown)}; known: {PARAMS}")
    if ctype == "PID" and "tf" not in params:
        raise ValueError("a PID needs tf (> 0)")
    kp, ki, kd, tf = np.broadcast_arrays(*(np.atleast_1d(np.asarray(params.get(k, 0.0 if k != "tf" else 1.0), float))
                                           for k in PARAMS))
    zero, one = np.zeros_like(kp), np.ones_like(kp)
    if ctype == "P":
        num_c, den_c = np.stack([zero, zero, kp], 1), np.stack([zero, zero, one], 1)
    elif ctype == "PI":
        num_c, den_c = np.stack([zero, kp, ki], 1), np.stack([zero, one, zero], 1)
    elif ctype == "PID":
        if np.any(~(tf > 0)):
            raise ValueError("tf must be > 0")
        num_c, den_c = np.stack([kp * tf + kd, kp + ki * tf, ki], 1), np.stack([tf, one, zero], 1)
    else:
        raise ValueError(f"ctype must be 'P', 'PI' or 'PID', not {ctype!r}")
    cancel = (num_c[:, 2] == 0) & (den_c[:, 2] == 0)
    num_c[cancel] = np.roll(num_c[cancel], 1, axis=1)
    den_c[cancel] = np.roll(den_c[cancel], 1, axis=1)
    return num_c, den_c


def _horner_shift(coef: np.ndarray, c: float) -> np.ndarray:
    """Row-wise coefficients, in w, of p(c + j w)."""
    r = coef[:, :1].astype(complex)
    for k in range(1, coef.shape[1]):
        new = np.zeros((coef.shape[0], k + 1), complex)
        new[:, :-1] += 1j * r
        new[:, 1:] += c * r
        new[:, -1] += coef[:, k]
        r = new
    return r


class _Loop:
    """The loops of one grid in factored form: L = k prod(s - z)/prod(s - p) exp(-delay s), the plant's roots
    (``z0``, ``p0``) shared by all loops, the controller's (``zc``, ``pc``, NaN-padded) one row per loop."""

    def __init__(self, nl: np.ndarray, dl: np.ndarray, z0: np.ndarray, p0: np.ndarray, zc: np.ndarray,
                 pc: np.ndarray, delay: float) -> None:
        self.nl, self.dl, self.delay = nl, dl, delay
        self.z0, self.p0, self.zc, self.pc = z0, p0, zc, pc
        with np.errstate(divide="ignore", invalid="ignore"):
            self.k = _lead(nl) / _lead(dl)
            self.logk = np.log(np.abs(self.k))
        self.poles = np.concatenate([np.broadcast_to(p0, (nl.shape[0], p0.size)), pc], 1)
        self.roots = np.concatenate([z0, p0, zc.ravel(), pc.ravel()])

    @staticmethod
    def _factors(w: np.ndarray, c: float, r: np.ndarray, full: bool) -> tuple:
        """Sums over the roots r (last axis, NaN: absent) of log|s - r|, arg(s - r) (continuous branch) and
        1/(s - r), at s = c + j w."""
        a = c - r.real
        b = w[..., None] - r.imag
        q = a * a + b * b
        present = ~np.isnan(r)
        logs = np.where(present, 0.5 * np.log(q), 0.0).sum(-1)
        if not full:
            return logs, None, None
        theta = np.where(a > 0, np.arctan2(b, a), np.pi + np.arctan2(-b, -a))
        theta = np.where(present, theta, 0.0).sum(-1)
        inv = (np.where(present, a / q, 0.0).sum(-1) - 1j * np.where(present, b / q, 0.0).sum(-1))
        return logs, theta, inv

    def evaluate(self, w: np.ndarray, c: float, full: bool = True) -> tuple:
        """log|L|, the continuous phase of L and L'/L at s = c + j w; w of shape (N, K), or (K,) shared by all
        loops. Only log|L| (the others None) unless ``full``."""
        shared = w.ndim == 1
        wc = w[None, :, None] if shared else w[..., None]
        zc, pc = self.zc[:, None, :], self.pc[:, None, :]
        lz0, tz0, iz0 = self._factors(w, c, self.z0, full)
        lp0, tp0, ip0 = self._factors(w, c, self.p0, full)
        lzc, tzc, izc = self._factors(wc[..., 0], c, zc, full)
        lpc, tpc, ipc = self._factors(wc[..., 0], c, pc, full)
        with np.errstate(invalid="ignore"):
            logmag = self.logk[:, None] - self.delay * c + (lz0 - lp0) + lzc - lpc
        if not full:
            return logmag, None, None
        phase = (np.where(self.k < 0, np.pi, 0.0)[:, None] + (tz0 - tp0) + tzc - tpc
                 - self.delay * (w[None, :] if shared else w))
        return logmag, phase, (iz0 - ip0) + izc - ipc - self.delay

    def winding(self, c: float, sigma: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Counter-clockwise winding of 1 + L around 0 along Re s = c, an ambiguity flag and a flag for |L| not
        falling below 1 as w grows."""
        n = self.nl.shape[0]
        a, b = _horner_shift(self.nl, c), _horner_shift(self.dl, c)
        q = np.exp(-2 * self.delay * c) * _conv(a, np.conj(a)).real - _conv(b, np.conj(b)).real
        xr = _batch_roots(q[:, ::2])
        real = np.isfinite(xr) & (xr.real > 0) & (np.abs(xr.imag) <= 1e-6 * np.abs(xr))
        w = np.sort(np.where(real, np.sqrt(np.abs(xr.real)), np.inf), axis=1)
        w = w[:, :max(1, int(np.isfinite(w).sum(1).max()))]
        fin = np.isfinite(w)
        wz = np.where(fin, w, 1.0)
        with np.errstate(all="ignore"):
            for _ in range(2):  # Newton on log|L| = 0, kept only when it moves little and improves
                lm, _, dlog = self.evaluate(wz, c)
                step = lm / dlog.imag  # d log|L| / dw = -Im(L'/L)
                new = wz + step
                lm2 = self.evaluate(new, c, full=False)[0]
                ok = fin & np.isfinite(new) & (np.abs(step) < 1e-3 * wz) & (np.abs(lm2) < np.abs(lm))
                wz = np.where(ok, new, wz)
            w = np.sort(np.where(fin, wz, np.inf), axis=1)
            wz = np.where(fin, w, 1.0)
            count = fin.sum(1)
            # status (|L| > 1) of the intervals [0, w1], [w1, w2], ..., [wK, inf)
            lo = np.concatenate([np.zeros((n, 1)), w], 1)
            hi = np.concatenate([w, np.full((n, 1), np.inf)], 1)
            mid = np.where(np.isinf(hi), np.where(lo == 0, 1.0, 2 * lo), np.where(lo == 0, hi / 2, np.sqrt(lo * hi)))
            valid = np.isfinite(lo)
            status = self.evaluate(np.where(valid, mid, 1.0), c, full=False)[0] > 0
            last = status[np.arange(n), count]
            status = np.where(valid, status, last[:, None])
            sgn = status[:, :-1].astype(int) - status[:, 1:].astype(int)  # +1: |L| falls through 1
            lm, ph, dlog = self.evaluate(wz, c)
            ph_neg = self.evaluate(-wz, c)[1]
            f = np.floor((ph - np.pi) / (2 * np.pi)) - np.floor((ph_neg - np.pi) / (2 * np.pi))
            winding = np.where(fin, sgn * f, 0.0).sum(1).round().astype(int)
            # Newton distance |1 + L| / |L'| to a closed-loop root, at the crossovers and at w = 0
            mag = np.exp(lm)
            dist = np.abs(1 + mag * np.exp(1j * ph)) / (mag * np.abs(dlog))
            amb = np.any(fin & ~(dist >= AMBIGUITY * sigma), axis=1)
            lm0, ph0, dlog0 = self.evaluate(np.zeros(1), c)
            mag0 = np.exp(lm0[:, 0])
            dist0 = np.abs(1 + mag0 * np.exp(1j * ph0[:, 0])) / (mag0 * np.abs(dlog0[:, 0]))
            amb |= ~(dist0 >= AMBIGUITY * sigma)
            amb |= ((lm0[:, 0] > 0) != status[:, 0]) & (np.abs(lm0[:, 0]) > 1e-9)
            # guard: |L| > 1 on a coarse log grid must agree with the intervals
            roots = np.abs(self.roots)
            roots = roots[np.isfinite(roots) & (roots > 0)]
            top = max(float(w[fin].max()) if fin.any() else 1.0, float(roots.max()) if roots.size else 1.0)
            bottom = min(float(w[fin].min()) if fin.any() else 1.0, float(roots.min()) if roots.size else 1.0)
            grid = np.geomspace(bottom * 1e-3, top * 1e3, _GUARD_POINTS)
            lg = self.evaluate(grid, c, full=False)[0]
            idx = (w[:, None, :] < grid[None, :, None]).sum(-1)
            expect = np.take_along_axis(status, idx, axis=1)
            amb |= np.any(((lg > 0) != expect) & (np.abs(lg) > 1e-6), axis=1)
        return winding, amb, last


def _by_roots(char: np.ndarray, sigma: float) -> dict[str, np.ndarray]:
    roots = _batch_roots(char)
    re = roots.real
    with np.errstate(invalid="ignore"):
        z_minus = (re > -sigma).sum(1)
        z_plus = (re > sigma).sum(1)
    degenerate = ~np.any(char != 0, axis=1)
    return {"z_minus": z_minus, "z_plus": z_plus, "ambiguous": degenerate, "not_decaying": np.zeros_like(degenerate)}


def closed_loop_counts(num, den, delay: float, ctype: str, params: Mapping[str, object],
                       method: str = "auto") -> dict[str, np.ndarray]:
    """Counts of closed-loop roots right of ``-sigma`` and of ``+sigma`` for many controllers.

    Parameters
    ----------
    num, den : array_like
        Proper plant, highest power first.
    delay : float
        Plant delay in seconds (>= 0).
    ctype, params : str, mapping
        As :func:`controller_polynomials`.
    method : str
        "auto" (roots without delay, winding with), "roots" (no delay only) or "winding".

    Returns
    -------
    dict
        ``z_minus``, ``z_plus`` (int arrays), ``ambiguous``, ``not_decaying`` (bool arrays: the count could not be
        trusted; ``|L|`` does not fall below 1 at high frequency behind a delay), ``stable``, ``marginal`` and
        ``sigma``.

    Examples
    --------
    >>> out = closed_loop_counts([1.0], [1.0, -1.0], 0.0, "PI", {"kp": [2.0, 0.5], "ki": 1.0})
    >>> out["z_minus"].tolist(), out["stable"].tolist()
    ([0, 2], [True, False])
    """
    num, den = _trim(num), _trim(den)
    if len(num) > len(den):
        raise ValueError("the plant must be proper")
    if delay < 0:
        raise ValueError("delay must be >= 0")
    sigma = MARGIN * frequency_scale(num, den)
    num_c, den_c = controller_polynomials(ctype, params)
    dl, nl = _conv(den_c, den), _conv(num_c, num)
    nl = np.concatenate([np.zeros((nl.shape[0], dl.shape[1] - nl.shape[1])), nl], 1)
    if method not in ("auto", "roots", "winding"):
        raise ValueError(f"unknown method {method!r}")
    if method == "roots" and delay > 0:
        raise ValueError("method 'roots' needs delay == 0")
    if method == "roots" or (method == "auto" and delay == 0):
        out = _by_roots(dl + nl, sigma)
    else:
        loop = _Loop(nl, dl, np.roots(num).astype(complex), np.roots(den).astype(complex), _batch_roots(num_c),
                     _batch_roots(den_c), float(delay))
        p = loop.poles
        counts, amb, not_decaying = {}, np.zeros(nl.shape[0], bool), np.zeros(nl.shape[0], bool)
        for key, c in (("z_minus", -sigma), ("z_plus", sigma)):
            winding, amb_c, nd = loop.winding(c, sigma)
            with np.errstate(invalid="ignore"):
                poles = (p.real > c).sum(1)
                amb |= amb_c | np.any(np.abs(p.real - c) < 1e-3 * sigma, axis=1)
            counts[key] = poles - winding
            not_decaying |= nd
        amb |= (counts["z_minus"] < 0) | (counts["z_plus"] < 0) | (counts["z_plus"] > counts["z_minus"])
        if delay == 0:  # without delay |L(inf)| >= 1 is a proper loop, counted as well (the arc adds nothing)
            amb |= not_decaying
            not_decaying = np.zeros_like(not_decaying)
        out = {**counts, "ambiguous": amb & ~not_decaying, "not_decaying": not_decaying}
    bad = out["ambiguous"] | out["not_decaying"]
    out["stable"] = (out["z_minus"] == 0) & ~bad
    out["marginal"] = (out["ambiguous"] | ((out["z_minus"] > 0) & (out["z_plus"] == 0))) & ~out["not_decaying"]
    out["sigma"] = sigma
    return out


def classify(num, den, delay: float, ctype: str, params: Mapping[str, object],
             method: str = "auto") -> tuple[np.ndarray, np.ndarray]:
    """Stable and marginal flags of many controllers (see :func:`closed_loop_counts`).

    Parameters
    ----------
    num, den, delay, ctype, params, method
        As :func:`closed_loop_counts`.

    Returns
    -------
    stable, marginal : ndarray of bool

    Examples
    --------
    >>> stable, marginal = classify([1.0], [1.0, 0.0], 1.0, "P", {"kp": [0.0, 1.0, 2.0]})
    >>> stable.tolist(), marginal.tolist()
    ([False, True, False], [True, False, False])
    """
    out = closed_loop_counts(num, den, delay, ctype, params, method)
    return out["stable"], out["marginal"]


def stable_grid(num, den, delay: float, ctype: str, fixed: Mapping[str, float], x_name: str,
                x_box: tuple[float, float], y_name: str, y_box: tuple[float, float], n: int = 161,
                method: str = "auto") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Brute-force stability map of the closed loop on a grid of two controller parameters.

    Parameters
    ----------
    num, den : array_like
        Plant polynomials, highest power first; ``G(s) = num(s)/den(s) exp(-delay s)`` (proper).
    delay : float
        Delay in seconds (>= 0).
    ctype : str
        "P" (``kp``), "PI" (``kp + ki/s``) or "PID" (``kp + ki/s + kd s/(tf s + 1)``).
    fixed : mapping
        The other parameters' values (kp, ki, kd default to 0; a PID needs tf). A name the type does not use
        is ignored (a "P" map over (kp, ki) repeats along ki).
    x_name, y_name : str
        The two varied parameters.
    x_box, y_box : tuple of float
        (lo, hi) of each.
    n : int
        Points per axis.
    method : str
        As :func:`closed_loop_counts`.

    Returns
    -------
    xs, ys : ndarray
        ``np.linspace`` over the boxes, length ``n``.
    stable : ndarray of bool
        (n, n), ``[j, i]`` for ``(ys[j], xs[i])``: every closed-loop root has ``Re s < -sigma``.
    marginal : ndarray of bool
        (n, n): the rightmost root has ``|Re s| <= sigma`` or the count is ambiguous (to be ignored).

    Examples
    --------
    >>> xs, ys, stable, marginal = stable_grid([1.0], [1.0, 3.0, 3.0, 1.0], 0.0, "P", {}, "kp", (-2.0, 10.0),
    ...                                        "ki", (0.0, 1.0), n=13)
    >>> xs[stable[0]].tolist(), xs[marginal[0]].tolist()
    ([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0], [-1.0, 8.0])
    """
    if x_name == y_name:
        raise ValueError("x_name and y_name must differ")
    xs, ys = np.linspace(*x_box, n), np.linspace(*y_box, n)
    gx, gy = np.meshgrid(xs, ys)
    params = {k: float(v) for k, v in fixed.items()}
    params[x_name], params[y_name] = gx.ravel(), gy.ravel()
    stable, marginal = classify(num, den, delay, ctype, params, method)
    return xs, ys, stable.reshape(n, n), marginal.reshape(n, n)


def winding_count_sampled(num_c, den_c, num, den, delay: float, shift: float, max_step: float = 0.3) -> int:
    """Closed-loop roots right of ``Re s = shift`` by the sampled argument principle (slow; a cross-check).

    ``1 + L`` is sampled along ``s = shift + j w`` from ``w = 0`` up to where ``|L|`` stays below 0.05 (found on
    a fine log grid of the magnitude), on a log grid joined with a linear one of ``0.5/delay`` spacing; any step
    whose phase change exceeds ``max_step`` is halved, recursively. The negative half follows by symmetry.

    Parameters
    ----------
    num_c, den_c, num, den : array_like
        Controller and plant polynomials (the loop strictly proper).
    delay, shift : float
        Delay (s) and the abscissa of the counting line.
    max_step : float
        Largest accepted phase step in rad.

    Returns
    -------
    int
        ``P - N``: the roots of ``den_c den + num_c num exp(-delay s)`` with ``Re s > shift``.

    Examples
    --------
    >>> winding_count_sampled([2.0], [1.0], [1.0], [1.0, 0.0], 1.0, -1e-6)
    2
    """
    nl, dl = np.polymul(num_c, num), _trim(np.polymul(den_c, den))
    nl = np.trim_zeros(np.atleast_1d(nl), "f")
    if nl.size and len(nl) >= len(dl):
        raise ValueError("the loop must be strictly proper")
    poles = int(np.sum(np.roots(dl).real > shift))
    if not nl.size or not np.any(nl):
        return poles

    def one_plus_l(w: np.ndarray) -> np.ndarray:
        s = shift + 1j * w
        return 1 + np.polyval(nl, s) / np.polyval(dl, s) * np.exp(-delay * s)

    feats = np.abs(np.concatenate([np.roots(nl), np.roots(dl)]))
    feats = feats[feats > 0]
    lo = min(1.0, feats.min()) if feats.size else 1.0
    hi = max(1.0, feats.max()) if feats.size else 1.0
    probe = np.geomspace(lo * 1e-4, hi * 1e9, 4000)
    big = np.abs(one_plus_l(probe) - 1) >= 0.05
    w_max = 4 * probe[np.flatnonzero(big)[-1]] if big.any() else lo
    parts = [[0.0], np.geomspace(max(abs(shift), 1e-12) * 1e-2, w_max, 100 * 14 + 1)]
    if delay > 0:
        parts.append(np.linspace(0, w_max, int(np.ceil(w_max * delay / 0.5)) + 2))
    w = np.unique(np.concatenate(parts))
    f = one_plus_l(w)
    for _ in range(80):
        step = np.angle(f[1:] / f[:-1])
        bad = np.flatnonzero(np.abs(step) > max_step)
        if bad.size == 0:
            break
        a, b = w[bad], w[bad + 1]
        if np.any(b - a <= 1e-14 * b):
            raise ArithmeticError("a closed-loop root on the counting line")
        mid = np.where(a > 0, np.sqrt(a * b), b / 2)
        w = np.insert(w, bad + 1, mid)
        f = np.insert(f, bad + 1, one_plus_l(mid))
    else:
        raise ArithmeticError("phase steps not resolved")
    theta0 = 0.0 if f[0].real > 0 else np.pi
    theta_end = theta0 + np.angle(f[1:] / f[:-1]).sum()
    theta_inf = 2 * np.pi * np.round(theta_end / (2 * np.pi))
    return poles - round((theta_inf - theta0) / np.pi)
