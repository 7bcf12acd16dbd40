"""The residual of a model on a measured record, and the size of the gap.

The model is driven by the measured input (held samples, exact delay, see
:func:`synth.ident.simulate.simulate_plant`); the residual is
``e = y_measured - (y_model + offset)``. The gap is measured by

``NRMSE = ||e|| / ||y - mean(y)||`` and ``fit_percent = 100 (1 - NRMSE)``,

so a model that only reproduces the mean of the record scores NRMSE = 1
(fit 0 %) and a perfect model NRMSE = 0 (fit 100 %).

The optional output offset is the operating point the linear model does not
know: a record of a plant whose static map is affine (friction, a dead-zone
intercept) is reproduced by a linear model only up to a constant. With
``offset="fit"`` it is the least-squares constant, ``mean(y - y_model)``;
with ``offset="none"`` it is zero; a number is used as given.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from synth.data.record import Record
from synth.errors import ModelError
from synth.ident.periodic_start import GAP_SETTLED, after_gaps, settling_time
from synth.ident.simulate import simulate_plant
from synth.plant import Plant

__all__ = ["HIDDEN_PULSE_FACTOR", "ModelResidual", "gap_size", "hidden_pulse_warnings", "model_residual",
           "not_judged_warning"]


@dataclass(frozen=True, eq=False)
class ModelResidual:
    """A model's output on a record and its residual.

    Attributes
    ----------
    t, u, y : numpy.ndarray
        Time [s], measured input and measured output.
    y_model : numpy.ndarray
        Model output on the measured input, offset included.
    e : numpy.ndarray
        Residual ``y - y_model``.
    offset : float
        Output offset added to the simulated model (output units).
    offset_mode : str
        ``"fit"``, ``"none"`` or ``"given"``.
    initial : str
        Initial condition of the simulation (``"steady"`` or ``"zero"``).
    nrmse : float
        ``||e|| / ||y - mean(y)||``.
    fit_percent : float
        ``100 (1 - nrmse)``.
    judged : numpy.ndarray of bool or None
        The samples judged (None: all). Not judged: what a gap in the record's log made up, and the model's
        settling after a gap that may hide a command change (:func:`synth.ident.periodic_start.after_gaps`): there
        the model's response is to an edge at the wrong time. ``y_model`` is ``y`` on them (no residual), and
        the offset and the NRMSE are of the other samples; :attr:`left_out` counts them.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 4, 0.01)
    >>> u = np.where(t >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("1/(0.2*s+1)")
    >>> r = model_residual(G, record_from_arrays(t, u, simulate_plant(G, t, u) + 0.5))
    >>> round(r.offset, 6), round(r.nrmse, 9), r.fit_percent
    (0.5, 0.0, 100.0)
    """

    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    y_model: np.ndarray
    e: np.ndarray
    offset: float
    offset_mode: str
    initial: str
    nrmse: float
    fit_percent: float
    judged: np.ndarray | None = None

    @property
    def left_out(self) -> int:
        """Samples not judged (:attr:`judged`)."""
        return 0 if self.judged is None else int(self.t.size - np.count_nonzero(self.judged))

    @property
    def dt(self) -> float:
        """Sample interval [s]."""
        return float((self.t[-1] - self.t[0]) / (self.t.size - 1))

    @property
    def rms(self) -> float:
        """Root mean square of the residual over the judged samples (output units)."""
        return float(np.sqrt(np.sum(self.e**2) / max(self.t.size - self.left_out, 1)))

    def to_dict(self) -> dict[str, Any]:
        """The ``"gap"`` part of the diagnosis JSON.

        Examples
        --------
        >>> import numpy as np
        >>> from synth.data import record_from_arrays
        >>> t = np.arange(0, 2, 0.01)
        >>> u = np.where(t >= 0.5, 1.0, 0.0)
        >>> r = model_residual(Plant.from_string("1/(0.1*s+1)"), record_from_arrays(t, u, 0.9 * u + 0.01 * t))
        >>> sorted(r.to_dict())
        ['fit_percent', 'initial', 'nrmse', 'offset', 'offset_mode', 'rms', 'samples']
        """
        return {"nrmse": self.nrmse, "fit_percent": self.fit_percent, "rms": self.rms, "offset": self.offset,
                "offset_mode": self.offset_mode, "initial": self.initial, "samples": int(self.t.size),
                **({"left_out_for_gaps_in_the_log": self.left_out} if self.left_out else {})}


def gap_size(y: np.ndarray, e: np.ndarray) -> tuple[float, float]:
    """NRMSE ``||e|| / ||y - mean(y)||`` and fit ``100 (1 - NRMSE)`` [%].

    Examples
    --------
    >>> import numpy as np
    >>> gap_size(np.array([0.0, 2.0]), np.array([0.1, -0.1]))
    (0.1, 90.0)
    """
    y = np.asarray(y, float)
    spread = float(np.linalg.norm(y - y.mean()))
    if spread == 0.0:
        raise ModelError("the measured output is constant; the NRMSE is undefined", where="record.y")
    nrmse = float(np.linalg.norm(np.asarray(e, float)) / spread)
    return nrmse, 100.0 * (1.0 - nrmse)


def model_residual(plant: Plant, record: Record, initial: str = "steady", offset: str | float = "fit",
                   burn_in: float = 0.0) -> ModelResidual:
    """Simulate ``plant`` on the record's input and return the residual.

    Parameters
    ----------
    plant : Plant
        The model (exact delay).
    record : Record
        The measured input (the command) and output.
    initial : {"steady", "zero"}
        Initial condition, see :func:`synth.ident.simulate.simulate_plant`.
    offset : "fit", "none" or float
        Output offset (operating point): fitted by least squares, zero, or given.
    burn_in : float
        Seconds at the record's start left out of the residual (an unknown initial state): the model is simulated
        from the start, and the residual, its offset and its size cover the samples after them.

    Returns
    -------
    ModelResidual

    Raises
    ------
    ModelError
        A bad ``offset`` or ``initial``.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 3, 0.01)
    >>> u = np.where(t >= 1, 1.0, 0.0)
    >>> G = Plant.from_string("2/(0.1*s+1)")
    >>> r = model_residual(G, record_from_arrays(t, u, 1.8 * u), offset="none")
    >>> round(r.nrmse, 2) > 0.0, round(float(r.e[-1]), 3)
    (True, -0.2)
    """
    if not isinstance(plant, Plant):
        raise ModelError(f"expected a Plant, got {type(plant).__name__}", where="plant")
    if not isinstance(record, Record):
        raise ModelError(f"expected a Record, got {type(record).__name__}", where="record")
    y_sim = simulate_plant(plant, record.t, record.u, initial=initial)
    if burn_in > 0:
        keep = (record.t - record.t[0]) >= burn_in
        if np.count_nonzero(keep) < 10:
            raise ModelError(f"{burn_in:g} s leaves {int(np.count_nonzero(keep))} samples of the record "
                             f"({record.duration:.4g} s)", where="burn_in")
        y_sim = y_sim[keep]
        record = record.segment(float(record.t[keep][0]), float(record.t[-1]))
    weights = after_gaps(record, plant)
    judged = np.ones(record.n, bool) if weights is None else weights > 0
    if np.count_nonzero(judged) < 10:
        raise ModelError(f"gaps in the log leave {int(np.count_nonzero(judged))} samples of the record to judge "
                         "(each gap's made-up samples, and the model's settling after one that may hide a command "
                         "change, are left out)", where="record")
    if isinstance(offset, str):
        if offset == "fit":
            c, mode = float(np.mean((record.y - y_sim)[judged])), "fit"
        elif offset == "none":
            c, mode = 0.0, "none"
        else:
            raise ModelError(f"must be 'fit', 'none' or a number, got {offset!r}", where="offset")
    else:
        c, mode = float(offset), "given"
        if not np.isfinite(c):
            raise ModelError(f"must be finite, got {offset!r}", where="offset")
    y_model = np.where(judged, y_sim + c, record.y)
    e = record.y - y_model
    nrmse, fit = gap_size(record.y[judged], e[judged])
    return ModelResidual(record.t, record.u, record.y, y_model, e, c, mode, initial, nrmse, fit,
                         None if weights is None else judged)


def not_judged_warning(n: int, dt: float, gaps: int, log: str) -> str:
    """The warning for ``n`` samples (``dt`` apart) that ``gaps`` gaps in ``log`` leave unjudged.

    Examples
    --------
    >>> not_judged_warning(150, 0.01, 2, "the log").split(":")[0]
    '150 samples (1.5 s) not judged'
    """
    return (f"{n} samples ({n * dt:.3g} s) not judged: what {gaps} gap(s) in {log} made up, and the model's "
            "settling after those that may hide a command change (the model's response there is to an edge at the "
            "wrong time)")


HIDDEN_PULSE_FACTOR = 10.0
"""A gap in the log after which the residual's mean square, over the model's settling, is this many times the
record's is named in a warning."""


