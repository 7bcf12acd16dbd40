"""Effects driven by a measured auxiliary signal (a column named with ``--aux``).

=========================  ========  =======================================================  ==============
effect                     side      augmented model                                         parameters
=========================  ========  =======================================================  ==============
``measured_sag(V)``        input     ``u + sag (u - u_rest) (V / V_nom - 1)``: the drive       ``sag``
                                     scales with the measured supply ``V``
``aux_input(d)``           input     ``u + gain (d - d_0)``: a measured disturbance enters    ``gain``
                                     at the input
=========================  ========  =======================================================  ==============

``sag = 1`` is a drive proportional to the measured supply (``V_nom``: the largest measured value,
the unloaded battery; ``u_rest``: the smallest command, where the drive delivers nothing). Both are
basis parameters (least squares) and are off at 0.

The effect reads its channel from the records it is bound to (:meth:`AuxEffect.bind`, done by
:func:`synth.gap.diagnose.diagnose` with the record and the validation records): the command it is
given is matched to a bound record's command (the whole record or its first part, as the held-out
split trains on). A command matched to none (validation runs joined by bridges) is a
:class:`~synth.errors.ModelError`: the candidate is left out there.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from synth.errors import DataError, ModelError
from synth.gap.effects.base import Effect, Params

if TYPE_CHECKING:
    from synth.data.record import Record
    from synth.plant import Plant

__all__ = ["AuxEffect", "AuxInputEffect", "MeasuredSagEffect"]


@dataclass(frozen=True)
class AuxEffect(Effect):
    """Base of the effects driven by a measured channel ``channel`` of the record (``name(channel)``).

    Attributes
    ----------
    channel : str
        The aux column.
    signals : tuple of (numpy.ndarray, numpy.ndarray)
        ``(command, channel)`` of each bound record.
    """

    channel: str = ""
    signals: tuple[tuple[np.ndarray, np.ndarray], ...] = field(default=(), compare=False, repr=False)
    aux_driven: ClassVar[bool] = True
    excluded_because: ClassVar[str] = "needs a measured channel: a candidate by default for each --aux column"

    @property
    def label(self) -> str:
        return f"{self.name}({self.channel})"

    @property
    def aux_channel(self) -> str | None:
        return self.channel

    def bind(self, records: Sequence[Record], plant: Plant | None = None) -> AuxEffect:
        """The effect reading its channel from ``records`` (the record first, then validation records).

        Raises
        ------
        DataError
            A record without the channel (one line naming it).

        Examples
        --------
        >>> from synth.data import record_from_arrays
        >>> t = np.arange(6.0); r = record_from_arrays(t, t, t, aux={"V": 4.0 - 0.1 * t})
        >>> eff = MeasuredSagEffect("V").bind([r])
        >>> eff.input_basis(t[:3], 1.0, {})[0].round(3).tolist()  # a prefix of the record's command
        [0.0, -0.025, -0.1]
        """
        signals = []
        for r in records:
            if self.channel not in r.aux:
                raise DataError(f"no column {self.channel!r} among the aux channels {sorted(r.aux)} (give it with "
                                "--aux)", where=f"{r.source} {self.label}")
            signals.append((np.asarray(r.u, float), np.asarray(r.aux[self.channel], float)))
        return replace(self, signals=tuple(signals))

    def measured(self, u: np.ndarray) -> tuple[np.ndarray, int]:
        """The channel on the samples of command ``u`` and the index of the bound record it came from."""
        n = u.size
        for j, (ur, ar) in enumerate(self.signals):
            if ur.size == n and np.array_equal(ur, u):
                return ar, j
        for j, (ur, ar) in enumerate(self.signals):
            if ur.size > n and np.array_equal(ur[:n], u):
                return ar[:n], j
        raise ModelError(f"no measured {self.channel!r} for this command (runs joined by bridges, or a command "
                         "changed by another effect)", where=f"effect {self.label}")

    def off(self) -> Params:
        return {name: 0.0 for name in self.basis_names}


@dataclass(frozen=True)
class MeasuredSagEffect(AuxEffect):
    """Drive proportional to the measured supply: ``u + sag (u - u_rest) (V / V_nom - 1)``.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 4, 0.01); u = np.where(t >= 1, 1.0, 0.0); V = np.where(t >= 2, 3.0, 4.0)
    >>> eff = MeasuredSagEffect("V").bind([record_from_arrays(t, u, u, aux={"V": V})])
    >>> y = eff.apply(Plant.from_string("1/(0.01*s+1)"), t, u, {"sag": 1.0})
    >>> round(float(y[150]), 3), round(float(y[-1]), 3)  # 3/4 of the drive once the supply sags
    (1.0, 0.75)
    """

    name: ClassVar[str] = "measured_sag"
    parameter_names: ClassVar[tuple[str, ...]] = ("sag",)
    basis_names: ClassVar[tuple[str, ...]] = ("sag",)

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        v, _ = self.measured(np.asarray(u, float))
        u_ref, v_ref = self.signals[0]
        v_nom = float(np.max(v_ref))
        if not v_nom > 0:
            raise ModelError(f"the measured {self.channel!r} is not positive", where=f"effect {self.label}")
        return [(u - float(np.min(u_ref))) * (v / v_nom - 1.0)]


@dataclass(frozen=True)
class AuxInputEffect(AuxEffect):
    """A measured disturbance entering at the input: ``u + gain (d - d_0)``, ``d_0`` its first bound value.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 2, 0.01); u = np.where(t >= 0.5, 1.0, 0.0); d = np.where(t >= 1, 2.0, 0.0)
    >>> eff = AuxInputEffect("load").bind([record_from_arrays(t, u, u, aux={"load": d})])
    >>> round(float(eff.apply(Plant.from_string("3/(0.01*s+1)"), t, u, {"gain": -0.5})[-1]), 3)  # 3 (1 - 1)
    0.0
    """

    name: ClassVar[str] = "aux_input"
    parameter_names: ClassVar[tuple[str, ...]] = ("gain",)
    basis_names: ClassVar[tuple[str, ...]] = ("gain",)

    def input_basis(self, u: np.ndarray, dt: float, params: Params) -> list[np.ndarray]:
        d, _ = self.measured(np.asarray(u, float))
        return [d - float(self.signals[0][1][0])]
