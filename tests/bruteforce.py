"""Independent brute-force evaluation of P/PI designs on dense grids (plain numpy, no synth code).

Used to check that the optimizers find the optimum: every requirement and the
objective are computed here from the loop's frequency response on a dense
grid; stability is decided by counting the net crossings of the negative real
axis left of -1 (stable open-loop plant: the closed loop is stable iff the
count is zero).
"""

from __future__ import annotations

import numpy as np

LEVEL_3DB = 10 ** (-3 / 20)


def x4(s: np.ndarray, delay: float) -> np.ndarray:
    return 23 * (s + 0.43) / ((s + 9.6) * (s + 0.54)) * np.exp(-delay * s)


def frequency_grid(delay: float) -> np.ndarray:
    log = np.geomspace(1e-3, 3e3, 2500)
    lin = np.arange(0.0, 3e3, 0.1 / max(delay, 1e-3))[1:]
    return np.unique(np.concatenate([log, lin]))


def evaluate(kp: np.ndarray, ki: np.ndarray, delay: float, reqs: dict, w: np.ndarray,
             need: tuple[str, ...] = ("bandwidth", "crossover", "Ms"),
             ki_over_s: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Requirements and measures for controllers kp[i] + ki[i]/s (1-D arrays of equal length).

    ``out["ok"]`` always, and the measures named in ``need`` (each is another pass over the grid: a search asks for
    its objective's only). ``ki_over_s``: ``ki[:, None] / (j w)``, when the caller holds it (a grid search's ki
    column is the same for every kp). Either gives the same numbers as computing everything."""
    s = 1j * w
    G = x4(s, delay)
    np.seterr(divide="ignore", invalid="ignore")
    C = kp[:, None] + (ki[:, None] / s[None, :] if ki_over_s is None else ki_over_s)
    L = C * G[None, :]
    S = 1 / (1 + L)
    out: dict[str, np.ndarray] = {}
    # stability: net crossings of the negative real axis left of -1 (upward minus downward), the crossing's real
    # part interpolated only where Im L changes sign
    im = L.imag
    sign = np.sign(im)
    rows, cols = np.nonzero(sign[:, :-1] != sign[:, 1:])
    a, b = im[rows, cols], im[rows, cols + 1]
    frac = a / (a - b + 1e-300)
    re_at = L.real[rows, cols] + frac * (L.real[rows, cols + 1] - L.real[rows, cols])
    left = re_at < -1
    net = np.bincount(rows[left & (b > a)], minlength=kp.size) - np.bincount(rows[left & (b < a)], minlength=kp.size)
    stable = net == 0
    if np.all(ki == 0):  # type 0: also L(0) must not be left of -1
        stable &= (kp * x4(np.array([0.0]), 0.0)[0].real > -1)
    ok = stable.copy()
    if "Ms" in reqs or "Ms" in need:
        ms = 20 * np.log10(np.abs(S).max(axis=1))
    if "Ms" in reqs:
        ok &= ms <= reqs["Ms"]
    if "Mt" in reqs or "bandwidth" in need or "bw_min" in reqs:
        T = L / (1 + L)
        absT = np.abs(T)
    if "Mt" in reqs:
        ok &= 20 * np.log10(absT.max(axis=1)) <= reqs["Mt"]
    if "KS" in reqs:
        ok &= 20 * np.log10(np.abs(C * S).max(axis=1)) <= reqs["KS"]
    if "slew" in reqs:
        B, de, (w1, w2) = reqs["slew"]
        band = (w >= w1) & (w <= w2)
        ok &= (de * np.abs(C[:, band]) * w[band]).max(axis=1) <= B
    if "static" in reqs:
        db, g = reqs["static"]
        static = np.where(ki > 0, -np.inf, 20 * np.log10(np.abs(1 / (1 + kp * g))))
        ok &= static <= db
    if "bandwidth" in need or "bw_min" in reqs:
        t0 = np.where(ki > 0, 1.0, np.abs(kp * x4(np.array([0.0]), 0.0)[0] / (1 + kp * x4(np.array([0.0]), 0.0)[0])))
        level = LEVEL_3DB * t0[:, None]
        below = absT < level
        k = np.argmax(below, axis=1)
        rows = np.arange(k.size)
        km1 = np.maximum(k - 1, 0)
        m0, m1 = absT[rows, km1] - level[:, 0], absT[rows, k] - level[:, 0]
        frac = np.clip(m0 / np.where(m0 - m1 == 0, 1, m0 - m1), 0, 1)  # interpolate the crossing in log w
        crossing = np.exp(np.log(w[km1]) + frac * (np.log(w[k]) - np.log(w[km1])))
        first = np.where(below.any(axis=1), crossing, np.inf)
        first = np.where(t0 > 0, first, np.nan)  # no loop gain: T = 0, no bandwidth
        out["bandwidth"] = first
        if "bw_min" in reqs:
            ok &= np.nan_to_num(first, nan=-1.0) >= reqs["bw_min"]
    if "crossover" in need:
        mag = np.abs(L)
        above = mag >= 1
        out["crossover"] = np.where(above.any(axis=1) & ~above.all(axis=1),
                                    w[np.clip(np.argmax(~above, axis=1), 0, w.size - 1)], 0.0)
    if "Ms" in need:
        out["Ms"] = ms
    out["ok"] = ok & (np.abs(kp) + np.abs(ki) > 0)
    return out


_NEED = {"bandwidth": ("bandwidth",), "crossover": ("crossover",), "peak_sensitivity": ("Ms",)}
"""The measure each objective's score reads (:func:`_score`); the gains' objectives read none."""


def best_pi(delay: float, reqs: dict, objective: str, kp_max: float, ki_max: float, n: int = 61,
            zooms: int = 3) -> tuple[float, float, float]:
    """Best feasible (value, kp, ki) by a grid search zoomed around the best point."""
    w = frequency_grid(delay)
    kp_lo, kp_hi, ki_lo, ki_hi = 0.0, kp_max, 0.0, ki_max
    best = (-np.inf, np.nan, np.nan)
    for _ in range(zooms + 1):
        kps = np.linspace(kp_lo, kp_hi, n)
        kis = np.linspace(ki_lo, ki_hi, n)
        ki_over_s = kis[:, None] / (1j * w)[None, :]
        for kp in kps:
            # integral_gain scores ki itself: only a ki above the best so far can replace it
            cols = np.flatnonzero(kis > best[0]) if objective == "integral_gain" else np.arange(n)
            if cols.size == 0:
                continue
            res = evaluate(np.full(cols.size, kp), kis[cols], delay, reqs, w, _NEED.get(objective, ()),
                           ki_over_s[cols])
            score = _score(res, kis[cols], objective)
            score[~res["ok"]] = -np.inf
            j = int(np.argmax(score))
            if score[j] > best[0]:
                best = (float(score[j]), float(kp), float(kis[cols[j]]))
        dkp, dki = (kp_hi - kp_lo) / (n - 1), (ki_hi - ki_lo) / (n - 1)
        kp_lo, kp_hi = max(0.0, best[1] - 3 * dkp), min(kp_max, best[1] + 3 * dkp)
        ki_lo, ki_hi = max(0.0, best[2] - 3 * dki), min(ki_max, best[2] + 3 * dki)
    return best


def best_p(delay: float, reqs: dict, objective: str, kp_max: float, n: int = 2001,
           zooms: int = 2) -> tuple[float, float]:
    """Best feasible (value, kp) on a dense kp grid, zoomed around the best point."""
    w = frequency_grid(delay)
    lo, hi = 0.0, kp_max
    best = (-np.inf, np.nan)
    for _ in range(zooms + 1):
        kps = np.linspace(lo, hi, n)
        for chunk in np.array_split(np.arange(n), max(1, n // 100)):
            res = evaluate(kps[chunk], np.zeros(chunk.size), delay, reqs, w, _NEED.get(objective, ()))
            score = _score(res, kps[chunk], objective)
            score[~res["ok"]] = -np.inf
            j = int(np.argmax(score))
            if score[j] > best[0]:
                best = (float(score[j]), float(kps[chunk][j]))
        step = (hi - lo) / (n - 1)
        lo, hi = max(0.0, best[1] - 3 * step), min(kp_max, best[1] + 3 * step)
        n = 201
    return best


def _score(res: dict, gains: np.ndarray, objective: str) -> np.ndarray:
    if objective in ("integral_gain", "low_frequency_gain"):
        return gains.astype(float).copy()
    if objective == "bandwidth":
        return res["bandwidth"].copy()
    if objective == "crossover":
        return res["crossover"].copy()
    if objective == "peak_sensitivity":
        return -res["Ms"]
    raise ValueError(objective)
