"""What a simulation gives: the time series of one run (:class:`SimResult`) or of a batch
(:class:`BatchResult`), in absolute units, with each block's activity per step.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from synth.sim.blocks import Block, Delay
from synth.sim.folding import fold_counts
from synth.sim.layout import SENSOR_BIT

__all__ = ["BatchResult", "SimResult"]


@dataclass(eq=False)
class SimResult:
    """Time series of one simulated run (absolute units).

    Attributes
    ----------
    t : ndarray
        Time (s).
    reference : ndarray
        Reference (closed loop) or the applied input command (open loop).
    output : ndarray
        True plant output (with any output disturbance).
    measured : ndarray
        Output of the sensor chain (what the controller sees).
    command : ndarray
        Controller output plus the operating-point input (closed loop), or the input (open loop).
    actuator : ndarray
        Output of the actuator chain's blocks (before trailing linear blocks folded into the plant).
    flags : ndarray of int32
        Per step, bit ``i`` set when actuator block ``i`` was active, bit ``16 + i`` for sensor block ``i``.
    dt : float
    actuator_blocks, sensor_blocks : list of str
        Block types in chain order (for reading ``flags``).
    actuator_flags, sensor_flags : list of str or None
        Each block's metric name (``"rate_limited"``, ``"saturated"``, ...).
    label : str
    actuator_rest : float
        Actuator output at rest before ``t = 0`` (plant input units).
    """

    t: np.ndarray
    reference: np.ndarray
    output: np.ndarray
    measured: np.ndarray
    command: np.ndarray
    actuator: np.ndarray
    flags: np.ndarray
    dt: float
    actuator_blocks: list[str]
    sensor_blocks: list[str]
    actuator_flags: list[str | None]
    sensor_flags: list[str | None]
    label: str = ""
    actuator_rest: float = float("nan")

    def active(self, name: str) -> np.ndarray:
        """Steps where any block with metric ``name`` (e.g. ``"saturated"``) was active.

        Examples
        --------
        >>> from synth.plant import Plant
        >>> from synth.sim.blocks import Saturation
        >>> from synth.sim.simulator import simulate_open_loop
        >>> r = simulate_open_loop(Plant.from_string("1/(s+1)"), [0.0, 2.0, 2.0], 0.1,
        ...                        actuator=[Saturation(-1, 1)])
        >>> r.active("saturated").tolist()
        [False, True, True]
        """
        mask = np.zeros(self.t.size, dtype=bool)
        for i, f in enumerate(self.actuator_flags):
            if f == name:
                mask |= (self.flags >> i) & 1 == 1
        for i, f in enumerate(self.sensor_flags):
            if f == name:
                mask |= (self.flags >> (SENSOR_BIT + i)) & 1 == 1
        return mask

    def time_active(self, name: str) -> float:
        """Seconds during which blocks with metric ``name`` were active.

        Examples
        --------
        >>> from synth.plant import Plant
        >>> from synth.sim.blocks import Saturation
        >>> from synth.sim.simulator import simulate_open_loop
        >>> r = simulate_open_loop(Plant.from_string("1/(s+1)"), [0.0, 2.0, 2.0], 0.1,
        ...                        actuator=[Saturation(-1, 1)])
        >>> round(r.time_active("saturated"), 6)
        0.2
        """
        return float(np.count_nonzero(self.active(name)) * self.dt)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (the time series are in :meth:`series`).

        Examples
        --------
        >>> from synth.plant import Plant
        >>> from synth.sim.simulator import simulate_open_loop
        >>> r = simulate_open_loop(Plant.from_string("1/(s+1)"), [0.0, 1.0, 1.0], 0.1)
        >>> r.to_dict()["steps"]
        3
        """
        names = sorted({f for f in self.actuator_flags + self.sensor_flags if f})
        return {"label": self.label, "dt": self.dt, "steps": int(self.t.size), "t_end": float(self.t[-1]),
                "actuator_blocks": self.actuator_blocks, "sensor_blocks": self.sensor_blocks,
                "time_active": {n: self.time_active(n) for n in names},
                "output_final": float(self.output[-1]), "actuator_rest": self.actuator_rest}

    def series(self) -> dict[str, np.ndarray]:
        """Columns for a CSV file.

        Examples
        --------
        >>> from synth.plant import Plant
        >>> from synth.sim.simulator import simulate_open_loop
        >>> r = simulate_open_loop(Plant.from_string("1/(s+1)"), [0.0, 1.0], 0.1)
        >>> list(r.series())
        ['t', 'reference', 'output', 'measured', 'command', 'actuator']
        """
        cols = {"t": self.t, "reference": self.reference, "output": self.output, "measured": self.measured,
                "command": self.command, "actuator": self.actuator}
        for name in sorted({f for f in self.actuator_flags + self.sensor_flags if f}):
            cols[name] = self.active(name).astype(int)
        return cols


@dataclass(eq=False)
class BatchResult:
    """Time series of a batch of variants: arrays of shape ``(variants, steps)``.

    ``result[i]`` is the :class:`SimResult` of variant ``i``.

    Examples
    --------
    >>> from synth.controllers import Controller
    >>> from synth.plant import Plant
    >>> from synth.sim.loops import NonlinearLoop
    >>> from synth.sim.simulator import simulate_batch
    >>> base = NonlinearLoop(Plant.from_string("10/(s+10)"), Controller("P", {"kp": 1}), label="kp=1")
    >>> batch = simulate_batch([base, base.with_gain("kp", 4)], 1.0, 0.5)
    >>> len(batch), batch[0].label, batch.output.shape
    (2, 'kp=1', (2, 501))
    """

    t: np.ndarray
    reference: np.ndarray
    output: np.ndarray
    measured: np.ndarray
    command: np.ndarray
    actuator: np.ndarray
    flags: np.ndarray
    dt: float
    loops: list[Any]
    actuator_rest: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __len__(self) -> int:
        return self.output.shape[0]

    def __getitem__(self, i: int) -> SimResult:
        chains = self._chains(i)
        ref = self.reference[i if self.reference.shape[0] > 1 else 0]
        return SimResult(self.t, ref, self.output[i], self.measured[i], self.command[i], self.actuator[i],
                         self.flags[i], self.dt, [b.kind for b in chains[0]], [b.kind for b in chains[1]],
                         [b.flag for b in chains[0]], [b.flag for b in chains[1]],
                         getattr(self.loops[i], "label", ""),
                         float(self.actuator_rest[i]) if self.actuator_rest.size else float("nan"))

    def _chains(self, i: int) -> tuple[list[Block], list[Block]]:
        loop = self.loops[i]
        act = [b for b in loop.actuator if not isinstance(b, Delay)]
        sen = [b for b in loop.sensor if not isinstance(b, Delay)]
        folded_a, folded_s = fold_counts(act, sen)
        return act[: len(act) - folded_a], sen[folded_s:]

    def __iter__(self):
        return (self[i] for i in range(len(self)))
