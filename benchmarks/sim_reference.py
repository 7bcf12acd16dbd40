"""An independent reference for synth's nonlinear loop simulation (issue 15, item 3).

Written from the *description* of the sampled loop in docs/simulation.md, without synth's
kernel: nothing here imports ``synth``. A loop is a plain dict (see ``benchmarks/sim_cases.py``):

    plant: {num, den}            continuous, strictly proper, deviation units
    delay: s                     in-loop delay (any real number >= 0, exact)
    controller: {type, kp, ki, kd, tf}   C(s) = kp + ki/s + kd s/(tf s + 1), Tustin at dt
    actuator: [[kind, {...}], ...]       saturation | rate_limit | dead_zone | backlash | relay | quantizer
    sensor:   [[kind, {...}], ...]       (the same kinds; quantizer is the usual one)
    dt, step (A), t_step

The sampled loop, per step k (t = k dt): y[k] = C x(k dt); m = sensor(y[k]);
u = C(z)(r[k] - m); a[k] = actuator(u); the plant input over [k dt, (k+1) dt) is a(t - delay)
with a(.) held between samples. The plant is propagated either by the exact matrix exponential
of the held input (``scipy.linalg.expm`` on an augmented matrix) or, as a check of that, by
``scipy.integrate.solve_ivp`` (DOP853, rtol 1e-11) over every piece of every step.

The verdict here is taken on a long fixed horizon chosen by the case generator (generous, several
times what synth needs); it does not adapt. ``classify`` is its own criterion, written for this
file: settled, limit_cycle (amplitude = half peak-to-peak over the last 3 whole cycles, period =
mean of the last up-crossing intervals), diverging, or ``ambiguous`` when even the long run does
not decide (reported separately, never counted as agreement).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
import scipy.signal
from scipy.integrate import solve_ivp

__all__ = ["ReferenceRun", "classify", "reference_run", "simulate_reference"]


def _block(kind: str, p: dict[str, float]):
    """A per-sample function of (x, state) -> (y, state) for one block kind."""
    if kind == "saturation":
        lo, hi = p["min"], p["max"]
        return lambda x, s: (min(max(x, lo), hi), s)
    if kind == "dead_zone":
        w = p["width"]
        return lambda x, s: ((x - w) if x > w else ((x + w) if x < -w else 0.0), s)
    if kind == "quantizer":
        q = p["step"]
        return lambda x, s: (q * float(np.round(x / q)), s)
    if kind == "relay":
        m, eps = p["level"], p["eps"]
        return lambda x, s: (m if x >= eps else (-m if x <= -eps else m * x / eps), s)
    if kind == "rate_limit":
        step = p["rate"] * p["dt"]
        return lambda x, s: ((s + min(max(x - s, -step), step)),) * 2
    if kind == "backlash":
        h = 0.5 * p["width"]
        return lambda x, s: ((min(max(s, x - h), x + h)),) * 2
    raise ValueError(f"unknown block {kind!r}")


def _chain(blocks: list[Any], dt: float):
    fns = []
    for kind, params in blocks:
        fns.append(_block(kind, {**params, "dt": dt}))
    state = [0.0] * len(fns)

    def apply(x: float) -> float:
        for i, f in enumerate(fns):
            x, state[i] = f(x, state[i])
        return x

    return apply


def _controller(c: dict[str, float], dt: float):
    """Tustin (no prewarping) of kp + ki/s + kd s/(tf s + 1), as a transposed direct form II."""
    kp, ki, kd, tf = c.get("kp", 0.0), c.get("ki", 0.0), c.get("kd", 0.0), c.get("tf", 0.0)
    if kd == 0.0 and ki == 0.0:
        return lambda e: kp * e
    if kd == 0.0:
        num, den = [kp, ki], [1.0, 0.0]
    else:
        num = np.polyadd(np.polyadd(np.polymul([kp], [tf, 1.0, 0.0]), np.polymul([ki], [tf, 1.0])), [kd, 0.0, 0.0])
        den = [tf, 1.0, 0.0]
    bd, ad, _ = scipy.signal.cont2discrete((num, den), dt, method="bilinear")
    b = np.ravel(bd) / ad[0]
    a = np.ravel(ad) / ad[0]
    n = a.size - 1
    b = np.concatenate([np.zeros(a.size - b.size), b])
    z = [0.0] * n

    def step(e: float) -> float:
        u = b[0] * e + z[0]
        for i in range(n - 1):
            z[i] = b[i + 1] * e - a[i + 1] * u + z[i + 1]
        z[n - 1] = b[n] * e - a[n] * u
        return float(u)

    return step


def _zoh(A: np.ndarray, B: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """exp(A h) and int_0^h exp(A s) ds B, from one matrix exponential (Van Loan)."""
    n = A.shape[0]
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = A, B
    E = scipy.linalg.expm(M * h)
    return E[:n, :n], E[:n, n]


@dataclass
class ReferenceRun:
    """Time series of a reference run."""

    t: np.ndarray
    y: np.ndarray
    u: np.ndarray


def simulate_reference(case: dict[str, Any], horizon: float, method: str = "expm") -> ReferenceRun:
    """Simulate ``case`` from rest at 0 over ``horizon`` seconds; ``method`` expm or ivp."""
    dt = float(case["dt"])
    A, B, C, D = scipy.signal.tf2ss(case["plant"]["num"], case["plant"]["den"])
    B, C = B[:, 0], C[0]
    if abs(float(np.ravel(D)[0])) > 0:
        raise ValueError("the reference takes strictly proper plants")
    delay = float(case.get("delay", 0.0))
    m = math.floor(delay / dt + 1e-9)
    f = delay / dt - m
    if f < 1e-9:
        f = 0.0
    n = round(horizon / dt) + 1
    t = np.arange(n) * dt
    step = float(case["step"])
    t_step = float(case.get("t_step", 0.0))
    ctrl = _controller(case["controller"], dt)
    act = _chain(case.get("actuator", []), dt)
    sen = _chain(case.get("sensor", []), dt)
    buf = [0.0] * (m + 2)  # a[k-m-1], a[k-m] at the end after each push
    x = np.zeros(A.shape[0])
    y = np.empty(n)
    u = np.empty(n)
    if method == "expm":
        if f == 0.0:
            Phi, Gam = _zoh(A, B, dt)
            P2, G1, G2 = Phi, np.zeros_like(Gam), Gam
        else:
            P1, G1_ = _zoh(A, B, f * dt)
            P2_, G2 = _zoh(A, B, (1 - f) * dt)
            P2, G1 = P2_ @ P1, P2_ @ G1_
    for k in range(n):
        yk = float(C @ x)
        y[k] = yk
        if not math.isfinite(yk) or abs(yk) > 1e12:
            y[k:] = np.inf
            u[k:] = np.nan
            break
        r = step if k * dt >= t_step - 1e-12 else 0.0
        a = act(ctrl(r - sen(yk)))
        u[k] = a
        buf.append(a)
        buf.pop(0)
        w_old, w_new = buf[-m - 2], buf[-m - 1]
        if method == "expm":
            x = P2 @ x + G1 * w_old + G2 * w_new
        else:
            x = _ivp_step(A, B, x, dt, f, w_old, w_new)
    return ReferenceRun(t, y, u)


def _ivp_step(A: np.ndarray, B: np.ndarray, x: np.ndarray, dt: float, f: float, w_old: float,
              w_new: float) -> np.ndarray:
    for h, w in ((f * dt, w_old), ((1 - f) * dt, w_new)):
        if h <= 0:
            continue
        sol = solve_ivp(lambda _t, z, w=w: A @ z + B * w, (0.0, h), x, method="DOP853", rtol=1e-11, atol=1e-13)
        x = sol.y[:, -1]
    return x


def _up_crossings(t: np.ndarray, r: np.ndarray, h: float) -> np.ndarray:
    """Interpolated instants where r rises through 0, after dipping below -h (hysteresis)."""
    out, armed = [], False
    for i in range(1, r.size):
        if r[i - 1] < -h:
            armed = True
        if armed and r[i - 1] < 0 <= r[i]:
            # count the crossing only if r then reaches +h before -h again
            j = i
            while j < r.size and -h <= r[j] <= h:
                j += 1
            if j < r.size and r[j] > h:
                out.append(t[i - 1] + (t[i] - t[i - 1]) * (-r[i - 1]) / (r[i] - r[i - 1]))
                armed = False
    return np.asarray(out)


def classify(t: np.ndarray, y: np.ndarray, step: float, t_step: float = 0.0, final: bool = False) -> dict[str, Any]:
    """The reference's own verdict on a long run: settled / limit_cycle / diverging / ambiguous.

    Windows of the last 30 % of the run: the half peak-to-peak over its first and last thirds
    (``h_before``, ``h_end``), up-crossings of its mid-range with 30 % hysteresis. A ratio
    ``h_end/h_before`` within 0.5 % of 1 with at least 3 cycles is a limit cycle; below 0.5 with
    the motion below 1e-4 of the step (or below 1e-7 of the step over the whole window) settled;
    farther than 10 steps from the reference and growing is diverging (on the longest run, or
    when the ratio is above 1.5); anything else is ambiguous. When the crossings give no verdict
    or cycles that do not repeat (lengths within 1 %, maxima and minima within 1 % of the
    amplitude), a record whose last 30 % repeats exactly (to 1e-6 of its amplitude) after a whole
    number of samples is a limit cycle (a sampled loop locked onto a pattern of k cycles); its
    period is the pattern's length over k, k the pattern's length over the mean crossing period.
    """
    scale = max(abs(step), 1e-12)
    if not np.all(np.isfinite(y)) or np.max(np.abs(y)) > 1e6 * scale:
        return {"verdict": "diverging"}
    n = y.size
    tail = slice(int(0.7 * n), n)
    tt, yy = t[tail], y[tail]
    half = 0.5 * (yy.max() - yy.min())
    end = slice(int(0.9 * n), n)
    before = slice(int(0.7 * n), int(0.8 * n))
    h_end = 0.5 * (y[end].max() - y[end].min())
    h_before = 0.5 * (y[before].max() - y[before].min())
    settled = {"verdict": "settled", **_step_times(t, y, t_step, float(np.mean(y[end])))}
    if half <= 1e-7 * scale or h_end <= 1e-9 * scale:
        return settled
    out = _by_crossings(t, y, yy, tt, half, h_end, h_before, settled, scale, step, final)
    if out["verdict"] == "limit_cycle" and out["repeats"]:
        return out
    lag = _exact_period(yy, half)  # crossings that do not repeat, or no verdict: does the record repeat exactly?
    if lag is not None:  # the sampled loop locked onto a pattern of a whole number of samples
        pattern = lag * float(t[1] - t[0])
        k = max(1, round(pattern / out["period"])) if out.get("period") else 1
        period = pattern / k if abs(pattern / k - out.get("period", pattern)) <= 0.01 * pattern / k else pattern
        k = round(pattern / period)
        return {"verdict": "limit_cycle", "amplitude": half, "period": period, "cycles": int(yy.size * k // lag),
                "period_range": out.get("period_range", [period, period]), "amplitude_range": [half, half],
                "repeats": True, "how": f"the last 30 % repeats exactly every {lag} samples ({k} cycles)"}
    return out


def _by_crossings(t: np.ndarray, y: np.ndarray, yy: np.ndarray, tt: np.ndarray, half: float, h_end: float,
                  h_before: float, settled: dict[str, Any], scale: float, step: float, final: bool) -> dict[str, Any]:
    """The verdict of :func:`classify` from the ratio of the ranges and the mean crossings."""
    n = y.size
    end = slice(int(0.9 * n), n)
    before = slice(int(0.7 * n), int(0.8 * n))
    r = yy - 0.5 * (yy.max() + yy.min())
    ups = _up_crossings(tt, r, 0.3 * half)
    ratio = h_end / h_before if h_before > 0 else np.inf
    dist_end = np.max(np.abs(y[end] - step))
    dist_before = np.max(np.abs(y[before] - step))
    if dist_end > 10 * scale and (ratio > 1.005 or dist_end > 1.05 * dist_before):
        if ratio > 1.5 or final:
            return {"verdict": "diverging"}
        return {"verdict": "ambiguous", "why": f"growing (x{ratio:.4g})"}
    if ratio > 1.005:
        return {"verdict": "ambiguous", "why": f"oscillation grows (x{ratio:.4g}) or is irregular"}
    if ratio < 0.5:
        if h_end < 1e-4 * scale:
            return settled
        return {"verdict": "ambiguous", "why": f"decaying (x{ratio:.3g}), still moving {h_end / scale:.2g} steps"}
    if ups.size < 4:
        return {"verdict": "ambiguous", "why": f"{max(ups.size - 1, 0)} cycles, ratio {ratio:.3g}"}
    last = (tt >= ups[-4]) & (tt < ups[-1])
    amp = 0.5 * float(yy[last].max() - yy[last].min())
    k = min(ups.size - 1, 6)
    period = float(np.mean(np.diff(ups[-k - 1:])))
    if ratio < 0.995:
        return {"verdict": "ambiguous", "why": f"decaying slowly (x{ratio:.4f})", "amplitude": amp, "period": period}
    return {"verdict": "limit_cycle", "amplitude": amp, "period": period, "cycles": int(ups.size - 1),
            **_cycle_ranges(tt, yy, ups)}


def _cycle_ranges(t: np.ndarray, y: np.ndarray, ups: np.ndarray) -> dict[str, Any]:
    """Each whole cycle of the window alone: the range of their lengths and of their half
    peak-to-peak; ``repeats`` when the lengths spread by at most 1 % of their mean and the
    cycles' maxima, and their minima, by at most 1 % of the mean half peak-to-peak."""
    lengths = np.diff(ups)
    hi, lo = [], []
    for a, b in itertools.pairwise(ups):
        seg = y[(t >= a) & (t < b)]
        hi.append(float(seg.max()) if seg.size else np.nan)
        lo.append(float(seg.min()) if seg.size else np.nan)
    top, bottom = np.asarray(hi), np.asarray(lo)
    h = 0.5 * (top - bottom)
    tol = 0.01 * np.mean(h)
    repeats = bool(np.ptp(lengths) <= 0.01 * np.mean(lengths) and np.ptp(top) <= tol and np.ptp(bottom) <= tol)
    return {"period_range": [float(lengths.min()), float(lengths.max())],
            "amplitude_range": [float(h.min()), float(h.max())], "repeats": repeats}


