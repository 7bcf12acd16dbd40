"""One row of a paper reconciliation table: a published number beside the value synth computes.

A row never bends a number: it states the paper's value as printed, synth's value, the unit, whether
the two agree within the paper's printed precision, and what would make them agree.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

__all__ = ["AGREES", "APPROXIMATE", "DERIVED", "DISAGREES", "PaperRow", "printed_tolerance", "rows_table"]

#: the values agree within half a unit of the paper's last printed digit
AGREES = "reconciles"
#: they differ by more than the printed precision but the paper calls its number approximate
APPROXIMATE = "approximately"
#: they do not agree
DISAGREES = "does not reconcile"
#: synth's number has no printed counterpart (context for the other rows)
DERIVED = "derived (no paper value)"


def printed_tolerance(printed: str) -> float:
    """Half a unit of the last digit of a number as printed (``"101.2"`` -> 0.05, ``"800"`` -> 0.5).

    Examples
    --------
    >>> printed_tolerance("101.2"), printed_tolerance("800"), printed_tolerance("0.0046")
    (0.05, 0.5, 5e-05)
    """
    text = printed.strip().lstrip("+-")
    decimals = len(text.split(".")[1]) if "." in text else 0
    return 0.5 * 10.0 ** (-decimals)


@dataclass(frozen=True)
class PaperRow:
    """A paper's number beside synth's.

    Attributes
    ----------
    quantity : str
        What the number is.
    paper : str or None
        The value as printed in the paper (``None``: the paper prints none).
    synth : float or None
        synth's value, computed.
    unit : str
        Unit of both values.
    source : str
        Where the paper states it (section, equation).
    status : str
        :data:`AGREES`, :data:`APPROXIMATE`, :data:`DISAGREES` or :data:`DERIVED`.
    reconcile : str
        How synth computed its value and what would make the two agree.

    Examples
    --------
    >>> r = PaperRow.compare("shaft power", "131", 139.92, "W", "sec. 3", "0.1749 N m x 800 rad/s")
    >>> r.status, round(r.difference, 2)
    ('does not reconcile', 8.92)
    """

    quantity: str
    paper: str | None
    synth: float | None
    unit: str
    source: str
    status: str
    reconcile: str

    @classmethod
    def compare(cls, quantity: str, paper: str, synth: float, unit: str, source: str, reconcile: str,
                tolerance: float | None = None, approximate: bool = False) -> PaperRow:
        """A row whose status follows from ``|synth - paper| <= tolerance``.

        ``tolerance`` defaults to :func:`printed_tolerance` of ``paper``; ``approximate=True`` (the paper
        says "about") turns a disagreement into :data:`APPROXIMATE`.

        Examples
        --------
        >>> PaperRow.compare("thrust", "12.7", 12.749, "N", "sec. 3", "4 kg x 1.3 x g / 4").status
        'reconciles'
        """
        tol = printed_tolerance(paper) if tolerance is None else tolerance
        if abs(float(synth) - float(paper)) <= tol:
            status = AGREES
        else:
            status = APPROXIMATE if approximate else DISAGREES
        return cls(quantity, paper, float(synth), unit, source, status, reconcile)

    @classmethod
    def derived(cls, quantity: str, synth: float, unit: str, source: str, note: str) -> PaperRow:
        """A computed number the paper does not print.

        Examples
        --------
        >>> PaperRow.derived("battery power", 325.6, "W", "sec. 2-3", "14.8 V x 22 A").status
        'derived (no paper value)'
        """
        return cls(quantity, None, float(synth), unit, source, DERIVED, note)

    @property
    def difference(self) -> float | None:
        """``synth - paper`` (``None`` without a paper value)."""
        if self.paper is None or self.synth is None:
            return None
        return float(self.synth) - float(self.paper)

    @property
    def reconciles(self) -> bool:
        """True unless the status is :data:`DISAGREES`."""
        return self.status != DISAGREES

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"quantity": self.quantity, "paper": self.paper, "synth": self.synth, "unit": self.unit,
                "difference": self.difference, "source": self.source, "status": self.status,
                "reconcile": self.reconcile}


def rows_table(rows: Sequence[PaperRow]) -> str:
    """Markdown table of rows (paper, synth, unit, status, source, what would reconcile).

    Examples
    --------
    >>> print(rows_table([PaperRow.derived("battery power", 325.6, "W", "sec. 2-3", "14.8 V x 22 A")]))
    | quantity | paper | synth | unit | status | source | what would reconcile it |
    |---|---|---|---|---|---|---|
    | battery power | - | 325.6 | W | derived (no paper value) | sec. 2-3 | 14.8 V x 22 A |
    """
    lines = ["| quantity | paper | synth | unit | status | source | what would reconcile it |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        synth = "-" if r.synth is None else f"{r.synth:.4g}"
        lines.append(f"| {r.quantity} | {r.paper or '-'} | {synth} | {r.unit} | {r.status} | {r.source} | "
                     f"{r.reconcile} |")
    return "\n".join(lines)
