"""An independent reference for ``synth.design``: dense parameter search with its own loop analysis.

Written from the definitions in docs/spec-format.md and the requirement docstrings only; it imports
nothing from synth. For a problem of ``benchmarks/design_problems.py``:

- the plant is ``num(jw)/den(jw) * exp(-j w delay)``, evaluated exactly (numpy ``polyval``);
- closed-loop stability by the argument principle on ``1 + L(s)`` along ``s = -eps + jw`` (a contour just
  left of the imaginary axis, so integrators count as open-loop poles inside it): the number of closed-loop
  poles with ``Re > -eps`` is ``P - (change of arg(1 + L))/(2 pi)`` over ``w`` from -inf to inf, with ``P``
  the open-loop poles with ``Re > -eps`` from ``numpy.roots`` of each factor's denominator without a delay, the
  closed-loop poles with ``Re > -eps`` are counted directly from ``numpy.roots`` of ``den cd + num cn`` (the
  contour passes within ``eps`` of a controller's poles on the imaginary axis and cannot follow ``1 + L`` there);
- every requirement from its definition on a log grid of ``DENSE_PER_DECADE`` points per decade (20x the
  80 per decade synth designs on), peaks refined by bounded Brent search, crossings by ``brentq`` (the margins'
  also between grid points, where an extremum near zero crosses it: ``_unseen_crossings``);
- the search: for one free parameter a grid of 400 values (linear and logarithmic) then bisection to the
  boundary and golden refinement around the best; for two, a grid of 32 linear and 16 logarithmic positions
  (six decades) per axis then Nelder-Mead from the best points; for more, 300 random points (a third
  small-biased, a third log-uniform over six decades) then Nelder-Mead from the best eight. Screening uses a coarse grid
  (``COARSE_PER_DECADE``); every point the reference calls feasible has passed the dense check.

A feasible point found is a proof of feasibility (the point itself); not finding one is only evidence.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import brentq, minimize, minimize_scalar

__all__ = ["COARSE_PER_DECADE", "DENSE_PER_DECADE", "Evaluation", "LoopModel", "ReferenceResult", "check_point",
           "controller_polys", "reference"]

DENSE_PER_DECADE = 1600
COARSE_PER_DECADE = 160
LN10_20 = np.log(10) / 20
DB3 = 10 ** (-3 / 20)


def _distinct(w: np.ndarray) -> np.ndarray:
    """Sorted ``w`` without points within 1e-9 (relative) of the one before: brackets between such neighbours
    are empty in floating point (a sign change seen on the grid that ``brentq`` cannot find again)."""
    if w.size < 2:
        return w
    keep = np.concatenate([[True], np.diff(w) > 1e-9 * np.abs(w[1:])])
    return w[keep]


def _log_crossing(f: Any, w_a: float, w_b: float, xtol: float) -> float:
    """The frequency in ``[w_a, w_b]`` where ``f`` changes sign, found by ``brentq`` in ``log w``. The grid saw a
    sign change between the two points; when ``f`` at ``exp(log w)`` (a rounded copy of the grid point) no longer
    shows it, the crossing is at an end within rounding, and the end where ``|f|`` is smaller is returned."""
    a, b = np.log(w_a), np.log(w_b)
    fa, fb = f(np.exp(a)), f(np.exp(b))
    if fa == 0 or fb == 0 or np.sign(fa) == np.sign(fb):
        return float(w_a if abs(fa) <= abs(fb) else w_b)
    return float(np.exp(brentq(lambda lx: f(np.exp(lx)), a, b, xtol=xtol)))


def controller_polys(ctype: str, order: list[int] | None, p: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """Controller numerator and denominator from the spec-format table."""
    t = ctype.lower()
    if t == "p":
        return np.array([p["kp"]]), np.array([1.0])
    if t == "pi":
        return np.array([p["kp"], p["ki"]]), np.array([1.0, 0.0])
    if t == "pid":
        kp, ki, kd, tf = p["kp"], p["ki"], p["kd"], p["tf"]
        # kp + ki/s + kd s/(tf s + 1) = (kp s (tf s + 1) + ki (tf s + 1) + kd s^2) / (s (tf s + 1))
        return np.array([kp * tf + kd, kp + ki * tf, ki]), np.array([tf, 1.0, 0.0])
    if t == "leadlag":
        return p["k"] * np.array([1.0, p["z"]]), np.array([1.0, p["p"]])
    m, n = order  # type: ignore[misc]
    return (np.array([p[f"b{i}"] for i in range(m, -1, -1)]),
            np.array([1.0] + [p[f"a{i}"] for i in range(n - 1, -1, -1)]))


def _at_infinity(num: np.ndarray, den: np.ndarray) -> float:
    """``lim num(s)/den(s)`` for ``s -> inf`` of a proper ratio (0 when strictly proper)."""
    num, den = _strip(np.asarray(num, float)), _strip(np.asarray(den, float))
    return float(num[0] / den[0]) if num.size == den.size and np.any(num) else 0.0


def _strip(c: np.ndarray) -> np.ndarray:
    c = np.trim_zeros(np.asarray(c, float), "f")
    return c if c.size else np.array([0.0])


@dataclass
class Evaluation:
    """One candidate checked: stability, each requirement's value and slack, the objective."""

    params: dict[str, float]
    stable: bool
    unstable_poles: int
    slacks: dict[str, float] = field(default_factory=dict)
    values: dict[str, float] = field(default_factory=dict)
    objective: float | None = None
    dense: bool = False

    @property
    def min_slack(self) -> float:
        s = min(self.slacks.values()) if self.slacks else np.inf
        return float(s) if self.stable else -1.0 - self.unstable_poles

    def feasible(self, tol: float = 0.0) -> bool:
        return self.stable and all(v >= -tol for v in self.slacks.values())

    def to_dict(self) -> dict[str, Any]:
        return {"params": self.params, "stable": self.stable, "unstable_poles": self.unstable_poles,
                "slacks": self.slacks, "values": self.values, "objective": self.objective}


