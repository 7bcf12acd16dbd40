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


def evaluate(kp: np.ndarray, ki: np.ndarray, delay: float, reqs: dict, w: np.ndarray) -> dict[str, np.ndarray]:
    """Requirements and measures for controllers kp[i] + ki[i]/s (1-D arrays of equal length)."""
    s = 1j * w
    G = x4(s, delay)
    np.seterr(divide="ignore", invalid="ignore")
    C = kp[:, None] + ki[:, None] / s[None, :]
    L = C * G[None, :]
    S = 1 / (1 + L)
    T = L / (1 + L)
    out: dict[str, np.ndarray] = {}
    # stability: net crossings of the negative real axis left of -1 (upward minus downward)
    im = L.imag
    cross = np.sign(im[:, :-1]) != np.sign(im[:, 1:])
    frac = im[:, :-1] / (im[:, :-1] - im[:, 1:] + 1e-300)
    re_at = L.real[:, :-1] + frac * (L.real[:, 1:] - L.real[:, :-1])
    left = cross & (re_at < -1)
    up = left & (im[:, 1:] > im[:, :-1])
    down = left & (im[:, 1:] < im[:, :-1])
    stable = (up.sum(axis=1) - down.sum(axis=1)) == 0
    if np.all(ki == 0):  # type 0: also L(0) must not be left of -1
        stable &= (kp * x4(np.array([0.0]), 0.0)[0].real > -1)
    ok = stable.copy()
    if "Ms" in reqs:
        ok &= 20 * np.log10(np.abs(S).max(axis=1)) <= reqs["Ms"]
    if "Mt" in reqs:
        ok &= 20 * np.log10(np.abs(T).max(axis=1)) <= reqs["Mt"]
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
    t0 = np.where(ki > 0, 1.0, np.abs(kp * x4(np.array([0.0]), 0.0)[0] / (1 + kp * x4(np.array([0.0]), 0.0)[0])))
    level = LEVEL_3DB * t0[:, None]
    below = np.abs(T) < level
    k = np.argmax(below, axis=1)
    rows = np.arange(k.size)
    km1 = np.maximum(k - 1, 0)
    m0, m1 = np.abs(T[rows, km1]) - level[:, 0], np.abs(T[rows, k]) - level[:, 0]
    frac = np.clip(m0 / np.where(m0 - m1 == 0, 1, m0 - m1), 0, 1)  # interpolate the crossing in log w
    crossing = np.exp(np.log(w[km1]) + frac * (np.log(w[k]) - np.log(w[km1])))
    first = np.where(below.any(axis=1), crossing, np.inf)
    first = np.where(t0 > 0, first, np.nan)  # no loop gain: T = 0, no bandwidth
    out["bandwidth"] = first
    if "bw_min" in reqs:
        ok &= np.nan_to_num(first, nan=-1.0) >= reqs["bw_min"]
    mag = np.abs(L)
    above = mag >= 1
    out["crossover"] = np.where(above.any(axis=1) & ~above.all(axis=1),
                                w[np.clip(np.argmax(~above, axis=1), 0, w.size - 1)], 0.0)
    out["Ms"] = 20 * np.log10(np.abs(S).max(axis=1))
    out["ok"] = ok & (np.abs(kp) + np.abs(ki) > 0)
    return out


def best_pi(delay: float, reqs: dict, objective: str, kp_max: float, ki_max: float, n: int = 61,
            zooms: int = 3) -> tuple[float, float, float]:
    """Best feasible (value, kp, ki) by a grid search zoomed around the best point."""
    w = frequency_grid(delay)
    kp_lo, kp_hi, ki_lo, ki_hi = 0.0, kp_max, 0.0, ki_max
    best = (-np.inf, np.nan, np.nan)
    for _ in range(zooms + 1):
        kps = np.linspace(kp_lo, kp_hi, n)
        kis = np.linspace(ki_lo, ki_hi, n)
        for kp in kps:
            res = evaluate(np.full(n, kp), kis, delay, reqs, w)
            score = _score(res, kis, objective)
            score[~res["ok"]] = -np.inf
            j = int(np.argmax(score))
            if score[j] > best[0]:
                best = (float(score[j]), float(kp), float(kis[j]))
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
            res = evaluate(kps[chunk], np.zeros(chunk.size), delay, reqs, w)
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
