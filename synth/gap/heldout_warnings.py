"""Why a held-out test may not see an effect: a held-out command that barely moves, or one that excites other
frequencies than the training part (a sweep cut in two)."""

from __future__ import annotations

import numpy as np

from synth.data.record import Record

__all__ = ["heldout_warnings"]


def heldout_warnings(record: Record, validate: Record | None = None, split: str = "tail",
                     train_fraction: float = 0.5, min_span: float = 0.05) -> list[str]:
    """Why the held-out test may not see an effect: a held-out command that barely moves.

    An effect of the dynamics (a delay, a lag, a limit) shows where the command changes. When
    the held-out part's command spans less than ``min_span`` of the record's (a single step
    early in a record split at its tail; a validation record at one operating point), the
    held-out test judges only the steady state and can neither confirm nor reject such an
    effect.

    Parameters
    ----------
    record, validate : Record
        As given to :func:`diagnose`.
    split : {"tail", "interleaved"}
    train_fraction : float
    min_span : float
        Smallest held-out command span, relative to the record's, that counts as excitation.

    Returns
    -------
    list of str
        Plain sentences; empty when the held-out part is excited.

    Examples
    --------
    >>> import numpy as np
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 10, 0.01); u = np.where(t >= 2, 1.0, 0.0)
    >>> heldout_warnings(record_from_arrays(t, u, u))[0][:58]
    'the held-out part (t >= 5 s, the tail of the record) has a'
    >>> heldout_warnings(record_from_arrays(t, u, u), split="interleaved")
    []
    """
    span = float(np.ptp(record.u))
    k = round(train_fraction * record.n)  # the tail split's first held-out sample
    if validate is not None:
        held, where = validate.u, "the validation record"
    elif split == "tail":
        held, where = record.u[k:], f"the held-out part (t >= {record.t[k]:.4g} s, the tail of the record)"
    else:
        return []
    held_span = float(np.ptp(held)) if held.size else 0.0
    if span > 0.0 and held_span >= min_span * span:
        if validate is None:
            apart = _excited_apart(record.u[:k], held, record.dt)
            if apart:
                return [f"the training part (t < {record.t[k]:.4g} s) and {where} excite different frequencies "
                        f"({apart}; a sweep cut in two): a model fitted on the one is judged on the other, and a "
                        "parameter the training part does not excite reads as a gap; give --split interleaved"]
        return []
    return [f"{where} has a command that spans {100 * held_span / span if span > 0 else 0.0:.2g} % of the "
            "record's: the held-out test judges only the steady state there and cannot see an effect of the "
            "transients (a delay, a lag, a limit); give --validate with steps, or --split interleaved"]


def _excited_apart(train: np.ndarray, held: np.ndarray, dt: float, share: float = 0.9) -> str:
    """Where the two parts' input power lies, in words, when most of the held-out part's lies beyond where ``share``
    of the training part's does (``""`` otherwise; a stationary input puts about ``1 - share`` there)."""
    def spectrum(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p = np.abs(np.fft.rfft(x - np.mean(x))) ** 2
        return 2.0 * np.pi * np.fft.rfftfreq(x.size, dt), np.cumsum(p) / max(float(np.sum(p)), 1e-300)

    (w_a, c_a), (w_b, c_b) = spectrum(train), spectrum(held)
    if c_a.size < 8 or c_b.size < 8 or c_a[-1] == 0.0 or c_b[-1] == 0.0:
        return ""
    a_hi, a_lo = float(np.interp(share, c_a, w_a)), float(np.interp(1.0 - share, c_a, w_a))
    above = 1.0 - float(np.interp(a_hi, w_b, c_b))
    below = float(np.interp(a_lo, w_b, c_b))
    if above > 0.5:
        return (f"{100 * share:.0f} % of the training part's input power lies below {a_hi:.3g} rad/s, {100 * above:.0f} % "
                f"of the held-out part's above it")
    if below > 0.5:
        return (f"{100 * share:.0f} % of the training part's input power lies above {a_lo:.3g} rad/s, {100 * below:.0f} % "
                f"of the held-out part's below it")
    return ""