def _exact_period(y: np.ndarray, half: float) -> int | None:
    """The smallest whole number of samples L (at most a third of the record) with
    |y[k] - y[k - L]| <= 1e-6 half for every k: candidates from the sum of squared differences
    (by FFT), the first one checked sample by sample. None when the record never repeats."""
    r = y - np.mean(y)
    n = r.size
    if n < 16:
        return None
    f = np.fft.rfft(r, 2 * n)
    ac = np.fft.irfft(f * np.conj(f))[: n // 3 + 1]
    sq = np.concatenate([[0.0], np.cumsum(r**2)])
    lags = np.arange(1, ac.size)
    ssd = (sq[n] - sq[lags]) + sq[n - lags] - 2 * ac[1:]  # sum over k >= L of (r[k] - r[k-L])^2
    tol = (1e-6 * half) ** 2
    for lag in lags[ssd <= max(1e-9 * sq[n], tol * n)][:20]:
        if np.max(np.abs(r[lag:] - r[:-lag])) <= 1e-6 * half:
            return int(lag)
    return None


def _step_times(t: np.ndarray, y: np.ndarray, t_step: float, yf: float) -> dict[str, Any]:
    """Rise time 10-90 % (interpolated crossings) and 2 % settling time, from the step."""
    i0 = int(np.argmax(t >= t_step - 1e-12))
    y0 = float(y[i0])
    d = yf - y0
    if abs(d) < 1e-12:
        return {"rise_time": None, "settling_time": None, "final_value": yf}
    z = (y[i0:] - y0) / d
    tt = t[i0:] - t[i0]

    def first(level: float) -> float | None:
        idx = np.nonzero(z >= level)[0]
        if idx.size == 0:
            return None
        j = int(idx[0])
        if j == 0:
            return 0.0
        return float(tt[j - 1] + (tt[j] - tt[j - 1]) * (level - z[j - 1]) / (z[j] - z[j - 1]))

    t10, t90 = first(0.1), first(0.9)
    rise = None if t10 is None or t90 is None else t90 - t10
    out = np.nonzero(np.abs(z - 1.0) > 0.02)[0]
    settling = 0.0 if out.size == 0 else float(tt[min(int(out[-1]) + 1, tt.size - 1)])
    return {"rise_time": rise, "settling_time": settling, "final_value": yf}


def reference_run(case: dict[str, Any], method: str = "expm", horizon: float = 120.0,
                  longest: float = 960.0, max_samples: int = 500_000) -> dict[str, Any]:
    """Simulate ``case`` over ``horizon`` (or ``case["ref_horizon"]``) seconds and classify it; an
    ambiguous run is repeated over twice the horizon, up to ``longest`` seconds and ``max_samples``."""
    T = float(case.get("ref_horizon", horizon))
    longest = min(longest, max_samples * float(case["dt"]))
    while True:
        last = 2 * T > longest
        run = simulate_reference(case, T, method)
        out = classify(run.t, run.y, float(case["step"]), float(case.get("t_step", 0.0)), final=last)
        if out["verdict"] != "ambiguous" or last:
            return {**out, "horizon": T}
        T *= 2


if __name__ == "__main__":  # the example, as a smoke test
    example = {"plant": {"num": [1.0], "den": [1.0, 3.0, 2.0, 0.0]}, "controller": {"kp": 20.0},
               "actuator": [["saturation", {"min": -1.0, "max": 1.0}]], "dt": 0.001, "step": 0.1,
               "ref_horizon": 120.0}
    print(reference_run(example))
