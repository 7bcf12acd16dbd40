"""A record whose output rests on its extreme value: named before a linear model is fitted to it.

A sensor's range or an actuator limit applied before logging cuts the output at one value; a linear fit then reads
the flat tops as the plant's response and returns a model with confident numbers (a 5 %-clipped step train: exit 0,
nothing said). :func:`synth.gap.where.clipping.find_clipping` finds such a clip from the record alone (many samples on
exactly the extreme value of a continuous-valued signal; the plant at rest left out); :func:`with_clipping_note` adds
its sentence to the record's notes, which ``synth identify`` prints and the JSON keeps.
"""

from __future__ import annotations

from dataclasses import replace

from synth.data.record import Record
from synth.gap.where.clipping import record_clipping

__all__ = ["with_clipping_note"]


def with_clipping_note(record: Record) -> Record:
    """``record`` with a note for each clipped end of its output (unchanged when none is).

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 20, 0.01); u = np.sin(t)
    >>> note = with_clipping_note(record_from_arrays(t, u, np.minimum(2 * u, 1.5))).notes[-1]
    >>> note[:64]
    'the output rests on its maximum 1.5 for 463 samples in 4 runs (l'
    >>> with_clipping_note(record_from_arrays(t, u, 2 * u)).notes == record_from_arrays(t, u, 2 * u).notes
    True
    """
    found = [c.describe() for c in record_clipping(record) if c.column == "output"]
    if not found:
        return record
    return replace(record, notes=(*record.notes, *(f"{text}: a linear model fitted to it reads the clipped samples as "
                                                   "the plant's response; fit a part of the record below the limit, "
                                                   "or model the clip" for text in found)))
