"""A SYNTHETIC X-4 rotor step-train record, generated from the seed paper's model (section 4B).

This is not measured data. It reproduces the identification experiment the
paper describes, from the paper's own identified model:

- plant (eq. 5): ``H = 23(s+0.43)/((s+9.6)(s+0.54))`` [rad/s per PWM unit];
- speed sensor (eq. 4): ``F = 442/((s+45)(s+9.7))``; its DC gain is
  442/436.5 = 1.0126, so the logged speed reads 1.26 % high in steady state;
- a 20 ms delay (plant plus processing) in front of both;
- input: a square wave between 175 and 225 PWM, 70 periods of 6 s (3 s low,
  then 3 s high), sampled at 1 kHz: 420,000 samples, 70 up steps and 69 down
  steps (the 70th down step would fall on t = 420 s, one sample after the end);
- operating point: eq. 5 is incremental, so the logged speed is
  ``820 + F H exp(-0.02 s) (u - 175)`` rad/s, which puts 175 PWM at 820 rad/s
  (the paper's 820 -> 920 rad/s; the model's step is 50 * 1.908 * 1.0126 = 96.6 rad/s);
- noise: white Gaussian, standard deviation 1.25 rad/s. The paper gives
  "10 rad/s peak-to-peak" and an SNR of 38 dB; reading peak-to-peak as +-4
  standard deviations (exceeded by 6e-5 of the samples) gives 1.25 rad/s, and
  a 100 rad/s step over 1.25 rad/s is 38.1 dB, so both statements agree.

The record starts at rest at 175 PWM. The CSV is not shipped: :func:`x4_step_train_path`
writes it on first use into a cache folder and rewrites it when its content
hash or the generator version differs.

Run ``python -m synth.ident.x4_record OUT.csv`` to write a copy.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

import numpy as np

from synth.data.record import Record, record_from_arrays
from synth.disk_cache import cache_dir
from synth.ident.simulate import simulate_plant
from synth.plant import Plant, Signal

__all__ = [
    "COLUMNS", "DELAY", "FILENAME", "FS", "NOISE_STD", "PERIOD", "PERIODS", "PLANT", "SEED", "SENSOR",
    "SPEED_AT_LOW", "STRUCTURE", "TRUTH", "VERSION", "main", "write_x4_csv", "x4_step_train",
    "x4_step_train_path",
]

PLANT = "23*(s+0.43)/((s+9.6)*(s+0.54))"
SENSOR = "442/((s+45)*(s+9.7))"
DELAY = 0.02
NOISE_STD = 1.25
PERIODS = 70
PERIOD = 6.0
FS = 1000.0
PWM_LOW, PWM_HIGH = 175.0, 225.0
SPEED_AT_LOW = 820.0
SEED = 2007
#: true parameter values for the structure ``k*(s+z)/((s+p1)*(s+p2))`` and the delay
TRUTH = {"k": 23.0, "z": 0.43, "p1": 9.6, "p2": 0.54, "delay": DELAY}
STRUCTURE = "k*(s+z)/((s+p1)*(s+p2))"
COLUMNS = ("time_s", "pwm_SYNTHETIC", "speed_SYNTHETIC")
VERSION = "x4-step-train-1"
FILENAME = "x4_step_train_SYNTHETIC.csv"


def x4_step_train(seed: int = SEED, noise_std: float = NOISE_STD, periods: int = PERIODS) -> Record:
    """The SYNTHETIC X-4 step train as a :class:`~synth.data.Record` (in memory).

    Parameters
    ----------
    seed : int
        Seed of the noise generator (``numpy.random.default_rng``).
    noise_std : float
        Standard deviation of the white Gaussian output noise [rad/s]; 0 for a noise-free record.
    periods : int
        Number of 6 s periods (70 in the paper).

    Examples
    --------
    >>> r = x4_step_train(periods=2)
    >>> r.n, r.dt, float(r.u[2999]), float(r.u[3000])
    (12000, 0.001, 175.0, 225.0)
    >>> round(float(x4_step_train(noise_std=0.0, periods=1).y[0]), 6)
    820.0
    """
    n = round(periods * PERIOD * FS)
    t = np.arange(n) / FS
    phase = np.mod(np.arange(n), round(PERIOD * FS))
    u = np.where(phase >= round(PERIOD * FS / 2), PWM_HIGH, PWM_LOW)
    model = Plant.from_string(PLANT).series(Plant.from_string(SENSOR)).with_delay(DELAY)
    y = SPEED_AT_LOW + simulate_plant(model, t, u - PWM_LOW, initial="steady")
    if noise_std > 0:
        y = y + np.random.default_rng(seed).normal(0.0, noise_std, n)
    return record_from_arrays(t, u, y, Signal(COLUMNS[1], "PWM"), Signal(COLUMNS[2], "rad/s"),
                              source=f"SYNTHETIC X-4 step train (seed {seed})", names=COLUMNS)


def write_x4_csv(path: str | Path, seed: int = SEED, periods: int = PERIODS) -> Path:
    """Write the SYNTHETIC record as CSV (header ``time_s,pwm_SYNTHETIC,speed_SYNTHETIC``).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = write_x4_csv(pathlib.Path(tempfile.mkdtemp()) / "x4.csv", periods=1)
    >>> p.read_text().splitlines()[:2]
    ['time_s,pwm_SYNTHETIC,speed_SYNTHETIC', '0.000,175,820.2018']
    """
    path = Path(path)
    r = x4_step_train(seed, periods=periods)
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = [",".join(COLUMNS)]
    lines += [f"{a:.3f},{b:.0f},{c:.4f}" for a, b, c in zip(r.t, r.u, r.y)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


_HASHED: dict[tuple[str, int, int], str] = {}
"""SHA-256 of files already hashed in this process, by (path, size, modification time in ns)."""


def _sha256(path: Path) -> str:
    st = path.stat()
    key = (str(path.resolve()), st.st_size, st.st_mtime_ns)
    if key not in _HASHED:
        _HASHED[key] = hashlib.sha256(path.read_bytes()).hexdigest()
    return _HASHED[key]


def x4_step_train_path(folder: str | Path | None = None) -> Path:
    """Path of the SYNTHETIC X-4 step-train CSV, generated deterministically if missing or stale.

    A sidecar ``.json`` holds the generator version, the seed and the file's
    SHA-256; the CSV is rewritten when either differs (about 2 s).

    Examples
    --------
    >>> x4_step_train_path().name
    'x4_step_train_SYNTHETIC.csv'
    """
    folder = Path(folder) if folder is not None else cache_dir()
    path = folder / FILENAME
    meta_path = path.with_suffix(".json")
    meta = {"version": VERSION, "seed": SEED}
    if path.exists() and meta_path.exists():
        try:
            stored = json.loads(meta_path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            stored = {}
        if {k: stored.get(k) for k in meta} == meta and stored.get("sha256") == _sha256(path):
            return path
    folder.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".tmp{os.getpid()}")
    write_x4_csv(tmp)
    os.replace(tmp, path)
    info = {**meta, "sha256": _sha256(path), "SYNTHETIC": True, "plant": PLANT, "sensor": SENSOR, "delay": DELAY,
            "noise": f"white Gaussian, std {NOISE_STD} rad/s", "offset": f"{SPEED_AT_LOW} rad/s at {PWM_LOW} PWM",
            "columns": list(COLUMNS), "note": "generated by synth.ident.x4_record from the seed paper's model"}
    meta_path.write_text(json.dumps(info, indent=2) + "\n", encoding="utf-8")
    return path


def main(argv: list[str] | None = None) -> int:
    """``python -m synth.ident.x4_record OUT.csv``: write the SYNTHETIC record to OUT.csv."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        sys.stderr.write("usage: python -m synth.ident.x4_record OUT.csv\n")
        return 2
    write_x4_csv(args[0])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
