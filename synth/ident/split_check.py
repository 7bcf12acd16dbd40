"""The split-record check: do fits of separate parts of a record scatter as their stds say?

A fit's std column assumes white residuals. Coloured noise, a slow drift or dynamics that change over the
record make the estimates scatter more, and a cycle average can hide the cause from the residuals (a random
walk drift: the residuals of the average look white while the estimates scatter 2.7-4.4 times more than their
stds). The check measures the scatter instead: the record is cut into ``parts`` contiguous parts of equal
length, each is identified as the whole was, and each parameter's part estimates are compared with their own
stds,

    chi2 = sum_k ((theta_k - theta_w) / sigma_k)^2,   theta_w the inverse-variance weighted mean,

which has ``parts - 1`` degrees of freedom when the stds are right. ``ratio = sqrt(chi2 / (parts - 1))`` is how
many times the scatter exceeds what the stds say; a parameter whose chi2 is significant (p below 0.001, divided
by the number of parameters tested) makes the verdict "stds too small".
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import pairwise
from typing import Any

import numpy as np

from synth.data.record import Record
from synth.distributions import chi2_sf
from synth.errors import DataError, SynthError
from synth.ident.exchangeable import align_labels, exchangeable_groups
from synth.ident.structure import parse_structure

__all__ = ["SplitCheck", "split_check"]

#: family-wise significance of the test over all parameters
ALPHA = 1e-3


@dataclass(frozen=True)
class SplitCheck:
    """Fits of ``parts`` contiguous parts of a record against their own stds.

    Attributes
    ----------
    parts : int
        Parts the record was cut into.
    part_seconds : float
        Length of each part [s].
    fitted : int
        Parts whose fit succeeded with every parameter regular (no weakly identifiable one, every std finite):
        the test needs 3.
    estimates, stds : dict of str to list of float
        Each parameter's estimate and std in each fitted part (delay included when it was fitted).
    ratio : dict of str to float
        ``sqrt(chi2 / (fitted - 1))``: the part estimates' scatter over what their stds say.
    p_value : dict of str to float
        Probability of a chi2 this large if the stds were right.
    verdict : str
        ``"stds too small"``, ``"consistent"`` or ``"undetermined"`` (fewer than 3 parts fitted).
    failures : list of str
        Why a part's fit failed.

    Examples
    --------
    >>> c = SplitCheck(5, 40.0, 5, {"K": [2.0] * 5}, {"K": [0.01] * 5}, {"K": 0.0}, {"K": 1.0}, "consistent")
    >>> c.text().split(":")[0]
    'split check over 5 parts of 40 s'
    """

    parts: int
    part_seconds: float
    fitted: int
    estimates: dict[str, list[float]]
    stds: dict[str, list[float]]
    ratio: dict[str, float]
    p_value: dict[str, float]
    verdict: str
    failures: list[str] = field(default_factory=list)

    def text(self) -> str:
        """One line: the verdict and what it rests on."""
        head = f"split check over {self.parts} parts of {self.part_seconds:.3g} s"
        if self.verdict == "undetermined":
            return (f"{head}: undetermined, only {self.fitted} of the part fits succeeded with regular parameters (3 needed)"
                    + (f"; {self.failures[0]}" if self.failures else ""))
        rows = ", ".join(f"{k} {self.ratio[k]:.2g}x (p {_p(self.p_value[k])})" for k in self.ratio)
        if self.verdict == "stds too small":
            return (f"{head}: the part estimates scatter more than their stds say ({rows}); the stds are too "
                    f"small by about the largest ratio (coloured noise, drift or dynamics that change over the "
                    f"record)")
        return f"{head}: the part estimates scatter as their stds say ({rows})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields, with the one-line ``text``."""
        return {"parts": self.parts, "part_seconds": self.part_seconds, "fitted": self.fitted,
                "estimates": self.estimates, "stds": self.stds, "ratio": self.ratio, "p_value": self.p_value,
                "verdict": self.verdict, "failures": list(self.failures), "text": self.text()}


def _p(p: float) -> str:
    return f"{p:.2g}" if p >= 1e-300 else "< 1e-300"