class LoopModel:
    """A problem's plant, controller structure, requirements and objective, evaluated on its own grids."""

    def __init__(self, num: list[float], den: list[float], delay: float, spec: dict[str, Any], eps_scale: float = 1e-6):
        self.num, self.den, self.delay = _strip(np.array(num)), _strip(np.array(den)), float(delay)
        self.spec = spec
        c = spec["controller"]
        self.ctype, self.order = c["type"], c.get("order")
        self.bounds = {k: (float(v[0]), float(v[1])) for k, v in c["bounds"].items()}
        self.free = [k for k, (lo, hi) in self.bounds.items() if hi > lo]
        self.fixed = {k: lo for k, (lo, hi) in self.bounds.items() if hi <= lo}
        self.requirements = spec["requirements"]
        obj = spec.get("objective")
        self.objective = None if obj is None else next(iter(obj.items()))  # (sense, name)
        feats = [abs(r) for r in np.concatenate([np.roots(self.num), np.roots(self.den)]) if abs(r) > 1e-12]
        for r in self.requirements:
            for key in ("min", "max"):
                if r.get(key):
                    feats.append(r[key])
            for b in r.get("band", []) or []:
                if b > 0:
                    feats.append(b)
            if r.get("delay_margin"):
                feats.append(1 / r["delay_margin"])
        if self.delay > 0:
            feats.append(1 / self.delay)
        wide = np.logspace(-6, 6, 2401)
        mag = np.abs(self.G(wide))
        for name in ("kp", "k"):  # where the loop crosses over at the largest proportional gain
            if name in self.bounds and self.bounds[name][1] > 0:
                x = np.log(mag * self.bounds[name][1])
                feats += [float(wide[i]) for i in np.nonzero(np.sign(x[:-1]) != np.sign(x[1:]))[0]]
        feats = feats or [1.0]
        self.w_lo, self.w_hi = min(feats) * 1e-3, max(feats) * 1e3
        self.eps = min(feats) * eps_scale
        self.grids = {d: self._grid(d) for d in (COARSE_PER_DECADE, DENSE_PER_DECADE)}

    def _grid(self, per_decade: int) -> dict[str, np.ndarray]:
        n = int(np.ceil(np.log10(self.w_hi / self.w_lo) * per_decade)) + 1
        w = np.logspace(np.log10(self.w_lo), np.log10(self.w_hi), n)
        ns = int(np.ceil(np.log10(self.w_hi / (self.eps * 1e-1)) * per_decade / 4)) + 1
        ws = np.concatenate([[0.0], np.logspace(np.log10(self.eps * 1e-1), np.log10(self.w_hi), ns)])
        s = -self.eps + 1j * ws
        return {"w": w, "G": self.G(w), "ws": ws, "Gs": np.polyval(self.num, s) / np.polyval(self.den, s)
                * np.exp(-self.delay * s)}

    def _near_axis(self, g: dict[str, np.ndarray], cn: np.ndarray, cd: np.ndarray) -> dict[str, np.ndarray]:
        """``g`` with points added around every open-loop pole and zero (plant and controller) within 2 % of its
        modulus of the contour: ``Im r + k d`` for ``|k|`` from 0.01 to 200 (geometric), ``d`` its distance from
        the contour. Near such a root ``1 + L`` can turn through a whole circle, and ``|S|`` or ``|T|`` peak,
        between two points of a log grid (seed 8 #88: controller poles at ``0.0018 +- 26.41j``, closed-loop
        poles at ``-0.0071 +- 26.405j``, a peak 0.01 rad/s wide)."""
        polys = [q for q in (self.den, self.num, cd, cn) if np.asarray(q).size > 1]
        roots = np.concatenate([np.roots(q) for q in polys]) if polys else np.zeros(0, complex)
        roots = roots[np.isfinite(roots) & (roots.imag > 0)]
        near = roots[np.abs(roots.real + self.eps) < 0.02 * np.abs(roots)]
        if near.size == 0:
            return g
        dist = np.maximum(np.abs(near.real + self.eps), 1e-7 * np.abs(near))  # a root on the axis: 1e-7 of it
        k = np.geomspace(0.01, 200.0, 60)
        k = np.concatenate([-k[::-1], [0.0], k])
        extra = (near.imag[:, None] + dist[:, None] * k[None, :]).ravel()
        extra = extra[extra > 0]
        ws = _distinct(np.union1d(g["ws"], extra))
        w = _distinct(np.union1d(g["w"], extra[(extra >= self.w_lo) & (extra <= self.w_hi)]))
        s = -self.eps + 1j * ws
        return {"w": w, "G": self.G(w), "ws": ws,
                "Gs": np.polyval(self.num, s) / np.polyval(self.den, s) * np.exp(-self.delay * s)}

    def F_shifted(self, ws: np.ndarray, cn: np.ndarray, cd: np.ndarray) -> np.ndarray:
        """``1 + L(s)`` on ``s = -eps + j ws``."""
        s = -self.eps + 1j * ws
        return 1.0 + np.polyval(self.num, s) / np.polyval(self.den, s) * np.exp(-self.delay * s) * (
            np.polyval(cn, s) / np.polyval(cd, s))

    def _arg_change(self, ws: np.ndarray, F: np.ndarray, cn: np.ndarray, cd: np.ndarray, depth: int = 5) -> float:
        """Continuous change of ``arg F`` along ``ws``; steps over 0.3 rad are subdivided (32 points, 5 levels)."""
        d = np.angle(F[1:] / F[:-1])
        if depth > 0:
            for i in np.nonzero(np.abs(d) > 0.3)[0]:
                wf = np.linspace(ws[i], ws[i + 1], 34)
                Ff = self.F_shifted(wf, cn, cd)
                Ff[0], Ff[-1] = F[i], F[i + 1]
                d[i] = self._arg_change(wf, Ff, cn, cd, depth - 1)
        return float(np.sum(d))

    def G(self, w: np.ndarray) -> np.ndarray:
        s = 1j * np.asarray(w, float)
        return np.polyval(self.num, s) / np.polyval(self.den, s) * np.exp(-self.delay * s)

    def params(self, x: np.ndarray) -> dict[str, float]:
        p = dict(self.fixed)
        for k, v in zip(self.free, x):
            lo, hi = self.bounds[k]
            p[k] = float(np.clip(v, lo, hi))
        return p

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, p: dict[str, float], dense: bool = True) -> Evaluation:
        """Check the controller with parameters ``p`` (dense grid and refined peaks when ``dense``)."""
        cn, cd = controller_polys(self.ctype, self.order, p)
        cn, cd = _strip(cn), _strip(cd)
        while cn.size > 1 and cd.size > 1 and cn[-1] == 0 and cd[-1] == 0:  # ki = 0: s/s is no integrator
            cn, cd = cn[:-1], cd[:-1]
        g = self.grids[DENSE_PER_DECADE if dense else COARSE_PER_DECADE]
        if cd[0] == 0 or not np.all(np.isfinite(cn)):
            return Evaluation(p, False, 99, dense=dense)
        g = self._near_axis(g, cn, cd)
        if self.delay == 0.0:  # a polynomial: its roots, counted directly
            unstable = self._polynomial_count(cn, cd)
            if unstable:
                return Evaluation(p, False, unstable, dense=dense)
            return self._requirements(p, cn, cd, g, dense)
        # stability: argument principle on the shifted contour
        ss = -self.eps + 1j * g["ws"]
        Ls = g["Gs"] * np.polyval(cn, ss) / np.polyval(cd, ss)
        F = 1.0 + Ls
        if not np.all(np.isfinite(F)) or np.any(F == 0):
            return Evaluation(p, False, 98, dense=dense)
        d_arg = 2.0 * self._arg_change(g["ws"], F, cn, cd)
        P = int(np.sum(np.roots(self.den).real > -self.eps) + np.sum(np.roots(cd).real > -self.eps))
        c_inf = _at_infinity(self.num, self.den) * _at_infinity(cn, cd)
        if c_inf == 0.0:  # strictly proper: 1 + L -> 1 on the closing arc; the grid must reach where |L| is small
            Z = round(float(P - d_arg / (2 * np.pi)))
            if Z != 0 or abs(Ls[-1]) > 0.1:
                return Evaluation(p, False, max(Z, 1), dense=dense)
        else:  # biproper: L -> c (times the delay) beyond the corners
            if 1.0 + c_inf == 0.0 or (self.delay > 0 and abs(c_inf) >= 1.0):
                # an improper closed loop, or a neutral one (infinitely many roots with Re s -> ln|c|/delay >= 0)
                return Evaluation(p, False, 97, dense=dense)
            # the closing arc (Re s > 0, far out): e^{-s delay} shrinks, so 1 + L moves from F(jR) to its conjugate
            # inside the disk |F - 1| <= |c| (delay) or stays near 1 + c (no delay): the short way round
            closing = float(np.angle(np.conj(F[-1]) / F[-1]))
            Z = round(float(P - (d_arg + closing) / (2 * np.pi)))
            rational_end = Ls[-1] * np.exp(self.delay * ss[-1])
            if Z != 0 or abs(rational_end - c_inf) > 0.1 * abs(c_inf):  # the grid's end must lie beyond the corners
                return Evaluation(p, False, max(Z, 1), dense=dense)
        return self._requirements(p, cn, cd, g, dense)

    def _polynomial_count(self, cn: np.ndarray, cd: np.ndarray) -> int:
        """Closed-loop poles with ``Re > -eps`` of a loop without delay: roots of ``den cd + num cn`` (``numpy.roots``).
        The contour count cannot follow ``1 + L`` past open-loop poles on the imaginary axis (a controller
        ``b0/(s^2 + a0)``): its path passes within ``eps`` of them. An improper closed loop counts as one pole."""
        char = np.polyadd(np.polymul(self.den, cd), np.polymul(self.num, cn))
        char = np.trim_zeros(char, "f")
        if char.size == 0 or not np.all(np.isfinite(char)):
            return 99
        if char.size < max(self.den.size + cd.size, self.num.size + cn.size) - 1:  # the leading terms cancel
            return 97
        return int(np.sum(np.roots(char).real > -self.eps))

    def _requirements(self, p: dict[str, float], cn: np.ndarray, cd: np.ndarray, g: dict[str, np.ndarray],
                      dense: bool) -> Evaluation:
        """Every requirement of a stable loop, on the grid ``g``."""
        ev = Evaluation(p, True, 0, dense=dense)
        w = g["w"]

        def parts(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            """``A = den cd``, ``B = num cn e^{-s delay}`` and ``cn den`` at ``s = jx``: S = A/(A+B), T = B/(A+B),
            KS = cn den/(A+B), finite where an open-loop pole lies on the axis (a controller's s^2 + a0: its
            frequency is on the grid near the axis, where C = inf made 1/(1 + L) NaN; seed 31 #26)."""
            s = 1j * np.asarray(x, float)
            den = np.polyval(self.den, s)
            return den * np.polyval(cd, s), np.polyval(self.num, s) * np.polyval(cn, s) * np.exp(-self.delay * s), \
                np.polyval(cn, s) * den

        A, B, X = parts(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            ev.values["min|1+L|"] = float(np.min(np.abs((A + B)[A != 0] / A[A != 0])))

        def curve(name: str, x: np.ndarray) -> np.ndarray:
            a, b, xx = parts(x) if x is not w else (A, B, X)
            return np.abs({"S": a, "T": b, "KS": xx}[name] / (a + b))

        with np.errstate(divide="ignore", invalid="ignore"):
            L = g["G"] * np.polyval(cn, 1j * w) / np.polyval(cd, 1j * w)  # the margins read L itself

        def Lf(x: float) -> complex:
            return complex(self.G(np.array([x]))[0] * np.polyval(cn, 1j * x) / np.polyval(cd, 1j * x))

        funcs = {name: (lambda x, name=name: float(curve(name, np.array([x]))[0])) for name in ("S", "T", "KS")}
        curves = {name: curve(name, w) for name in ("S", "T", "KS")}

        def peak(name: str, band: tuple[float, float] | None = None) -> float:
            y, ww = curves[name], w
            if band is not None:
                sel = (w >= band[0]) & (w <= band[1])
                ww = np.concatenate([[max(band[0], self.w_lo)], w[sel], [band[1]]])
                y = np.array([funcs[name](ww[0]), *y[sel], funcs[name](ww[-1])])
            i = int(np.argmax(y))
            best = float(y[i])
            if dense and 0 < i < len(ww) - 1:
                r = minimize_scalar(lambda lx: -funcs[name](np.exp(lx)), bounds=(np.log(ww[i - 1]), np.log(ww[i + 1])),
                                    method="bounded", options={"xatol": 1e-10})
                best = max(best, float(-r.fun))
            return best

        int_c = cd[-1] == 0
        int_g = self.den[-1] == 0

        def bandwidth() -> float:
            if int_c or int_g:
                t0 = 1.0
            else:
                l0 = self.num[-1] / self.den[-1] * cn[-1] / cd[-1]
                t0 = abs(l0 / (1 + l0))
            if not t0 > 0:
                return 0.0
            thr = t0 * DB3
            below = np.nonzero(curves["T"] < thr)[0]
            if below.size == 0:
                return float(w[-1])
            i = int(below[0])
            if i == 0:
                return float(w[0])
            return _log_crossing(lambda x: funcs["T"](x) - thr, w[i - 1], w[i], 1e-12)

        for k, r in enumerate(self.requirements):
            t = r["type"]
            key = f"{k}:{t}"
            if t == "bandwidth":
                bw = bandwidth()
                ev.values[key] = bw
                sl = []
                with np.errstate(divide="ignore"):  # bw = 0 (|T| never reaches the level): log 0 = -inf
                    if r.get("min") is not None:
                        sl.append(np.log(bw / r["min"]))
                    if r.get("max") is not None:
                        sl.append(np.log(r["max"] / bw) if bw > 0 else np.inf)
                ev.slacks[key] = float(min(sl))
            elif t in ("sensitivity", "peak_sensitivity", "peak_complementary", "peak_control_sensitivity"):
                name = {"sensitivity": "S", "peak_sensitivity": "S", "peak_complementary": "T",
                        "peak_control_sensitivity": "KS"}[t]
                band = r.get("band")
                val = 20 * np.log10(max(peak(name, tuple(band) if band else None), 1e-300))
                ev.values[key] = float(val)
                ev.slacks[key] = float((r["max_db"] - val) * LN10_20)
            elif t == "sensitivity_static":
                gain = r.get("plant_gain")
                if gain is None:
                    gain = np.inf if int_g else self.num[-1] / self.den[-1]
                c0 = np.inf if int_c else cn[-1] / cd[-1]
                prod = c0 * gain if not (c0 == 0 or gain == 0) else 0.0
                val = -np.inf if not np.isfinite(prod) else 20 * np.log10(max(abs(1 / (1 + prod)), 1e-300))
                ev.values[key] = float(val)
                ev.slacks[key] = float((r["max_db"] - val) * LN10_20) if np.isfinite(val) else 10.0
            elif t == "slew_rate":
                lo, hi = r["band"]
                sel = (w >= lo) & (w <= hi)
                ww = np.concatenate([[lo], w[sel], [hi]])
                dem = r["max_error"] * np.abs(np.polyval(cn, 1j * ww) / np.polyval(cd, 1j * ww)) * ww
                val = float(np.max(dem))
                ev.values[key] = val
                ev.slacks[key] = float(np.log(r["rate_limit"] / val)) if val > 0 else 10.0
            elif t == "margins":
                gm, pm, dm = self.margins(w, L, Lf)
                ev.values[key + ":gm"], ev.values[key + ":pm"], ev.values[key + ":dm"] = gm, pm, dm
                sl = []
                if r.get("gain_margin_db") is not None:
                    sl.append((gm - r["gain_margin_db"]) * LN10_20)
                if r.get("phase_margin_deg") is not None:
                    sl.append(np.radians(pm - r["phase_margin_deg"]))
                if r.get("delay_margin") is not None:
                    sl.append(np.log(dm / r["delay_margin"]) if dm > 0 else -10.0)
                ev.slacks[key] = float(min(sl))
            else:
                raise ValueError(f"reference: no definition for requirement type {t!r}")
        if self.objective is not None:
            _, name = self.objective
            if name == "bandwidth":
                ev.objective = bandwidth()
            elif name == "peak_sensitivity":
                ev.objective = float(20 * np.log10(peak("S")))
            else:
                raise ValueError(f"reference: no objective {name!r}")
        return ev

    def margins(self, w: np.ndarray, L: np.ndarray, Lf: Any) -> tuple[float, float, float]:
        """Gain margin (dB: the nearer of the upward and the downward one, as docs/spec-format.md defines it for
        a conditionally stable loop; an upward one beyond 80 dB counts as none), smallest phase margin (deg),
        delay margin (s)."""
        mag = np.log(np.abs(L))
        ks = []
        with np.errstate(all="ignore"):
            l0 = complex(Lf(0.0))  # L(0) is real: a phase crossing at w = 0 when it is negative (unstable plant)
        if np.isfinite(l0) and l0.real < 0:
            ks.append(1 / abs(l0))
        im = L.imag
        brackets = [(w[i], w[i + 1]) for i in np.nonzero(np.sign(im[:-1]) * np.sign(im[1:]) < 0)[0]
                    if L[i].real < 0 or L[i + 1].real < 0]
        brackets += _unseen_crossings(lambda x: Lf(x).imag / abs(Lf(x)), w, im / np.abs(L))
        for a, b in brackets:
            x = _log_crossing(lambda x: Lf(x).imag, a, b, 1e-13)
            lv = Lf(x)
            if lv.real < 0:
                ks.append(1 / abs(lv))
        up = [k for k in ks if k > 1]
        down = [k for k in ks if k < 1]  # a gain reduction that puts a crossing on -1 destabilizes the loop too
        gm = min(20 * np.log10(min(up)) if up and min(up) < 1e4 else np.inf,
                 -20 * np.log10(max(down)) if down else np.inf)
        pm, dm = np.inf, np.inf
        brackets = [(w[i], w[i + 1]) for i in np.nonzero(np.sign(mag[:-1]) * np.sign(mag[1:]) < 0)[0]]
        for a, b in brackets + _unseen_crossings(lambda x: np.log(abs(Lf(x))), w, mag):
            x = _log_crossing(lambda x: np.log(abs(Lf(x))), a, b, 1e-13)
            ph = np.degrees(np.angle(Lf(x)))
            this = (ph + 360.0) % 360.0 - 180.0
            pm = min(pm, this)
            lag = (ph + 180.0) % 360.0  # extra phase lag that puts this crossing on -1: the PM in [0, 360)
            dm = min(dm, np.radians(lag) / x)
        return float(gm), float(pm), float(dm)


def _unseen_crossings(f: Any, w: np.ndarray, v: np.ndarray, near: float = 0.05) -> list[tuple[float, float]]:
    """Brackets of sign changes of ``f`` that the grid ``w`` (where ``f`` is ``v``) does not show: around an
    interior grid extremum within ``near`` of zero whose neighbours lie on its side, the extremum is refined
    (bounded Brent search in ``log w``); when it lies on the other side of zero, ``f`` crosses zero twice between
    the neighbours, and the two brackets are returned. A lightly damped resonance can lift ``|L|`` through 1 for
    less than one grid spacing (two gain crossovers 0.05 % apart against the grid's 0.14 %: seed 28 #20 of the
    design benchmark, whose phase margin at the first crossover is 81 deg and at the hidden pair 27 deg).

    Examples
    --------
    >>> w = np.array([1.0, 2.0, 3.0])
    >>> f = lambda x: 1e-4 - (x - 2.1) ** 2  # above zero only on (2.09, 2.11): the grid sees -0.0099 at 2
    >>> [tuple(round(x, 4) for x in bracket) for bracket in _unseen_crossings(f, w, f(w))]
    [(1.0, 2.1), (2.1, 3.0)]
    """
    out: list[tuple[float, float]] = []
    turns = (v[1:-1] - v[:-2]) * (v[2:] - v[1:-1]) <= 0
    for k in np.nonzero(turns & (np.abs(v[1:-1]) < near))[0] + 1:
        side = np.sign(v[k])
        if side == 0 or np.sign(v[k - 1]) != side or np.sign(v[k + 1]) != side:
            continue  # a crossing the grid shows
        r = minimize_scalar(lambda lx, side=side: side * f(np.exp(lx)), bounds=(np.log(w[k - 1]), np.log(w[k + 1])),
                            method="bounded", options={"xatol": 1e-12})
        if r.fun < 0:
            x = float(np.exp(r.x))
            out += [(float(w[k - 1]), x), (x, float(w[k + 1]))]
    return out


@dataclass
class ReferenceResult:
    """Best point the reference found, and its effort."""

    feasible: bool
    best: Evaluation | None
    evaluations: int
    seconds: float
    method: str

    def to_dict(self) -> dict[str, Any]:
        return {"feasible": self.feasible, "best": None if self.best is None else self.best.to_dict(),
                "evaluations": self.evaluations, "seconds": self.seconds, "method": self.method}


class _Search:
    def __init__(self, model: LoopModel, tol: float):
        self.m, self.tol, self.n = model, tol, 0
        self.best: Evaluation | None = None

    def score(self, ev: Evaluation) -> float:
        """Larger is better: objective in log units (or min slack without objective)."""
        if self.m.objective is None:
            return ev.min_slack
        _, name = self.m.objective
        v = ev.objective
        if name == "bandwidth":
            return float(np.log(max(v, 1e-300)))
        return float(-v * LN10_20)  # peak |S| dB, minimized

    def ev(self, p: dict[str, float], dense: bool) -> Evaluation:
        self.n += 1
        e = self.m.evaluate(p, dense)
        if dense and e.feasible(-self.tol) and (self.best is None or self.score(e) > self.score(self.best)):
            self.best = e
        return e

    def penalty(self, x: np.ndarray) -> float:
        e = self.ev(self.m.params(x), dense=False)
        if not e.feasible(-self.tol):
            return 1e3 - e.min_slack if e.stable else 1e4 + e.unstable_poles
        return -self.score(e)


def reference(num: list[float], den: list[float], delay: float, spec: dict[str, Any], *,
              tol: float = 1e-4, budget: float = 1.0, seed: int = 0) -> ReferenceResult:
    """Search the controller box of ``spec`` for the best point that passes the dense check.

    ``tol`` is the slack (nepers/radians) a point must have to count as feasible; ``budget`` scales
    the number of grid points and starts.

    Examples
    --------
    >>> spec = {"controller": {"type": "P", "bounds": {"kp": [0, 10]}},
    ...         "requirements": [{"type": "bandwidth", "min": 2}], "objective": {"maximize": "bandwidth"}}
    >>> r = reference([1.0], [1.0, 1.0], 0.0, spec)   # 1/(s+1), P: bandwidth = kp + 1
    >>> r.feasible, round(r.best.params["kp"], 3), round(r.best.objective, 3)
    (True, 10.0, 11.0)
    """
    with np.errstate(all="ignore"):
        return _reference(num, den, delay, spec, tol, budget, seed)


def _reference(num: list[float], den: list[float], delay: float, spec: dict[str, Any], tol: float,
               budget: float, seed: int) -> ReferenceResult:
    t0 = time.perf_counter()
    m = LoopModel(num, den, delay, spec)
    srch = _Search(m, tol)
    rng = np.random.default_rng(seed)
    lo = np.array([m.bounds[k][0] for k in m.free])
    hi = np.array([m.bounds[k][1] for k in m.free])
    nfree = len(m.free)
    if nfree == 0:
        srch.ev(m.params(np.array([])), dense=True)
        method = "fixed"
    elif nfree == 1:
        n = max(50, int(200 * budget))
        pos = lo[0] + (hi[0] - lo[0]) * np.concatenate([np.linspace(0, 1, n), np.logspace(-5, 0, n)])
        xs = np.unique(pos)
        evs = [srch.ev(m.params(np.array([x])), dense=False) for x in xs]
        # candidates: points within 0.05 of feasible on the coarse grid (asking for a slack of +0.05 instead, as
        # until session 75, stopped the refinement short of a boundary optimum: P on 2/(s+1), bandwidth <= 6, 2.362
        # for 2.507)
        scores = np.array([srch.score(e) if e.feasible(0.05) else -np.inf for e in evs])
        ok = np.nonzero(np.isfinite(scores))[0]
        done = 0
        for i in ok[np.argsort(-scores[ok], kind="stable")][:12]:
            e = srch.ev(evs[i].params, dense=True)
            if not e.feasible(-tol):
                continue
            done += 1
            if m.objective is None or done > 2:
                break  # any point proves feasibility; with an objective refine around the best two
            # towards each neighbour: bisection to the feasibility boundary, or golden search inside
            for j in (i - 1, i + 1):
                if not 0 <= j < len(xs):
                    continue
                a, b = xs[i], xs[j]
                eb = srch.ev(m.params(np.array([b])), dense=True)
                if eb.feasible(-tol):
                    r = minimize_scalar(lambda x: _dense_pen(srch, x),
                                        bounds=(min(a, b), max(a, b)), method="bounded",
                                        options={"xatol": 1e-9 * max(1.0, abs(a))})
                    _dense_pen(srch, r.x)
                else:
                    for _ in range(28):
                        c = 0.5 * (a + b)
                        if srch.ev(m.params(np.array([c])), dense=True).feasible(-tol):
                            a = c
                        else:
                            b = c
        method = f"grid {len(xs)} + boundary bisection"
    else:
        if nfree == 2:
            k = max(12, int(32 * np.sqrt(budget)))
            # linear and logarithmic positions on each axis: a feasible set of tiny gains (a high-gain plant, a
            # vanishing integral gain) lies below the first linear step
            axis = np.unique(np.concatenate([np.linspace(0, 1, k), np.logspace(-6, 0, k // 2)]))
            g1, g2 = np.meshgrid(axis, axis)
            U = np.column_stack([g1.ravel(), g2.ravel()])
            method = f"grid {axis.size}x{axis.size} (linear and log) + Nelder-Mead"
        else:
            U = rng.random((max(60, int(300 * budget)), nfree))
            third = len(U) // 3
            U[:third] = U[:third] ** 3  # many points near the lower bound (small gains)
            U[third: 2 * third] = 10.0 ** (-6.0 * U[third: 2 * third])  # log-uniform over six decades
            method = f"{len(U)} random starts + Nelder-Mead"
        X = lo + (hi - lo) * U
        pen = np.array([srch.penalty(x) for x in X])
        starts = X[np.argsort(pen)[: max(3, int(8 * budget))]]
        if m.objective is None:  # feasibility only: the best screened point may already prove it
            for x0 in starts[:3]:
                if srch.ev(m.params(x0), dense=True).feasible(-tol):
                    starts = starts[:0]
                    break
        scale = hi - lo
        for x0 in starts:
            r = minimize(lambda u: srch.penalty(lo + scale * np.clip(u, 0, 1)), (x0 - lo) / scale,
                         method="Nelder-Mead", options={"maxfev": int(300 * budget) + 50, "xatol": 1e-7,
                                                        "fatol": 1e-9})
            xe = lo + scale * np.clip(r.x, 0, 1)
            e = srch.ev(m.params(xe), dense=True)
            if not e.feasible(-tol):
                # back off towards the start until the dense check passes
                a, b = x0, xe
                if srch.ev(m.params(a), dense=True).feasible(-tol):
                    for _ in range(30):
                        c = 0.5 * (a + b)
                        if srch.ev(m.params(c), dense=True).feasible(-tol):
                            a = c
                        else:
                            b = c
    best = srch.best
    return ReferenceResult(best is not None, best, srch.n, time.perf_counter() - t0, method)


def _dense_pen(srch: _Search, x: float) -> float:
    e = srch.ev(srch.m.params(np.array([x])), dense=True)
    return -srch.score(e) if e.feasible(-srch.tol) else 1e3 - e.min_slack


def check_point(num: list[float], den: list[float], delay: float, spec: dict[str, Any],
                params: dict[str, float], eps_scale: float = 1e-6) -> Evaluation:
    """Dense check of one controller (e.g. synth's design).

    Closed-loop poles with ``Re > -eps`` count as unstable, ``eps = eps_scale`` times the smallest plant or
    requirement frequency.

    Examples
    --------
    >>> spec = {"controller": {"type": "P", "bounds": {"kp": [0, 10]}},
    ...         "requirements": [{"type": "margins", "phase_margin_deg": 45}]}
    >>> e = check_point([10.0], [1.0, 4.0, -5.0], 0.0, spec, {"kp": 0.4})   # 10/((s-1)(s+5)): unstable
    >>> e.stable, e.unstable_poles
    (False, 1)
    """
    with np.errstate(all="ignore"):
        return LoopModel(num, den, delay, spec, eps_scale).evaluate(dict(params), dense=True)
