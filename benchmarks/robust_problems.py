"""Seeded random multi-plant (robust) design problems for an independent check of ``synth.design``.

Each problem is a spec dict for :func:`synth.parse_spec` whose plant has ``variants``, plus every plant as plain
polynomials and a delay, so that the reference (``benchmarks/robust_reference.py``) evaluates it without synth.

What is generated:

- a nominal plant of order 1-4 built from factors: open-loop unstable real poles ``(s - p)``, integrators, lightly
  damped pairs (damping 0.02 ... 0.7), stable real poles, left-half-plane zeros ``(s + z)`` and right-half-plane
  zeros ``(1 - s/z)``; always strictly proper; a gain chosen so that ``|G(j wt)| = 1`` at a target crossover
  ``wt``; a delay (60 % of the plants) up to half the crossover period ``pi/wt``, written either as the ``delay``
  key or (a third of them) as ``exp(-tau*s)`` inside ``tf``;
- 1-4 ``variants`` of every kind docs/spec-format.md allows: ``gain`` (0.3x ... 3x), ``tf`` replacements (a pole
  or zero moved by a factor 0.4-2.5, a pair's damping changed, an extra stable pole or a lightly damped mode
  added with the DC gain kept), ``delay`` replacements (0 ... 2.5x the nominal one, or a new delay), and a few
  combinations (``gain`` with ``delay``; ``gain`` with ``tf``, which synth reads as the gain scaling the replaced
  ``tf``); in 15 % of the problems one variant is made much harder (gain 5-10x or 0.1x, a slow right-half-plane
  zero, a long delay, an unstable pole);
- a controller P, PI, PID (filter fixed), leadlag or rational up to order (2, 3), bounds scaled to the plant;
- 1-3 requirements drawn from the types with a frequency-domain definition (``sensitivity``,
  ``sensitivity_static``, ``bandwidth``, ``peak_sensitivity``, ``peak_complementary``,
  ``peak_control_sensitivity``, ``margins``, ``delay_margin``, ``disk_margin``, ``slew_rate``); bounds drawn so
  that some problems are feasible and some are not;
- an objective: maximize ``bandwidth``, ``crossover``, ``integral_gain`` (PI/PID) or ``low_frequency_gain``
  (P, leadlag), minimize ``peak_sensitivity``, ``peak_complementary`` or ``control_effort`` (with a bandwidth floor
  added, else a vanishing gain is best), or none.

Each plant is also stored as ``(label, num, den, delay)``, the variant applied as the spec reads it: a variant's
``tf`` replaces the nominal ``tf`` (and an ``exp`` written in it), its ``delay`` replaces the nominal ``delay``
key, a key it does not give keeps the nominal part, and ``gain`` multiplies the result.

Run ``python benchmarks/robust_problems.py --n 3`` to print a few.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["CONTROLLERS", "PlantData", "RobustProblem", "generate", "problem"]

CONTROLLERS = ("P", "PI", "PID", "leadlag", "rational")
REQUIREMENTS = ("bandwidth", "sensitivity", "sensitivity_static", "peak_sensitivity", "peak_complementary",
                "peak_control_sensitivity", "margins", "delay_margin", "disk_margin", "slew_rate")


@dataclass
class PlantData:
    """One plant of a problem as polynomials (highest power first) and a delay (s)."""

    label: str
    num: list[float]
    den: list[float]
    delay: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return dict(self.__dict__)


@dataclass
class RobustProblem:
    """One multi-plant design problem.

    Attributes
    ----------
    index : int
        Position in the seeded sequence.
    spec : dict
        The spec, as ``synth.parse_spec`` takes it (``plant.variants`` non-empty).
    plants : list of PlantData
        The nominal plant first, then every variant, as the reference evaluates them.
    features : list of str
        What the nominal plant has and what the variants do.
    """

    index: int
    spec: dict[str, Any]
    plants: list[PlantData]
    features: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"index": self.index, "spec": self.spec, "plants": [p.to_dict() for p in self.plants],
                "features": self.features}


def _g(x: float) -> str:
    return f"{x:.6g}"


def _r(x: float) -> float:
    return float(_g(x))


@dataclass
class _Factors:
    """A plant as factors: ``k * prod(zeros) / prod(poles)``."""

    k: float = 1.0
    poles: list[float] = field(default_factory=list)  # real: s + p (p < 0: unstable, p = 0: integrator)
    pairs: list[tuple[float, float]] = field(default_factory=list)  # (a1, a0): s^2 + a1 s + a0
    lhp_zeros: list[float] = field(default_factory=list)  # s + z
    rhp_zeros: list[float] = field(default_factory=list)  # 1 - s/z

    def copy(self) -> _Factors:
        return _Factors(self.k, list(self.poles), list(self.pairs), list(self.lhp_zeros), list(self.rhp_zeros))

    def polys(self) -> tuple[np.ndarray, np.ndarray]:
        num, den = np.array([1.0]), np.array([1.0])
        for p in self.poles:
            den = np.polymul(den, [1.0, p])
        for a1, a0 in self.pairs:
            den = np.polymul(den, [1.0, a1, a0])
        for z in self.lhp_zeros:
            num = np.polymul(num, [1.0, z])
        for z in self.rhp_zeros:
            num = np.polymul(num, [-1.0 / z, 1.0])
        return self.k * num, den

    def text(self) -> str:
        def pole(p: float) -> str:
            return "s" if p == 0 else (f"(s+{_g(p)})" if p > 0 else f"(s-{_g(-p)})")

        nums = [f"(s+{_g(z)})" for z in self.lhp_zeros] + [f"(1-s/{_g(z)})" for z in self.rhp_zeros]
        dens = [pole(p) for p in self.poles] + [f"(s^2+{_g(a1)}*s+{_g(a0)})" for a1, a0 in self.pairs]
        return f"{_g(self.k)}*" + ("*".join(nums) if nums else "1") + "/(" + "*".join(dens) + ")"

    def scale_to(self, wt: float) -> None:
        num, den = self.polys()
        self.k = _r(self.k / abs(np.polyval(num, 1j * wt) / np.polyval(den, 1j * wt)))

    def order(self) -> int:
        return len(self.poles) + 2 * len(self.pairs)

    def nzeros(self) -> int:
        return len(self.lhp_zeros) + len(self.rhp_zeros)


def _nominal(rng: np.random.Generator, wt: float) -> tuple[_Factors, list[str]]:
    order = int(rng.integers(1, 5))
    f, feats, left = _Factors(), [], order
    if rng.random() < 0.25:
        f.poles.append(-_r(wt * 10 ** rng.uniform(-1.0, -0.2)))
        feats.append("unstable")
        left -= 1
    if left >= 1 and rng.random() < 0.25:
        f.poles.append(0.0)
        feats.append("integrator")
        left -= 1
    if left >= 2 and rng.random() < 0.4:
        wn = wt * 10 ** rng.uniform(-0.7, 0.7)
        zeta = 10 ** rng.uniform(np.log10(0.02), np.log10(0.7))
        f.pairs.append((_r(2 * zeta * wn), _r(wn * wn)))
        feats.append(f"light(zeta={zeta:.3f})")
        left -= 2
    while left > 0:
        f.poles.append(_r(wt * 10 ** rng.uniform(-1.3, 1.0)))
        left -= 1
    n_zeros = int(rng.integers(0, min(order - 1, 2) + 1)) if order > 1 else 0
    for i in range(n_zeros):
        z = _r(wt * 10 ** rng.uniform(-0.5, 1.2))
        if i == 0 and rng.random() < 0.35:
            f.rhp_zeros.append(z)
            feats.append("rhp_zero")
        else:
            f.lhp_zeros.append(z)
    f.scale_to(wt)
    return f, feats


def _moved(rng: np.random.Generator, f: _Factors, wt: float) -> tuple[_Factors, str]:
    """A ``tf`` replacement: one part of the nominal plant moved, or a mode added (the DC gain kept where finite)."""
    v = f.copy()
    choices = ["add_pole", "add_mode"]
    if any(p != 0 for p in v.poles):
        choices.append("move_pole")
    if v.pairs:
        choices.append("damping")
    if v.lhp_zeros or v.rhp_zeros:
        choices.append("move_zero")
    what = str(rng.choice(choices))
    fac = 10 ** rng.uniform(np.log10(0.4), np.log10(2.5))
    if what == "move_pole":
        i = int(rng.choice([j for j, p in enumerate(v.poles) if p != 0]))
        v.poles[i] = _r(v.poles[i] * fac)
        v.k = _r(v.k * fac) if v.poles[i] > 0 else v.k  # keeps the DC gain of a stable real pole
    elif what == "damping":
        a1, a0 = v.pairs[0]
        v.pairs[0] = (_r(a1 * 10 ** rng.uniform(-0.5, 0.3)), _r(a0 * fac))
        v.k = _r(v.k * fac)
    elif what == "move_zero":
        if v.lhp_zeros and (not v.rhp_zeros or rng.random() < 0.5):
            v.lhp_zeros[0] = _r(v.lhp_zeros[0] * fac)
            v.k = _r(v.k / fac)
        else:
            v.rhp_zeros[0] = _r(v.rhp_zeros[0] * fac)
    elif what == "add_pole":
        p = _r(wt * 10 ** rng.uniform(-0.3, 1.2))
        v.poles.append(p)
        v.k = _r(v.k * p)
    else:  # a lightly damped mode above crossover, unit DC gain
        wn = wt * 10 ** rng.uniform(0.0, 1.0)
        zeta = 10 ** rng.uniform(np.log10(0.02), np.log10(0.3))
        v.pairs.append((_r(2 * zeta * wn), _r(wn * wn)))
        v.k = _r(v.k * v.pairs[-1][1])
    return v, f"tf:{what}"


def _hard(rng: np.random.Generator, f: _Factors, wt: float, delay: float) -> tuple[dict[str, Any], _Factors | None,
                                                                                      float | None, str]:
    """A variant that makes the problem much harder: (spec entry without label, factors or None, delay or None)."""
    what = str(rng.choice(["big_gain", "small_gain", "slow_rhp_zero", "long_delay", "unstable_pole"]))
    if what == "big_gain":
        return {"gain": _r(10 ** rng.uniform(np.log10(5), 1))}, None, None, "hard:big_gain"
    if what == "small_gain":
        return {"gain": _r(10 ** rng.uniform(-1.2, -1))}, None, None, "hard:small_gain"
    if what == "long_delay":
        d = _r(max(delay, 0.0) + rng.uniform(0.5, 1.5) * np.pi / wt)
        return {"delay": d}, None, d, "hard:long_delay"
    v = f.copy()
    if what == "slow_rhp_zero":
        v.rhp_zeros.append(_r(wt * 10 ** rng.uniform(-0.5, 0.0)))
        v.poles.append(_r(wt * 10 ** rng.uniform(0.5, 1.0)))  # stays strictly proper
        v.k = _r(v.k * v.poles[-1])
    else:
        p = _r(wt * 10 ** rng.uniform(-0.5, 0.2))
        v.poles.append(-p)
        v.k = _r(v.k * p)
    return {"tf": v.text()}, v, None, f"hard:{what}"


def _controller(rng: np.random.Generator, kind: str, wt: float) -> dict[str, Any]:
    kmax = _r(10 ** rng.uniform(0.3, 1.5))
    if kind == "P":
        return {"type": "P", "bounds": {"kp": [0.0, kmax]}}
    if kind == "PI":
        return {"type": "PI", "bounds": {"kp": [0.0, kmax], "ki": [0.0, _r(kmax * wt)]}}
    if kind == "PID":
        tf = _r(0.1 / wt)
        return {"type": "PID", "bounds": {"kp": [0.0, kmax], "ki": [0.0, _r(kmax * wt)],
                                          "kd": [0.0, _r(kmax / wt)], "tf": [tf, tf]}}
    if kind == "leadlag":
        return {"type": "leadlag", "bounds": {"k": [0.0, kmax], "z": [_r(0.05 * wt), _r(20 * wt)],
                                              "p": [_r(0.05 * wt), _r(50 * wt)]}}
    n = int(rng.integers(1, 4))
    m = int(rng.integers(0, min(n, 2) + 1))
    bounds: dict[str, list[float]] = {}
    for i in range(m + 1):
        b = _r(kmax * wt ** (n - i) * 10)
        bounds[f"b{i}"] = [-b, b]
    for i in range(n):
        bounds[f"a{i}"] = [0.0, _r(50 * wt ** (n - i) * 3 ** n)]
    return {"type": "rational", "order": [m, n], "bounds": bounds}


def _requirements(rng: np.random.Generator, wt: float, integrator: bool) -> list[dict[str, Any]]:
    n = int(rng.integers(1, 4))
    reqs: list[dict[str, Any]] = []
    for t in map(str, rng.choice(REQUIREMENTS, size=n, replace=False)):
        if t == "bandwidth":
            r: dict[str, Any] = {"type": t, "min": _r(wt * 10 ** rng.uniform(-0.8, 0.5))}
            if rng.random() < 0.2:
                r["max"] = _r(r["min"] * 10 ** rng.uniform(0.2, 1.0))
        elif t == "sensitivity":
            hi = _r(wt * 10 ** rng.uniform(-1.5, -0.3))
            lo = 0.0 if rng.random() < 0.5 else _r(hi * 0.01)
            r = {"type": t, "max_db": _r(rng.uniform(-25, -3)), "band": [lo, hi]}
        elif t == "sensitivity_static":
            r = {"type": t, "max_db": _r(rng.uniform(-30, -6))}
            if integrator or rng.random() < 0.4:
                r["plant_gain"] = _r(10 ** rng.uniform(-0.5, 1.0))
        elif t in ("peak_sensitivity", "peak_complementary"):
            r = {"type": t, "max_db": _r(rng.uniform(1.0, 9.0))}
            if rng.random() < 0.15:
                r["band"] = [_r(wt * 0.01), _r(wt * 10 ** rng.uniform(0.0, 1.0))]
        elif t == "peak_control_sensitivity":
            r = {"type": t, "max_db": _r(rng.uniform(5.0, 35.0))}
        elif t == "margins":
            r = {"type": t}
            which = rng.choice(3, size=int(rng.integers(1, 3)), replace=False)
            if 0 in which:
                r["gain_margin_db"] = _r(rng.uniform(2.0, 12.0))
            if 1 in which:
                r["phase_margin_deg"] = _r(rng.uniform(20.0, 70.0))
            if 2 in which:
                r["delay_margin"] = _r(rng.uniform(0.05, 0.6) / wt)
        elif t == "delay_margin":
            r = {"type": t, "min": _r(rng.uniform(0.05, 0.8) / wt)}
        elif t == "disk_margin":
            r = {"type": t, "min": _r(rng.uniform(0.2, 0.8))}
            if rng.random() < 0.3:
                r["skew"] = _r(rng.uniform(-0.8, 0.8))
        else:  # slew_rate
            de = _r(10 ** rng.uniform(-1, 0.5))
            r = {"type": t, "rate_limit": _r(de * wt * 10 ** rng.uniform(0.3, 2.0)), "max_error": de,
                 "band": [_r(0.01 * wt), _r(wt * 10 ** rng.uniform(0.0, 1.0))]}
        reqs.append(r)
    return reqs


def problem(seed: int, index: int, *, controllers: tuple[str, ...] = CONTROLLERS) -> RobustProblem:
    """The ``index``-th problem of the sequence ``seed`` (a pure function of both).

    Parameters
    ----------
    seed, index : int
        Seed of the sequence and position in it.
    controllers : tuple of str
        Structures to draw from.

    Returns
    -------
    RobustProblem
        The spec and every plant as polynomials.

    Examples
    --------
    >>> p = problem(7, 0)
    >>> len(p.plants) == 1 + len(p.spec["plant"]["variants"]) >= 2
    True
    """
    rng = np.random.default_rng([seed, index, 77])
    wt = _r(10 ** rng.uniform(-1, 2))
    f, feats = _nominal(rng, wt)
    delay = 0.0
    if rng.random() < 0.6:
        delay = _r(rng.uniform(0, 1) ** 2 * np.pi / wt)
        feats.append("delay")
    in_tf = delay > 0 and rng.random() < 1 / 3
    plant: dict[str, Any] = {"tf": f.text() + (f"*exp(-{_g(delay)}*s)" if in_tf else "")}
    if not in_tf:
        plant["delay"] = delay
    if in_tf:
        feats.append("delay_in_tf")
    num, den = f.polys()
    plants = [PlantData("nominal", [float(x) for x in num], [float(x) for x in den], delay)]
    n_var = int(rng.integers(1, 5))
    hard_at = int(rng.integers(0, n_var)) if rng.random() < 0.15 else -1
    variants = []
    for i in range(n_var):
        label = f"v{i + 1}"
        vf, vdelay, gain = f, None, 1.0
        if i == hard_at:
            entry, hf, hd, what = _hard(rng, f, wt, delay)
            vf = hf or f
            vdelay = hd
            gain = entry.get("gain", 1.0)
        else:
            kind = str(rng.choice(["gain", "gain", "tf", "tf", "delay", "gain+delay", "gain+tf"]))
            entry, what = {}, kind
            if "gain" in kind:
                gain = _r(10 ** rng.uniform(np.log10(0.3), np.log10(3)))
                entry["gain"] = gain
            if "tf" in kind:
                vf, w = _moved(rng, f, wt)
                entry["tf"] = vf.text()
                what = kind.replace("tf", w)
            if "delay" in kind:
                vdelay = _r(delay * rng.uniform(0, 2.5) if delay > 0 else rng.uniform(0.05, 0.5) * np.pi / wt)
                entry["delay"] = vdelay
        if "tf" in entry and in_tf and "delay" not in entry:  # the exp written in the nominal tf goes with it
            vdelay = _r(delay * rng.uniform(0.5, 1.5))
            entry["delay"] = vdelay
        feats.append(f"{label}={what}")
        variants.append({"label": label, **entry})
        vnum, vden = vf.polys()
        plants.append(PlantData(label, [float(x) * gain for x in vnum], [float(x) for x in vden],
                                delay if vdelay is None else vdelay))
    plant["variants"] = variants
    kind = str(rng.choice(controllers))
    integrator = any(p == 0 for p in f.poles)
    spec: dict[str, Any] = {"name": f"robust_{seed}_{index}", "plant": plant,
                            "controller": _controller(rng, kind, wt),
                            "requirements": _requirements(rng, wt, integrator)}
    objectives = [("maximize", "bandwidth"), ("maximize", "bandwidth"), ("maximize", "crossover"),
                  ("minimize", "peak_sensitivity"), ("minimize", "peak_complementary"), ("minimize", "control_effort"),
                  None, None]
    if kind in ("PI", "PID"):
        objectives += [("maximize", "integral_gain")] * 2
    if kind in ("P", "leadlag"):
        objectives += [("maximize", "low_frequency_gain")]
    obj = objectives[int(rng.integers(0, len(objectives)))]
    if obj is not None:
        spec["objective"] = {obj[0]: obj[1]}
        if obj[0] == "minimize" and not any(r["type"] == "bandwidth" for r in spec["requirements"]):
            # without a bandwidth floor a vanishing gain minimizes these peaks (no best point)
            spec["requirements"].append({"type": "bandwidth", "min": _r(wt * 10 ** rng.uniform(-0.8, 0.3))})
    return RobustProblem(index, spec, plants, feats)


def generate(n: int, seed: int = 0, start: int = 0, **kwargs: Any) -> list[RobustProblem]:
    """Problems ``start .. start+n-1`` of the sequence ``seed``.

    Examples
    --------
    >>> [p.index for p in generate(3, seed=2, start=5)]
    [5, 6, 7]
    """
    return [problem(seed, i, **kwargs) for i in range(start, start + n)]


def main() -> None:
    """Print problems as JSON lines."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--start", type=int, default=0)
    args = ap.parse_args()
    for p in generate(args.n, args.seed, args.start):
        print(json.dumps(p.to_dict()))


if __name__ == "__main__":
    main()