def split_check(record: Record, structure: Any, delay: str | float | None = None, sensor: Any = None,
                average: str = "auto", parts: int = 5, reference: dict[str, float] | None = None) -> SplitCheck:
    """Identify ``parts`` contiguous parts of ``record`` as :func:`~synth.ident.identification.identify` would
    the whole, and test whether the part estimates scatter as their stds say.

    Parameters
    ----------
    record : Record
    structure, delay, sensor, average
        As given to :func:`~synth.ident.identification.identify` for the whole record.
    parts : int
        Number of parts, 3 or more.
    reference : dict, optional
        The whole record's fitted parameters: parameters that play the same role (the two poles of
        ``k/((s+p1)*(s+p2))``, :func:`~synth.ident.exchangeable.exchangeable_groups`) are labelled in each part as
        in this fit (default: as in the first part that fits). Unaligned, a part that returned the slow pole
        as ``p2`` made a right std look 24 times too small.

    Returns
    -------
    SplitCheck

    Raises
    ------
    DataError
        ``parts`` below 3, or parts shorter than 20 samples.

    Examples
    --------
    >>> from synth.data import record_from_arrays
    >>> from synth.ident.simulate import simulate_plant
    >>> from synth.plant import Plant
    >>> t = np.arange(0, 100, 0.01); u = np.where((t // 2) % 2 == 1, 2.0, 1.0)
    >>> y = simulate_plant(Plant.from_string("2/(0.5*s+1)"), t, u)
    >>> y = y + 0.05 * np.random.default_rng(1).normal(size=t.size)
    >>> check = split_check(record_from_arrays(t, u, y), "K/(T*s+1)", parts=4)
    >>> check.verdict, check.fitted
    ('consistent', 4)
    """
    from synth.ident.identification import identify

    parts = int(parts)
    if parts < 3:
        raise DataError(f"the split check needs at least 3 parts, got {parts}", where="parts")
    if record.t.size // parts < 20:
        raise DataError(f"{record.t.size} samples cut into {parts} parts leave fewer than 20 per part",
                        where="parts")
    edges = np.linspace(0, record.t.size, parts + 1).astype(int)
    groups = exchangeable_groups(parse_structure(structure) if isinstance(structure, str) else structure)
    estimates: dict[str, list[float]] = {}
    stds: dict[str, list[float]] = {}
    failures: list[str] = []
    fitted = 0
    for a, b in pairwise(edges):
        part = record.segment(float(record.t[a]), float(record.t[b - 1]))
        try:
            fit = identify(part, structure, delay, sensor, average=average, compare_directions=False).fit
        except SynthError as exc:
            failures.append(f"part {len(failures) + fitted + 1}: {exc.message}")
            continue
        names = fit.names[:-1]  # the parameters and the fitted delay; not the offset
        irregular = [w.name for w in fit.weak] + [k for k in names if not np.isfinite(fit.std.get(k, np.nan))]
        if irregular:  # its std is no local statement (a weak or unbounded parameter): nothing to compare with
            failures.append(f"part {len(failures) + fitted + 1}: {', '.join(dict.fromkeys(irregular))} weakly "
                            f"identifiable in this part, not compared")
            continue
        fitted += 1
        values = {k: float(fit.parameters.get(k, fit.delay)) for k in names}
        errors = {k: float(fit.std.get(k, np.nan)) for k in names}
        if reference is None:
            reference = values
        values, errors = align_labels(values, errors, reference, groups)  # p1 the slow pole in every part
        for name in names:
            estimates.setdefault(name, []).append(values[name])
            stds.setdefault(name, []).append(errors[name])
    seconds = float(record.t[-1] - record.t[0]) / parts
    if fitted < 3:
        return SplitCheck(parts, seconds, fitted, estimates, stds, {}, {}, "undetermined", failures)
    ratio, p_value = {}, {}
    for name, values in estimates.items():
        v, s = np.asarray(values), np.asarray(stds[name])
        if v.size != fitted or not np.all(np.isfinite(s)) or np.any(s <= 0):
            continue  # a part without a finite std for it: no test of this parameter
        w = 1.0 / s**2
        chi2 = float(np.sum(((v - np.sum(w * v) / np.sum(w)) / s) ** 2))
        ratio[name] = float(np.sqrt(chi2 / (fitted - 1)))
        p_value[name] = float(chi2_sf(chi2, fitted - 1))
    if not ratio:
        return SplitCheck(parts, seconds, fitted, estimates, stds, {}, {}, "undetermined",
                          [*failures, "no parameter has a finite std in every part"])
    small = any(p < ALPHA / len(p_value) for p in p_value.values())
    return SplitCheck(parts, seconds, fitted, estimates, stds, ratio, p_value,
                      "stds too small" if small else "consistent", failures)
