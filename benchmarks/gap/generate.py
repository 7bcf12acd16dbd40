"""Withheld-effect benchmark: records from a plant with one hidden effect, diagnosed against the nominal model.

Every case is reproducible from ``(seed, index)``:

* **plant**: the X-4 rotor drive of the seed paper (eq. 5, ``23 (s+0.43)/((s+9.6)(s+0.54))``, PWM ->
  rad/s, 0.02 s sampling, noise 1 rad/s) or the DC-motor lab drive (``245.6/(0.151 s+1)^2 exp(-0.032 s)``,
  V -> rpm, 0.01 s sampling, noise 8 rpm);
* **nominal model** handed to the diagnosis: the true plant with every nonzero coefficient off by
  2-5 % (random sign), the delay kept: a parameter mismatch in every case;
* **effect**: one of :data:`EFFECT_NAMES` (the library of :mod:`synth.gap.effects`; the lag at the
  actuator: at the sensor it gives the same output on a linear model) or none (about 15 % of cases);
* **severity**: the effect's strength is set by bisection so that the RMS difference between the
  true plant's output with and without the effect is ``ratio x noise``, ``ratio`` in
  :data:`SEVERITIES` (1: barely above the noise, 30: large);
* **experiment**: a step train of 16 levels of several amplitudes, or a sweep (log chirp over the
  plant's band, twice, with a triangular amplitude envelope so both halves hold small and large
  amplitudes);
* **truth**: the effect's output and the *true shrinkage* ``1 - J_true / J_refit`` on the held-out
  half (``J_true`` of the true model with the true effect, ``J_refit`` of the nominal re-fitted alone on
  the training half by :func:`synth.gap.attribution.refit.fit_augmented`), as
  :func:`synth.gap.attribution.heldout.diagnose_effects` computes them.

Run ``python benchmarks/gap/generate.py --list`` to print the case list.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.data import record_from_arrays
from synth.data.record import Record
from synth.gap.attribution.refit import fit_augmented
from synth.gap.effects import make_effect
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

EFFECT_NAMES: tuple[str, ...] = ("delay", "lag", "resonance", "rate_limit", "saturation", "deadzone", "backlash",
                                 "quantization", "supply_sag", "static_nonlinearity", "drift")
"""Effects drawn (every effect of the library; the lag at the actuator)."""
SEVERITIES: tuple[float, ...] = (1.0, 3.0, 10.0, 30.0)
"""Effect RMS over the noise standard deviation."""
TRAIN_FRACTION = 0.5


@dataclass(frozen=True)
class PlantSetup:
    """One benchmark plant and its experiments."""

    name: str
    tf: str
    delay: float
    dt: float
    hold: float
    levels: tuple[float, float]
    sweep: tuple[float, float]
    noise: float


PLANTS: tuple[PlantSetup, ...] = (
    PlantSetup("x4_rotor", "23*(s+0.43)/((s+9.6)*(s+0.54))", 0.0, 0.02, 1.5, (170.0, 245.0), (0.3, 40.0), 1.0),
    PlantSetup("dc_motor", "245.6/(0.151*s+1)^2", 0.032, 0.01, 0.8, (2.0, 10.0), (0.5, 60.0), 8.0),
)


@dataclass(frozen=True, eq=False)
class Case:
    """One benchmark record with its hidden truth.

    Attributes
    ----------
    index, seed : int
    plant_name, experiment : str
    effect : str or None
        The hidden effect (``None``: only the parameter mismatch).
    severity : float
        Target effect RMS over the noise (0 for none).
    params : dict
        The effect's true parameters.
    true_plant, nominal : Plant
    noise : float
        Noise standard deviation (output units).
    record : Record
    clean : numpy.ndarray
        Noise-free output of the true plant with the effect.
    effect_rms : float
        RMS of the effect's contribution (output with minus without the effect).
    true_shrinkage : float
        ``1 - J_true / J_refit`` on the held-out half (``nan`` for effect-free cases).
    j_true, j_refit : float
    """

    index: int
    seed: int
    plant_name: str
    experiment: str
    effect: str | None
    severity: float
    params: dict[str, float]
    true_plant: Plant
    nominal: Plant
    noise: float
    record: Record = field(repr=False)
    clean: np.ndarray = field(repr=False)
    effect_rms: float
    true_shrinkage: float
    j_true: float
    j_refit: float

    def to_dict(self) -> dict[str, Any]:
        """JSON description (no arrays).

        Examples
        --------
        >>> c = make_case(0, 0, compute_truth=False)
        >>> sorted(c.to_dict())[:4]
        ['effect', 'effect_rms', 'experiment', 'index']
        """
        return {"index": self.index, "seed": self.seed, "plant": self.plant_name, "experiment": self.experiment,
                "effect": self.effect, "severity": self.severity,
                "params": {k: float(v) for k, v in self.params.items()},
                "true_plant": self.true_plant.to_string(6), "nominal": self.nominal.to_string(6),
                "noise": self.noise, "samples": int(self.record.n), "effect_rms": self.effect_rms,
                "true_shrinkage": self.true_shrinkage, "j_true": self.j_true, "j_refit": self.j_refit}


def case_list(n_free: int = 16) -> list[tuple[str, str | None, float, str]]:
    """The deterministic case list: ``(plant, effect, severity, experiment)``.

    Every effect at every severity on every plant (the experiment alternating with the severity
    and the plant), plus ``n_free`` effect-free cases.

    Examples
    --------
    >>> cases = case_list()
    >>> len(cases), sum(c[1] is None for c in cases)
    (104, 16)
    """
    out: list[tuple[str, str | None, float, str]] = []
    for p_i, setup in enumerate(PLANTS):
        for effect in EFFECT_NAMES:
            for s_i, sev in enumerate(SEVERITIES):
                out.append((setup.name, effect, sev, ("steps", "sweep")[(s_i + p_i) % 2]))
    free = [(PLANTS[i % len(PLANTS)].name, None, 0.0, ("steps", "sweep")[(i // len(PLANTS)) % 2])
            for i in range(n_free)]
    # spread the effect-free cases through the list (every 7th case)
    merged: list[tuple[str, str | None, float, str]] = []
    step = max(1, len(out) // max(n_free, 1))
    for i, c in enumerate(out):
        if i % step == 0 and free:
            merged.append(free.pop(0))
        merged.append(c)
    return merged + free


def _setup(name: str) -> PlantSetup:
    return next(p for p in PLANTS if p.name == name)


def _mismatch(plant: Plant, rng: np.random.Generator) -> Plant:
    """Every nonzero coefficient (not the leading denominator one) off by 2-5 %, random sign."""
    def off(c: np.ndarray, keep_first: bool) -> np.ndarray:
        out = c.astype(float).copy()
        for i in range(out.size):
            if out[i] != 0.0 and not (keep_first and i == 0):
                out[i] *= 1.0 + rng.choice([-1.0, 1.0]) * rng.uniform(0.02, 0.05)
        return out

    den = plant.den / plant.den[0]
    return Plant(off(plant.num / plant.den[0], False), off(den, True), plant.delay, label="nominal")


def experiment_input(setup: PlantSetup, experiment: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Time and command of a step train (16 random levels) or a double log sweep.

    Examples
    --------
    >>> t, u = experiment_input(PLANTS[0], "steps", np.random.default_rng(0))
    >>> t.size, bool(170 <= u.min() and u.max() <= 245)
    (1200, True)
    """
    lo, hi = setup.levels
    n_levels = 16
    duration = n_levels * setup.hold
    t = np.arange(0.0, duration, setup.dt)
    if experiment == "steps":
        # levels of several amplitudes: alternate low and high halves so steps go both ways and vary in size
        levels = np.where(np.arange(n_levels) % 2 == 0, rng.uniform(lo, lo + 0.45 * (hi - lo), n_levels),
                          rng.uniform(lo + 0.55 * (hi - lo), hi, n_levels))
        return t, levels[np.minimum((t // setup.hold).astype(int), n_levels - 1)]
    w0, w1 = setup.sweep
    half = duration / 2.0
    tau = t % half
    k = np.log(w1 / w0) / half
    phase = w0 / k * (np.exp(k * tau) - 1.0)
    envelope = 0.3 + 0.7 * (1.0 - np.abs(2.0 * tau / half - 1.0))
    mid, amp = 0.5 * (lo + hi), 0.5 * (hi - lo)
    return t, mid + amp * envelope * np.sin(phase)


def _strength_params(effect: str, s: float, t: np.ndarray, u: np.ndarray, plant: Plant) -> dict[str, float]:
    """The effect's parameters at strength ``s`` in (0, 1] (0: off, larger: stronger)."""
    span = float(np.max(u) - np.min(u))
    p = np.abs(plant.poles())
    slow, fast = float(np.min(p)), float(np.max(p))
    dt = float(t[1] - t[0])
    if effect == "delay":
        return {"delay": s * 2.0 / fast}
    if effect == "lag":
        return {"tau": s * 0.9 / fast}
    if effect == "resonance":
        top = 0.9 * np.pi / dt  # from just below the Nyquist frequency down to twice the fastest pole
        return {"wn": float(top * (2 * fast / top) ** s), "zeta": 0.15}
    if effect == "rate_limit":
        top = float(np.max(np.abs(np.diff(u)))) / dt
        return {"rate": float(top * (0.02 * span * slow / top) ** s)}
    if effect == "saturation":
        return {"upper": float(np.max(u) - 0.6 * s * span)}
    if effect == "deadzone":
        return {"width": 0.4 * s * span, "center": float(u[0])}
    if effect == "backlash":
        return {"width": 0.4 * s * span}
    if effect == "quantization":
        return {"step": 0.4 * s * span}
    if effect == "supply_sag":
        return {"sag": 0.95 * s / span, "tau": 0.5 / slow}
    if effect == "static_nonlinearity":
        return {"a2": -0.8 * s, "a3": 0.5 * s, "center": float(0.5 * (np.max(u) + np.min(u))), "scale": 0.5 * span}
    if effect == "drift":
        return {"slope": s * span * abs(plant.dc_gain()) / float(t[-1] - t[0])}
    raise ValueError(effect)


def _calibrate(effect: str, target: float, t: np.ndarray, u: np.ndarray, plant: Plant) -> tuple[dict[str, float],
                                                                                              float]:
    """Bisection on the strength so that the effect's RMS contribution is ``target`` (or the strongest reachable)."""
    eff = make_effect(effect)
    y0 = simulate_plant(plant, t, u)

    def rms(s: float) -> float:
        return float(np.sqrt(np.mean((eff.apply(plant, t, u, _strength_params(effect, s, t, u, plant)) - y0) ** 2)))

    lo, hi = 1e-4, 1.0
    if rms(hi) <= target:
        return _strength_params(effect, hi, t, u, plant), rms(hi)
    for _ in range(40):
        mid = np.sqrt(lo * hi)
        if rms(mid) < target:
            lo = mid
        else:
            hi = mid
        if hi / lo < 1.001:
            break
    return _strength_params(effect, hi, t, u, plant), rms(hi)


def make_case(seed: int, index: int, compute_truth: bool = True, n_free: int = 16) -> Case:
    """Case ``index`` of the list for ``seed`` (the same arguments give the same record).

    Parameters
    ----------
    seed, index : int
    compute_truth : bool
        Also re-fit the nominal alone to get ``J_refit`` and the true shrinkage (one casadi fit).
    n_free : int
        Effect-free cases in the list.

    Returns
    -------
    Case

    Examples
    --------
    >>> c = make_case(0, 1, compute_truth=False)
    >>> c.effect, c.severity, c.record.n
    ('delay', 1.0, 1200)
    >>> float(np.max(np.abs(make_case(0, 1, compute_truth=False).record.y - c.record.y)))
    0.0
    """
    plant_name, effect, severity, experiment = case_list(n_free)[index]
    setup = _setup(plant_name)
    rng = np.random.default_rng([seed, index])
    true_plant = Plant.from_string(setup.tf, delay=setup.delay)
    nominal = _mismatch(true_plant, rng)
    t, u = experiment_input(setup, experiment, rng)
    if effect is None:
        params: dict[str, float] = {}
        clean = simulate_plant(true_plant, t, u)
        eff_rms = 0.0
    else:
        params, eff_rms = _calibrate(effect, severity * setup.noise, t, u, true_plant)
        clean = make_effect(effect).apply(true_plant, t, u, params)
    y = clean + setup.noise * rng.standard_normal(t.size)
    record = record_from_arrays(t, u, y)
    shrink, j_true, j_refit = np.nan, np.nan, np.nan
    if compute_truth:
        k = round(TRAIN_FRACTION * t.size)
        held = np.arange(t.size) >= k
        refit = fit_augmented(nominal, t[:k], u[:k], y[:k])
        j_refit = float(np.mean((y - refit.predict(t, u))[held] ** 2))
        j_true = float(np.mean((y - clean)[held] ** 2))
        shrink = 1.0 - j_true / j_refit if effect is not None else np.nan
    return Case(index, seed, plant_name, experiment, effect, severity, params, true_plant, nominal, setup.noise,
                record, clean, eff_rms, float(shrink), float(j_true), float(j_refit))


def main(argv: list[str] | None = None) -> None:
    """CLI: list the cases (``--list``) or describe one (``--index``)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--index", type=int, default=None)
    ap.add_argument("--list", action="store_true")
    args = ap.parse_args(argv)
    if args.list or args.index is None:
        for i, c in enumerate(case_list()):
            print(i, *c)
        return
    print(make_case(args.seed, args.index).to_dict())


if __name__ == "__main__":
    main()
