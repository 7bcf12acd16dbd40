"""SYNTHETIC disturbance records from a stated spectrum (the X-4 paper's section 5 and 6A, or any other).

This is not measured data. The X-4 paper shows its disturbance spectra only in a figure (Fig. 5);
its text states: the power lies below 30 rad/s and decays up to 80 rad/s, the noise floor is about
-30 dB, supply spikes sit between 150 and 300 rad/s, the log-log plot is linear, and -15 dB of
attenuation brings the disturbance down to what the sensor resolves. :data:`X4_SYNTHETIC_SHAPE`
turns these statements into a closed-form spectrum (one-sided, ``unit^2/(rad/s)``, dB re 1):

- disturbance ``D(w)``: a plateau of ``plateau_db`` up to the ``corner``, then a straight line of
  ``slope_db_per_decade`` on the log-log plot (X-4: -15 dB to 30 rad/s, then down 15 dB by 80 rad/s,
  ``-15 / log10(80/30) = -35.2`` dB/decade);
- sensor noise: white, ``floor_db`` (X-4: -30 dB, the plateau 15 dB above it, so that -15 dB of
  attenuation meets the floor; the paper does not print Fig. 5's dB reference, this is synth's reading);
- spikes: sinusoids ``(w, amplitude)`` (X-4: 157, 220 and 283 rad/s, 0.5 rad/s each; the paper gives
  only the 150-300 rad/s range).

The record is ``D`` synthesized with random phases (:func:`synth.sim.signals.psd_signal`) plus white
Gaussian noise of variance ``10^(floor_db/10) pi/dt`` plus the sinusoids, all from one seeded generator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.data.disturbance import DisturbanceRecord, disturbance_from_arrays
from synth.errors import ModelError
from synth.sim.signals import psd_signal

__all__ = ["X4_SEED", "X4_SYNTHETIC_SHAPE", "DisturbanceShape", "synthetic_disturbance_record",
           "synthetic_noise_record"]

#: seed of the X-4 SYNTHETIC records
X4_SEED = 2005


@dataclass(frozen=True)
class DisturbanceShape:
    """A closed-form disturbance spectrum: plateau, corner, log-log decay, white sensor floor, spikes.

    Attributes
    ----------
    plateau_db : float
        Disturbance PSD below the corner [dB re 1 unit^2/(rad/s)].
    corner : float
        End of the plateau [rad/s].
    slope_db_per_decade : float
        Decay of the disturbance above the corner [dB/decade], < 0.
    floor_db : float
        White sensor-noise PSD [dB re 1 unit^2/(rad/s)].
    spikes : tuple of (float, float)
        Sinusoids ``(w [rad/s], amplitude [unit])``.
    unit : str

    Examples
    --------
    >>> s = X4_SYNTHETIC_SHAPE
    >>> round(s.meets_floor, 6), s.attenuation_db, round(s.frequency_above_floor(3.0), 1)
    (80.0, -15.0, 65.8)
    """

    plateau_db: float
    corner: float
    slope_db_per_decade: float
    floor_db: float
    spikes: tuple[tuple[float, float], ...] = ()
    unit: str = "rad/s"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.corner) and self.corner > 0):
            raise ModelError(f"disturbance shape: corner must be > 0 rad/s, got {self.corner!r}")
        if not (math.isfinite(self.slope_db_per_decade) and self.slope_db_per_decade < 0):
            raise ModelError(f"disturbance shape: slope must be < 0 dB/decade, got {self.slope_db_per_decade!r}")
        if not (math.isfinite(self.plateau_db) and math.isfinite(self.floor_db)):
            raise ModelError("disturbance shape: plateau_db and floor_db must be finite")

    def disturbance_db(self, w: Any) -> np.ndarray:
        """``D(w)`` in dB: the plateau, then the log-log line."""
        x = np.log10(np.asarray(w, float) / self.corner)
        return self.plateau_db + self.slope_db_per_decade * np.maximum(x, 0.0)

    def psd(self, w: Any) -> np.ndarray:
        """Disturbance plus sensor floor [unit^2/(rad/s)] (spikes left out)."""
        return 10 ** (self.disturbance_db(w) / 10) + 10 ** (self.floor_db / 10)

    def frequency_above_floor(self, margin_db: float) -> float:
        """Where ``D`` stands ``margin_db`` above the floor [rad/s] (the corner if the plateau is lower)."""
        rise = self.floor_db + margin_db - self.plateau_db
        return self.corner * 10 ** (rise / self.slope_db_per_decade) if rise < 0 else self.corner

    @property
    def meets_floor(self) -> float:
        """Where ``D`` falls to the floor [rad/s]."""
        return self.frequency_above_floor(0.0)

    @property
    def attenuation_db(self) -> float:
        """``floor_db - plateau_db``: the sensitivity that brings the plateau down to the floor [dB]."""
        return self.floor_db - self.plateau_db

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        u = f"dB re 1 ({self.unit})^2/(rad/s)"
        return {"plateau_db": self.plateau_db, "corner": self.corner, "slope_db_per_decade": self.slope_db_per_decade,
                "floor_db": self.floor_db, "spikes": [list(s) for s in self.spikes], "meets_floor": self.meets_floor,
                "attenuation_db": self.attenuation_db,
                "units": {"plateau_db": u, "floor_db": u, "corner": "rad/s", "meets_floor": "rad/s",
                          "slope_db_per_decade": "dB/decade", "spikes": f"[rad/s, {self.unit}]"}}


#: the X-4 paper's stated spectrum (sec. 5, 6A) as a closed form; SYNTHETIC, see the module text
X4_SYNTHETIC_SHAPE = DisturbanceShape(plateau_db=-15.0, corner=30.0, slope_db_per_decade=-15.0 / math.log10(80 / 30),
                                      floor_db=-30.0, spikes=((157.0, 0.5), (220.0, 0.5), (283.0, 0.5)))


def _check(duration: float, dt: float) -> int:
    if not (math.isfinite(dt) and dt > 0 and math.isfinite(duration) and duration > 16 * dt):
        raise ModelError(f"synthetic record: need dt > 0 and duration > 16 dt, got dt={dt!r}, duration={duration!r}")
    return round(duration / dt)


def synthetic_disturbance_record(shape: DisturbanceShape = X4_SYNTHETIC_SHAPE, duration: float = 70.0,
                                 dt: float = 0.001, seed: int = X4_SEED) -> DisturbanceRecord:
    """A SYNTHETIC disturbance record with the spectrum ``shape`` (70 s at 1 kHz, as the paper's tests).

    Examples
    --------
    >>> r = synthetic_disturbance_record(duration=10.0)
    >>> r.name, r.x.size, r.source.startswith("SYNTHETIC")
    ('speed_SYNTHETIC', 10000, True)
    """
    n = _check(duration, dt)
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    w_lo, w_hi = 0.5 * 2 * np.pi / (n * dt), np.pi / dt
    corner = min(max(shape.corner, 1.01 * w_lo), 0.99 * w_hi)
    table = tuple((float(w), float(10 ** (shape.disturbance_db(w) / 10))) for w in (w_lo, corner, w_hi))
    x = psd_signal(table, n, dt, rng)
    x = x + rng.normal(0.0, math.sqrt(10 ** (shape.floor_db / 10) * np.pi / dt), n)
    for w, a in shape.spikes:
        x = x + a * np.sin(w * t + rng.uniform(0, 2 * np.pi))
    return disturbance_from_arrays(t, x, "speed_SYNTHETIC", shape.unit,
                                   f"SYNTHETIC disturbance record (seed {seed})")


def synthetic_noise_record(shape: DisturbanceShape = X4_SYNTHETIC_SHAPE, duration: float = 70.0, dt: float = 0.001,
                           seed: int = X4_SEED + 1) -> DisturbanceRecord:
    """A SYNTHETIC sensor-noise record (the paper's "motor stopped" test): white noise at ``shape.floor_db``.

    Examples
    --------
    >>> r = synthetic_noise_record(duration=100.0)
    >>> round(float(10 * np.log10(np.var(r.x) * r.dt / np.pi)), 1)
    -30.0
    """
    n = _check(duration, dt)
    rng = np.random.default_rng(seed)
    x = rng.normal(0.0, math.sqrt(10 ** (shape.floor_db / 10) * np.pi / dt), n)
    return disturbance_from_arrays(np.arange(n) * dt, x, "speed_noise_SYNTHETIC", shape.unit,
                                   f"SYNTHETIC sensor-noise record (seed {seed})")
