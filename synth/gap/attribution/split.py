"""The held-out split: which records the fits see, which the models are judged on, and which samples count.

Without a validation record the record is split (``"tail"``: the first ``train_fraction`` trains, the
rest is held out, the models simulated over the whole record; ``"interleaved"``: every second of
``2 blocks`` segments is held out, the fits counting only the others). With one validation record the
fits use the whole record and the validation record is held out; with several (runs of one plant) they
are joined by settling bridges (:mod:`synth.gap.attribution.stitch`), each run held out on its own.
A burn-in leaves the first seconds of every record out of every cost.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from synth.data.record import Record
from synth.errors import ModelError
from synth.gap.attribution.stitch import settle_time, stitch_runs
from synth.ident.periodic_start import after_gaps
from synth.plant import Plant

__all__ = ["GAPS_KEPT", "HeldoutSplit", "block_ids", "split_heldout"]


GAPS_KEPT = 0.25
"""Least share of the training part that gaps in the log may leave to judge: with less, the fits see a few
seconds of the record (a 28.5 s dropout in a 30 s training half gave shrinkages of -5e5 and -3e9, and exit 0)."""


def block_ids(n_held: int, blocks: int) -> np.ndarray:
    """Segment index of each of ``n_held`` samples cut into ``blocks`` contiguous segments of about equal length.

    Examples
    --------
    >>> block_ids(7, 3).tolist()
    [0, 0, 1, 1, 1, 2, 2]
    """
    edges = np.linspace(0, n_held, blocks + 1).round().astype(int)
    return np.repeat(np.arange(blocks), np.diff(edges))


@dataclass(frozen=True, eq=False)
class HeldoutSplit:
    """What the fits see and what the models are judged on.

    Attributes
    ----------
    train : Record
        The record the fits run on (from rest at its first sample).
    evaluated : Record
        The record every model is simulated on: the record itself (split), the validation record, or
        the validation runs joined by settling bridges.
    held : numpy.ndarray of bool
        Held-out samples of ``evaluated``.
    train_mask : numpy.ndarray of bool or None
        Samples of ``train`` that count in the fits' cost (``None``: all).
    groups : numpy.ndarray or None
        Validation run of each held-out sample (several runs), else ``None``.
    settled : numpy.ndarray of bool
        Samples of ``evaluated`` past the burn-in (where the noise floor is estimated).
    runs : int
        Validation runs (1 for one record or a split record).
    validation : bool
        Whether the held-out data is a validation record (else a part of the record).
    mode : str
        ``"tail"``, ``"interleaved"`` or ``"validation"``.
    """

    train: Record
    evaluated: Record
    held: np.ndarray
    train_mask: np.ndarray | None
    groups: np.ndarray | None
    settled: np.ndarray
    runs: int
    validation: bool
    mode: str

    @property
    def n_held(self) -> int:
        """Number of held-out samples."""
        return int(self.held.sum())

    @property
    def n_train(self) -> int:
        """Number of training samples that count in the fits."""
        return int(self.train.n if self.train_mask is None else self.train_mask.sum())


def split_heldout(plant: Plant, record: Record, validate: Record | Sequence[Record] | None, split: str = "tail",
                  train_fraction: float = 0.5, blocks: int = 10, burn_in: float = 0.0) -> HeldoutSplit:
    """Split ``record`` (or hold out ``validate``) for :func:`synth.gap.attribution.heldout.diagnose_effects`.

    Parameters
    ----------
    plant : Plant
        The nominal model (its settling time spaces several validation runs).
    record : Record
        The measured record.
    validate : Record, sequence of Record, or None
        Held-out record(s); a sequence of one is that record.
    split, train_fraction, blocks, burn_in
        As :class:`synth.gap.attribution.heldout.DiagnoseOptions`.

    Returns
    -------
    HeldoutSplit

    Raises
    ------
    ModelError
        A burn-in that leaves fewer than 20 training samples, or fewer than ``10 blocks`` held-out
        samples (in any run).

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> t = np.arange(0, 4, 0.01); rec = record_from_arrays(t, (t >= 1).astype(float), t)
    >>> sp = split_heldout(Plant.from_string("1/(s+1)"), rec, None)
    >>> sp.train.n, sp.evaluated.n, sp.n_held, sp.mode
    (200, 400, 200, 'tail')
    >>> split_heldout(Plant.from_string("1/(s+1)"), rec, None, split="interleaved").n_train
    200
    """
    runs: list[Record] | None = list(validate) if isinstance(validate, list | tuple) else None
    if runs is not None and len(runs) < 2:
        validate, runs = (runs[0] if runs else None), None
    train_mask: np.ndarray | None = None
    joined = None
    if validate is None and split == "tail":
        k = round(train_fraction * record.n)
        train = record.segment(float(record.t[0]), float(record.t[k - 1]))  # keeps its notes and gaps
        evaluated = record
        held = np.arange(record.n) >= k
    elif validate is None:  # interleaved: odd segments held out, the fits count the even ones
        train = evaluated = record
        held = block_ids(record.n, 2 * blocks) % 2 == 1
        train_mask = ~held
    elif runs is None:
        train, evaluated = record, validate
        held = np.ones(validate.n, bool)
    else:
        train = record
        joined = stitch_runs(runs, settle_time(plant))
        evaluated = Record(joined.t, joined.u, joined.y, record.input, record.output, source="validation runs")
        held = joined.run >= 0
    judged_tr, judged_ev = after_gaps(train, plant), after_gaps(evaluated, plant)  # None without gaps
    if judged_tr is not None:  # what a gap in the log made up, and the settling after a change one may hide
        share = float(np.mean(judged_tr > 0))
        if share < GAPS_KEPT:
            raise ModelError(f"gaps in the log leave {share:.1%} of the training part to judge (their made-up "
                             "samples, and the model's settling after those that may hide a command change, are "
                             f"left out; at least {GAPS_KEPT:.0%} is needed): cut the record to a part without "
                             "such gaps, or give --validate", where=train.source or "record")
        train_mask = judged_tr > 0 if train_mask is None else train_mask & (judged_tr > 0)
    if judged_ev is not None:
        gapped = int(np.sum(held & (judged_ev <= 0)))
        held = held & (judged_ev > 0)
    t_tr, t_ev = train.t, evaluated.t
    if burn_in > 0.0:
        settled_tr = t_tr >= t_tr[0] + burn_in
        train_mask = settled_tr if train_mask is None else train_mask & settled_tr
        held = held & ((t_ev >= t_ev[0] + burn_in) if joined is None else (np.nan_to_num(joined.since_start,
                                                                                           nan=-1.0) >= burn_in))
        if int(train_mask.sum()) < 20:
            raise ModelError(f"a burn-in of {burn_in:g} s leaves too few training samples", where="burn_in")
    if judged_tr is not None and int(train_mask.sum()) < 20:
        raise ModelError(f"gaps in the log leave {int(train_mask.sum())} training samples",
                         where=train.source or "record")
    n_held = int(held.sum())
    groups = None if joined is None else joined.run[held]  # the held-out run of each held-out sample
    for r in range(1 if runs is None else len(runs)):
        n_r = n_held if groups is None else int(np.sum(groups == r))
        if n_r < 10 * blocks:
            where = (evaluated.source or "record") if runs is None else f"validate run {r + 1}"
            because = (f" (gaps in the log left out {gapped}: their made-up samples and the model's settling after "
                       "those that may hide a command change)" if judged_ev is not None and gapped else "")
            raise ModelError(f"{n_r} held-out samples are too few for the held-out test ({blocks} segments of at least "
                             f"10 samples: {10 * blocks}){because}; record longer, or give --validate with a record "
                             "of its own", where=where)
    settled = (t_ev >= t_ev[0] + burn_in) if runs is None else held
    if judged_ev is not None:
        settled = settled & (judged_ev > 0)
    return HeldoutSplit(train, evaluated, held, train_mask, groups, settled, 1 if runs is None else len(runs),
                        validate is not None, split if validate is None else "validation")
