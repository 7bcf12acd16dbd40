"""Problem generator of the generalizing withheld-effect benchmark: seeded random plants, lengths, designs, effects.

Every problem is reproducible from ``(seed, index)`` and the case list (:func:`case_list`):

* **plant** (:func:`random_plant`), one of :data:`FAMILIES`: ``first_order`` ``k/(T s+1)``;
  ``second_order`` two real poles (time constants up to 8 apart), a left-half-plane zero in half the
  draws; ``resonant`` a lightly damped mode (zeta 0.1-0.4), a zero in half the draws;
  ``third_order`` a real pole and a mode (zeta 0.1-0.7), a zero in half the draws. Gain log-uniform
  in [0.2, 50]; in half the draws a delay of 0.2-1 fastest time constant. Sample time: 5-20 samples per
  fastest time constant, coarser when the record is too short for eight settled steps;
* **length**: samples, one of the list's lengths (1,000 to 100,000 in the full list);
* **experiment**: ``steps`` (levels of several sizes both ways, each held three to six settling times),
  ``sweep`` (a log chirp over the plant's band, twice, with a triangular amplitude envelope),
  ``noise`` (Gaussian noise held over a fraction of the fastest time constant, its amplitude growing
  linearly over the record, as the Silverbox "arrow");
* **nominal model** handed to the diagnosis: every nonzero coefficient of the true plant off by 2-5 %
  (random sign), the delay kept: a parameter mismatch in every case;
* **supply**: every record carries a measured supply voltage ``V`` (a battery sagging with the
  filtered command and discharging slowly over the record, measured with noise); it drives the plant
  only in the ``measured_sag`` cases, so its presence does not give the answer away;
* **effect**: one of :data:`EFFECT_NAMES` or none; **severity**: the strength is set by bisection
  so that the RMS difference between the true plant's output with and without the effect is
  ``ratio x noise`` (``ratio`` in :data:`SEVERITIES`; computed on at most the first 4,000 samples),
  or the strongest the effect reaches;
* **truth**: simulated by :func:`benchmarks.gap.reference.simulate_reference` (scipy ``solve_ivp``,
  not synth's simulation code); the true shrinkage is ``1 - J_true / J_refit`` on the held-out half,
  ``J_true`` of the true model with the true effect, ``J_refit`` of the nominal re-fitted alone on the
  training half (:func:`synth.gap.attribution.refit.fit_augmented`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from benchmarks.gap.reference import TruePlant, simulate_reference
from synth.data import record_from_arrays
from synth.data.record import Record
from synth.gap.attribution.refit import fit_augmented
from synth.plant import Plant

FAMILIES: tuple[str, ...] = ("first_order", "second_order", "resonant", "third_order")
EXPERIMENTS: tuple[str, ...] = ("steps", "sweep", "noise")
EFFECT_NAMES: tuple[str, ...] = ("delay", "lag", "resonance", "rate_limit", "saturation", "deadzone", "backlash",
                                 "quantization", "supply_sag", "static_nonlinearity", "drift", "direction", "duffing",
                                 "amplitude_damping", "measured_sag")
"""Every default candidate effect of :mod:`synth.gap.effects` (the lag at the actuator) and the newer ones."""
SEVERITIES: tuple[float, ...] = (1.0, 2.0, 5.0, 10.0, 30.0)
"""Effect RMS over the noise standard deviation."""
LENGTHS_FULL: tuple[int, ...] = (1000, 3000, 10000, 30000, 100000)
TRAIN_FRACTION = 0.5
CALIBRATION_SAMPLES = 4000
AUX = "V"


def label(effect: str | None) -> str:
    """The verdict's name of a benchmark effect (``measured_sag`` reads the supply column ``V``).

    Examples
    --------
    >>> label("measured_sag"), label("lag"), label(None)
    ('measured_sag(V)', 'lag', 'none')
    """
    if effect is None:
        return "none"
    return f"measured_sag({AUX})" if effect == "measured_sag" else effect


@dataclass(frozen=True)
class PlantDraw:
    """A random plant and its sampling."""

    family: str
    plant: TruePlant
    dt: float
    settle: float
    fast: float


def _poles_ok(den: np.ndarray, ratio: float = 15.0) -> bool:
    p = np.roots(den)
    return bool(np.all(p.real < 0) and np.max(np.abs(p)) / np.min(-p.real) <= ratio)


def random_plant(rng: np.random.Generator, family: str, n: int) -> PlantDraw:
    """A stable random plant of ``family`` sampled for a record of ``n`` samples.

    Examples
    --------
    >>> d = random_plant(np.random.default_rng(0), "resonant", 1000)
    >>> len(d.plant.den), bool(d.dt > 0)
    (3, True)
    """
    for _ in range(200):
        k = float(np.exp(rng.uniform(np.log(0.2), np.log(50.0))))
        T = float(np.exp(rng.uniform(np.log(0.02), np.log(2.0))))
        zero = (1.0,) if rng.random() < 0.5 else (float(T * rng.uniform(0.2, 2.0)), 1.0)
        if family == "first_order":
            num, den = (1.0,), (T, 1.0)
        elif family == "second_order":
            T2 = T * float(rng.uniform(1.0 / 8.0, 1.0))
            num, den = zero, tuple(np.polymul((T, 1.0), (T2, 1.0)))
        elif family == "resonant":
            wn, z = 1.0 / T, float(rng.uniform(0.1, 0.4))
            num, den = zero, (1.0 / wn**2, 2 * z / wn, 1.0)
        else:
            wn, z = 1.0 / T, float(rng.uniform(0.1, 0.7))
            T1 = T * float(np.exp(rng.uniform(np.log(0.3), np.log(4.0))))
            num, den = zero, tuple(np.polymul((T1, 1.0), (1.0 / wn**2, 2 * z / wn, 1.0)))
        den_a = np.asarray(den, float)
        if not _poles_ok(den_a):
            continue
        poles = np.roots(den_a)
        settle, fast = 1.0 / float(np.min(-poles.real)), 1.0 / float(np.max(np.abs(poles)))
        dt = fast / float(rng.uniform(5.0, 20.0))
        dt = max(dt, 8 * 4.0 * settle / n)  # eight steps held four settling times at least
        if dt > 0.6 * fast:
            continue
        delay = float(rng.uniform(0.2, 1.0) * fast) if rng.random() < 0.5 else 0.0
        num_a = k * np.asarray(num, float) / float(num[-1])
        return PlantDraw(family, TruePlant(tuple(num_a), tuple(den_a), delay), dt, settle, fast)
    raise RuntimeError(f"no {family} plant found for {n} samples")


def experiment(rng: np.random.Generator, kind: str, draw: PlantDraw, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Time and command of ``n`` samples: a step train, a double log sweep or growing held noise.

    Examples
    --------
    >>> rng = np.random.default_rng(1); d = random_plant(rng, "first_order", 1000)
    >>> t, u = experiment(rng, "steps", d, 1000)
    >>> t.size, bool(np.ptp(u) > 0)
    (1000, True)
    """
    t = np.arange(n) * draw.dt
    lo = float(rng.uniform(-1.0, 1.0))
    span = float(np.exp(rng.uniform(np.log(0.5), np.log(20.0))))
    hi = lo + span
    if kind == "steps":
        hold = draw.settle * float(rng.uniform(3.0, 6.0))
        n_levels = max(8, int(np.ceil(t[-1] / hold)) + 1)
        levels = np.where(np.arange(n_levels) % 2 == 0, rng.uniform(lo, lo + 0.45 * span, n_levels),
                          rng.uniform(lo + 0.55 * span, hi, n_levels))
        hold = (t[-1] + draw.dt) / n_levels
        return t, levels[np.minimum((t // hold).astype(int), n_levels - 1)]
    mid, amp = 0.5 * (lo + hi), 0.5 * span
    if kind == "sweep":
        w0, w1 = 0.2 / draw.settle, min(3.0 / draw.fast, 0.4 * np.pi / draw.dt)
        half = (t[-1] + draw.dt) / 2.0
        tau = t % half
        kk = np.log(w1 / w0) / half
        envelope = 0.3 + 0.7 * (1.0 - np.abs(2.0 * tau / half - 1.0))
        return t, mid + amp * envelope * np.sin(w0 / kk * (np.exp(kk * tau) - 1.0))
    m = max(1, round(draw.fast * float(rng.uniform(0.5, 2.0)) / draw.dt))
    e = np.repeat(rng.standard_normal(n // m + 1), m)[:n]
    envelope = np.linspace(0.2, 1.0, n)
    return t, mid + amp * np.clip(0.4 * envelope * e, -1.0, 1.0)


def supply_voltage(rng: np.random.Generator, t: np.ndarray, u: np.ndarray, settle: float) -> np.ndarray:
    """A battery's voltage under the command's load: sags with the filtered command, discharges slowly (noise-free).

    Examples
    --------
    >>> t = np.arange(100) * 0.1; v = supply_voltage(np.random.default_rng(0), t, np.ones(100), 1.0)
    >>> bool(v[-1] < v[0] <= 12.6)
    True
    """
    load = (u - np.min(u)) / max(float(np.ptp(u)), 1e-12)
    a = 1.0 - np.exp(-(t[1] - t[0]) / (0.3 * settle))
    f = np.empty_like(load)
    acc = load[0]
    for i, x in enumerate(load):
        acc += a * (x - acc)
        f[i] = acc
    depth = float(rng.uniform(0.1, 0.25))
    discharge = float(rng.uniform(0.03, 0.1))
    return 12.6 * (1.0 - depth * f - discharge * (t - t[0]) / (t[-1] - t[0]))


def strength_params(effect: str, s: float, t: np.ndarray, u: np.ndarray, draw: PlantDraw, y0: np.ndarray,
                    extra: dict[str, float]) -> dict[str, float]:
    """The effect's parameters at strength ``s`` in (0, 1] (larger: stronger)."""
    span = float(np.ptp(u))
    dt, fast, settle = draw.dt, draw.fast, draw.settle
    a = float(np.max(np.abs(y0 - np.mean(y0))))
    if effect == "delay":
        return {"delay": s * 2.0 * fast}
    if effect == "lag":
        return {"tau": s * 0.9 * fast}
    if effect == "resonance":
        top = 0.9 * np.pi / dt
        return {"wn": float(top * (2.0 / fast / top) ** s), "zeta": 0.15}
    if effect == "rate_limit":
        top = float(np.max(np.abs(np.diff(u)))) / dt
        return {"rate": float(top * (0.02 * span / settle / top) ** s)}
    if effect == "saturation":
        return {"upper": float(np.max(u) - 0.6 * s * span)}
    if effect == "deadzone":
        return {"width": 0.4 * s * span, "center": float(u[0])}
    if effect == "backlash":
        return {"width": 0.4 * s * span}
    if effect == "quantization":
        return {"step": 0.4 * s * span, "offset": extra["offset"] * 0.4 * s * span}
    if effect == "supply_sag":
        return {"sag": 0.95 * s / span, "tau": 0.5 * settle}
    if effect == "static_nonlinearity":
        return {"a2": extra["sign"] * 0.8 * s, "a3": 0.5 * s, "center": float(0.5 * (np.max(u) + np.min(u))),
                "scale": 0.5 * span}
    if effect == "drift":
        return {"slope": s * float(np.ptp(y0)) / float(t[-1] - t[0])}
    if effect == "direction":
        return {"tau_up": s * 0.8 * settle + 1e-3 * fast, "tau_down": 0.15 * s * settle + 1e-3 * fast,
                "delay_up": s * 0.5 * fast, "delay_down": 0.0}
    if effect == "duffing":
        return {"cubic": s * 1.5 / a**2}
    if effect == "amplitude_damping":
        v = float(np.max(np.abs(np.diff(y0)))) / dt
        return {"drag": s * 2.0 * a / v**2}
    if effect == "measured_sag":
        return {"sag": s, "v_nominal": 12.6, "u_rest": float(np.min(u))}
    raise ValueError(effect)


def calibrate(effect: str, target: float, t: np.ndarray, u: np.ndarray, draw: PlantDraw, v: np.ndarray,
              extra: dict[str, float]) -> dict[str, float]:
    """Strength bisection (on the first :data:`CALIBRATION_SAMPLES` samples) to an effect RMS of ``target``."""
    m = min(t.size, CALIBRATION_SAMPLES)
    tc, uc, vc = t[:m], u[:m], v[:m]
    y0c = simulate_reference(draw.plant, tc, uc)
    y0 = simulate_reference(draw.plant, t, u) if effect == "drift" else y0c

    def params(s: float) -> dict[str, float]:
        return strength_params(effect, s, t if effect == "drift" else tc, u if effect == "drift" else uc, draw,
                               y0, extra)

    def rms(s: float) -> float:
        if effect == "drift":  # additive: exact on the whole record
            return float(params(s)["slope"] * np.sqrt(np.mean((t - t[0]) ** 2)))
        y = simulate_reference(draw.plant, tc, uc, effect, params(s), aux=vc)
        return float(np.sqrt(np.mean((y - y0c) ** 2)))

    lo, hi = 1e-4, 1.0
    if rms(hi) <= target:
        return params(hi)
    for _ in range(30):
        mid = float(np.sqrt(lo * hi))
        if rms(mid) < target:
            lo = mid
        else:
            hi = mid
        if hi / lo < 1.03:
            break
    return params(hi)


def _mismatch(plant: TruePlant, rng: np.random.Generator) -> Plant:
    def off(c: np.ndarray, keep_first: bool) -> np.ndarray:
        out = c.astype(float).copy()
        for i in range(out.size):
            if out[i] != 0.0 and not (keep_first and i == 0):
                out[i] *= 1.0 + rng.choice([-1.0, 1.0]) * rng.uniform(0.02, 0.05)
        return out

    den = np.asarray(plant.den, float)
    return Plant(off(np.asarray(plant.num, float) / den[0], False), off(den / den[0], True), plant.delay,
                 label="nominal")


def case_list(lengths: tuple[int, ...], n_free: int = 12) -> list[tuple[str | None, float, int, str, str]]:
    """``(effect, severity, samples, family, experiment)`` of every case: each effect at each severity, then
    ``n_free`` effect-free cases; lengths, families and experiments rotate so that each effect meets several.

    The length of effect ``e`` at severity ``s`` (indices) is ``lengths[(e + s) % len(lengths)]``: with five
    lengths every effect meets every length once and every length every severity three times (a rotation by
    the case index alone would tie each length to one severity). For one, two or four lengths this is the
    case index's rotation, so the cases of the earlier two-length runs (seeds 11-14) are unchanged.

    Examples
    --------
    >>> cases = case_list((1000, 2000))
    >>> len(cases), sum(c[0] is None for c in cases), cases[0]
    (87, 12, ('delay', 1.0, 1000, 'first_order', 'steps'))
    """
    out: list[tuple[str | None, float, int, str, str]] = []
    i = 0
    for e, effect in enumerate(EFFECT_NAMES):
        for s, sev in enumerate(SEVERITIES):
            out.append((effect, sev, lengths[(e + s) % len(lengths)], FAMILIES[(i // 3) % len(FAMILIES)],
                        EXPERIMENTS[i % len(EXPERIMENTS)]))
            i += 1
    for j in range(n_free):
        out.append((None, 0.0, lengths[j % len(lengths)], FAMILIES[j % len(FAMILIES)],
                    EXPERIMENTS[(j // len(FAMILIES)) % len(EXPERIMENTS)]))
    return out


@dataclass(frozen=True, eq=False)
class Problem:
    """One record with its hidden truth (see the module text)."""

    index: int
    seed: int
    family: str
    experiment: str
    effect: str | None
    severity: float
    params: dict[str, float]
    true_plant: TruePlant
    nominal: Plant
    noise: float
    record: Record = field(repr=False)
    clean: np.ndarray = field(repr=False)
    effect_rms: float
    true_shrinkage: float

    def to_dict(self) -> dict[str, Any]:
        """JSON description (no arrays).

        Examples
        --------
        >>> sorted(make_problem(0, 0, (1000,), compute_truth=False).to_dict())[:3]
        ['effect', 'effect_rms', 'experiment']
        """
        return {"index": self.index, "seed": self.seed, "family": self.family, "experiment": self.experiment,
                "effect": self.effect, "label": label(self.effect), "severity": self.severity,
                "params": {k: float(v) for k, v in self.params.items()},
                "true_plant": {"num": list(self.true_plant.num), "den": list(self.true_plant.den),
                               "delay": self.true_plant.delay},
                "nominal": self.nominal.to_string(6), "noise": self.noise, "samples": int(self.record.n),
                "effect_rms": self.effect_rms, "true_shrinkage": self.true_shrinkage}


def make_problem(seed: int, index: int, lengths: tuple[int, ...], compute_truth: bool = True) -> Problem:
    """Problem ``index`` of :func:`case_list` for ``seed`` (the same arguments give the same record).

    Examples
    --------
    >>> p = make_problem(0, 0, (1000,), compute_truth=False)
    >>> p.effect, p.record.n, sorted(p.record.aux)
    ('delay', 1000, ['V'])
    >>> float(np.max(np.abs(make_problem(0, 0, (1000,), compute_truth=False).record.y - p.record.y)))
    0.0
    """
    effect, severity, n, family, kind = case_list(lengths)[index]
    rng = np.random.default_rng([seed, index, 17])
    draw = random_plant(rng, family, n)
    nominal = _mismatch(draw.plant, rng)
    t, u = experiment(rng, kind, draw, n)
    v = supply_voltage(rng, t, u, draw.settle)
    y_lin = simulate_reference(draw.plant, t, u)
    noise = float(np.ptp(y_lin)) * float(np.exp(rng.uniform(np.log(0.003), np.log(0.02))))
    extra = {"offset": float(rng.uniform(0.0, 1.0)), "sign": float(rng.choice([-1.0, 1.0]))}
    if effect is None:
        params: dict[str, float] = {}
        clean = y_lin
    else:
        params = calibrate(effect, severity * noise, t, u, draw, v, extra)
        clean = simulate_reference(draw.plant, t, u, effect, params, aux=v)
    eff_rms = float(np.sqrt(np.mean((clean - y_lin) ** 2)))
    y = clean + noise * rng.standard_normal(n)
    v_meas = v + 0.002 * 12.6 * rng.standard_normal(n)
    record = record_from_arrays(t, u, y, aux={AUX: v_meas})
    shrink = np.nan
    if compute_truth and effect is not None:
        k = round(TRAIN_FRACTION * n)
        held = np.arange(n) >= k
        refit = fit_augmented(nominal, t[:k], u[:k], y[:k])
        j_refit = float(np.mean((y - refit.predict(t, u))[held] ** 2))
        j_true = float(np.mean((y - clean)[held] ** 2))
        shrink = 1.0 - j_true / j_refit
    return Problem(index, seed, family, kind, effect, severity, params, draw.plant, nominal, noise, record, clean,
                   eff_rms, float(shrink))