def hidden_pulse_warnings(record: Record, residual: ModelResidual, plant: Plant) -> list[str]:
    """Warnings for gaps in the log that were judged (the command at one level at both ends, shorter than its
    shortest hold) and right after which the residual is large: such a gap may hide a command change and its
    return, which the log cannot show (a 0.4 s pulse inside a 0.8 s dropout left 94 % of a true model's residual
    in the second after it).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 20, 0.01); u = np.where((t % 4) >= 2, 1.0, 0.0)
    >>> pulse = np.where((t >= 9.2) & (t < 9.5), 1.0, u)  # hidden by the dropout 9.0-9.6 s
    >>> G = Plant.from_string("1/(0.2*s+1)")
    >>> keep = (t <= 9.0) | (t >= 9.6)
    >>> y = simulate_plant(G, t, pulse) + 0.001 * np.random.default_rng(0).normal(size=t.size)
    >>> rec = record_from_arrays(t[keep], u[keep], y[keep])
    >>> hidden_pulse_warnings(rec, model_residual(G, rec), G)[0].split(' is ')[0]
    'the residual in the 1.38 s after the gap in the log at t = 9-9.6 s'
    """
    if not record.gaps:
        return []
    settle = max(float(settling_time(plant, GAP_SETTLED)), 5.0 * residual.dt)
    e2 = residual.e**2
    judged = np.ones(e2.size, bool) if residual.judged is None else residual.judged
    typical = float(np.mean(e2[judged])) if np.any(judged) else 0.0
    out = []
    for before, after in record.gaps:
        window = (residual.t >= after) & (residual.t < after + settle) & judged
        if typical > 0 and np.count_nonzero(window) >= 5 and np.mean(e2[window]) > HIDDEN_PULSE_FACTOR * typical:
            out.append(f"the residual in the {settle:.3g} s after the gap in the log at t = {before:.4g}-{after:.4g} s "
                       f"is {np.mean(e2[window]) / typical:.3g} times its mean square over the record: the gap may "
                       "hide a command change and its return (the command is at one level at both ends)")
    return out
